"""The joint plot PNG of a run (matplotlib, Agg): positions and velocities over time against the limits."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray
from cell.preview.figures import new_figure, save_figure
from cell.preview.views import ARC_COLOUR
from cell.types.robot import JointLimits


def render_joint_plots(
    times: npt.ArrayLike,
    q: npt.ArrayLike,
    qd: npt.ArrayLike,
    limits: JointLimits,
    out_path: str | Path,
    *,
    arc_on: npt.ArrayLike | None = None,
    title: str = "",
    bands: Sequence[tuple[float, float, str]] = (),
) -> Path:
    """Joint positions [deg] and velocities [deg/s] over time, one row per joint, limits shaded red.

    times : (n,) [s]; q : (n, dof) [rad]; qd : (n, dof) [rad/s]; arc_on : optional (n,) bool, shaded yellow.
    bands : (start, end [s], seam id) of each weld: the seam's name is written above its band in the top row.
    Position axes fit the motion (a limit far away is named in the row title); velocity axes always show the
    limits. Returns ``out_path``.
    """
    from matplotlib.patches import Patch

    t = np.asarray(times, dtype=float)
    qa, qda = np.degrees(np.asarray(q, dtype=float)), np.degrees(np.asarray(qd, dtype=float))
    dof = limits.dof
    if t.ndim != 1 or qa.shape != (len(t), dof) or qda.shape != (len(t), dof):
        raise ValueError(
            f"render_joint_plots: need times (n,), q and qd (n, {dof}); got {t.shape}, {qa.shape}, {qda.shape}"
        )
    lo, hi = np.degrees(limits.q_min), np.degrees(limits.q_max)
    vmax = np.degrees(limits.v_max)
    arc = None if arc_on is None else np.asarray(arc_on, bool)
    fig = new_figure(11.0, 1.6 * dof + 1.0)
    axes = fig.subplots(dof, 2, sharex=True, squeeze=False)
    shade = {"color": "#d62728", "alpha": 0.15, "lw": 0}
    for j in range(dof):
        ax_q, ax_v = axes[j]
        ax_q.plot(t, qa[:, j], color="#1f77b4", lw=1.2)
        span = max(float(np.ptp(qa[:, j])), 5.0)
        ylo, yhi = float(qa[:, j].min()) - 0.15 * span, float(qa[:, j].max()) + 0.15 * span
        ax_q.axhspan(hi[j], max(yhi, hi[j]) + 1e3, **shade)
        ax_q.axhspan(min(ylo, lo[j]) - 1e3, lo[j], **shade)
        ax_q.set_ylim(ylo, yhi)
        ax_q.set_ylabel(f"{limits.names[j]}\n[deg]", fontsize=8)
        ax_q.set_title(f"{limits.names[j]} position (limits {lo[j]:.0f} .. {hi[j]:.0f} deg)", fontsize=8)
        ax_v.plot(t, qda[:, j], color="#ff7f0e", lw=1.2)
        vlim = max(float(np.abs(qda[:, j]).max()), vmax[j]) * 1.15
        ax_v.axhspan(vmax[j], vlim, **shade)
        ax_v.axhspan(-vlim, -vmax[j], **shade)
        ax_v.set_ylim(-vlim, vlim)
        ax_v.set_ylabel("[deg/s]", fontsize=8)
        ax_v.set_title(f"{limits.names[j]} velocity (limit +-{vmax[j]:.0f} deg/s)", fontsize=8)
        if arc is not None:
            for a, b in _runs(t, arc):
                for ax in (ax_q, ax_v):
                    ax.axvspan(a, b, color=ARC_COLOUR, alpha=0.35, lw=0)
        for ax in (ax_q, ax_v):
            ax.grid(True, lw=0.3, alpha=0.5)
            ax.tick_params(labelsize=7)
    pad = 6.0 + 3.8 * max((len(seam) for _, _, seam in bands), default=0)  # [pt] rotated labels under the titles
    for ax in axes[0]:
        ax.set_title(ax.get_title(), fontsize=8, pad=pad)
    for a, b, seam in bands:
        for ax in axes[0]:
            ax.text((a + b) / 2.0, 1.02, seam, transform=ax.get_xaxis_transform(), rotation=90, fontsize=6,
                    ha="center", va="bottom")  # fmt: skip
    axes[-1][0].set_xlabel("time [s]")
    axes[-1][1].set_xlabel("time [s]")
    handles = [Patch(color="#d62728", alpha=0.15, label="outside the limits")]
    if arc is not None:
        handles.append(Patch(color=ARC_COLOUR, alpha=0.35, label="arc on"))
    fig.legend(handles=handles, loc="outside lower center", ncols=len(handles), fontsize=8, frameon=False)
    head = f"{title}: " if title else ""
    fig.suptitle(f"{head}joint trajectory, {t[-1] - t[0]:.1f} s, {len(t)} samples")
    return save_figure(fig, out_path)


def _runs(t: FloatArray, on: npt.NDArray[np.bool_]) -> list[tuple[float, float]]:
    """Time intervals [s] where ``on`` holds (each sample's state lasting until the next sample)."""
    out = []
    k, n = 0, len(on)
    while k < n:
        if on[k]:
            k1 = k
            while k1 + 1 < n and on[k1 + 1]:
                k1 += 1
            out.append((float(t[k]), float(t[min(k1 + 1, n - 1)])))
            k = k1 + 1
        else:
            k += 1
    return out
