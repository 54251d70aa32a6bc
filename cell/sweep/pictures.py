"""A sweep's pictures (matplotlib, headless): ``risk.png``, each seam on the part's top view in the colour of its
probability within the weld tolerance with its probabilities as bars, and ``errors.png``, per seam the histogram of
its lateral error (docs/sweep.md)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from cell.outputs import replacing
from cell.types import WeldMap

_MM = 1000.0


def _pyplot() -> Any:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _footprint(corners_M: np.ndarray) -> np.ndarray:
    """The outline (k, 2) of a box's corners (8, 3) seen from above: their convex hull in x-y [m]."""
    from scipy.spatial import ConvexHull

    xy = corners_M[:, :2]
    return np.asarray(xy[ConvexHull(xy).vertices])


def write_risk(path: Path, weldmap_M: WeldMap, summary: Mapping[str, Any]) -> Path:
    """``risk.png``: the top view coloured by probability within tolerance, and the per-seam bars."""
    plt = _pyplot()
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize

    seams: Mapping[str, Any] = summary["seams"]
    cmap, norm = plt.get_cmap("RdYlGn"), Normalize(0.0, 1.0)
    ids = [s.id for s in weldmap_M.seams if s.id in seams]
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(15, max(5.0, 0.32 * len(ids) + 1.5)), width_ratios=(1.6, 1.0))
    for part in weldmap_M.parts:
        outline = _footprint(np.asarray(part.vertices())) * _MM  # any body: the hull of its vertices from above
        ax.fill(outline[:, 0], outline[:, 1], facecolor="0.88", edgecolor="0.45", linewidth=0.8)
        c = np.asarray(part.center)[:2] * _MM
        ax.text(c[0], c[1], part.name, fontsize=7, color="0.35", ha="center", va="center")

    def risk(sid: str) -> float:
        p = seams[sid].get("probability_within_tolerance")
        return -1.0 if p is None or not seams[sid].get("probability_found") else float(p)

    shift = _spread(weldmap_M, ids)
    for sid in sorted(ids, key=risk, reverse=True):  # the riskiest last: drawn on top; never found: grey, first
        seam = weldmap_M.seam(sid)
        p = risk(sid)
        a, b = np.asarray(seam.p_start)[:2] * _MM + shift[sid], np.asarray(seam.p_end)[:2] * _MM + shift[sid]
        style = (
            {"color": "0.6", "linewidth": 2, "linestyle": ":"} if p < 0 else {"color": cmap(norm(p)), "linewidth": 4}
        )
        if np.linalg.norm(b - a) < 1.0:  # a vertical seam seen from above: a point
            ax.plot([a[0]], [a[1]], marker="o", markersize=6, color=style["color"])
        else:
            ax.plot([a[0], b[0]], [a[1], b[1]], solid_capstyle="round", **style)
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm] (map M)")
    ax.set_ylabel("y [mm]")
    tol = summary.get("weld_tolerance_mm")
    ax.set_title(f"probability within the weld tolerance ({tol} mm), {summary['done']} runs, top view")
    fig.colorbar(ScalarMappable(norm=norm, cmap=cmap), ax=ax, fraction=0.03, label="probability within tolerance")
    _bars(bx, ids, seams, summary.get("stage", "detect"))
    fig.tight_layout()
    with replacing(path, what="picture") as tmp:
        fig.savefig(tmp, dpi=110)
    plt.close(fig)
    return path


def _spread(weldmap_M: WeldMap, ids: Sequence[str], step_mm: float = 14.0) -> dict[str, np.ndarray]:
    """Per seam, a shift [mm] in the top view: seams that would cover each other from above (the sides of one
    joint) are set side by side, ``step_mm`` apart across their direction."""
    groups: dict[tuple[int, int], list[str]] = {}
    for sid in ids:
        m = weldmap_M.seam(sid)
        mid = (np.asarray(m.p_start)[:2] + np.asarray(m.p_end)[:2]) / 2.0 * _MM
        groups.setdefault((round(mid[0] / 20.0), round(mid[1] / 20.0)), []).append(sid)
    out: dict[str, np.ndarray] = {}
    for members in groups.values():
        for i, sid in enumerate(members):
            m = weldmap_M.seam(sid)
            d = (np.asarray(m.p_end) - np.asarray(m.p_start))[:2]
            across = np.array([-d[1], d[0]]) / np.linalg.norm(d) if np.linalg.norm(d) > 1e-6 else np.array([1.0, 0.0])
            out[sid] = across * step_mm * (i - (len(members) - 1) / 2.0)
    return out


def _bars(ax: Any, ids: Sequence[str], seams: Mapping[str, Any], stage: str) -> None:
    """Horizontal bars per seam: found, within tolerance, and planned (plan) or welded (weld)."""
    keys = [("probability_found", "found"), ("probability_within_tolerance", "within tolerance")]
    if stage == "plan":
        keys.append(("probability_planned", "planned + gate"))
    elif stage == "weld":
        keys.append(("probability_welded", "welded"))
    y = np.arange(len(ids))
    h = 0.8 / len(keys)
    for j, (key, label) in enumerate(keys):
        vals = [seams[s].get(key) or 0.0 for s in ids]
        ax.barh(y + (j - (len(keys) - 1) / 2) * h, vals, height=h, label=label)
    ax.set_yticks(y, ids, fontsize=7)
    ax.invert_yaxis()
    ax.set_xlim(0.0, 1.0)
    ax.set_xlabel("probability")
    ax.legend(fontsize=7, loc="lower right")


def write_errors(path: Path, lines: Sequence[Mapping[str, Any]], seam_ids: Sequence[str], tol_mm: float) -> Path:
    """``errors.png``: per seam found at least once, the histogram of its lateral error [mm], tolerance dashed."""
    plt = _pyplot()
    errs = {
        s: [float(ln["seams"][s]["lateral_mm"]) for ln in lines if ln["seams"].get(s, {}).get("lateral_mm") is not None]
        for s in seam_ids
    }
    shown = [s for s in seam_ids if errs[s]]
    cols = 4
    rows = max(1, -(-len(shown) // cols))
    fig, axes = plt.subplots(rows, cols, figsize=(3.4 * cols, 2.4 * rows), squeeze=False)
    for ax, sid in zip(axes.flat, shown, strict=False):
        ax.hist(errs[sid], bins=20, color="tab:blue")
        ax.axvline(tol_mm, color="tab:red", linestyle="--", linewidth=1)
        within = float(np.mean(np.asarray(errs[sid]) <= tol_mm))
        ax.set_title(f"{sid}: {within:.0%} of {len(errs[sid])} found within", fontsize=7)
        ax.set_xlim(left=0.0)
        ax.tick_params(labelsize=6)
    for ax in list(axes.flat)[len(shown) :]:
        ax.axis("off")
    fig.supxlabel(f"lateral error [mm] (dashed: weld tolerance {tol_mm} mm)", fontsize=8)
    fig.tight_layout()
    with replacing(path, what="picture") as tmp:
        fig.savefig(tmp, dpi=100)
    plt.close(fig)
    return path


def write_pictures(
    out: Path, weldmap_M: WeldMap, summary: Mapping[str, Any], lines: Sequence[Mapping[str, Any]]
) -> list[Path]:
    """Both pictures into ``out``; their paths."""
    ok = [ln for ln in lines if ln.get("seams")]
    tol = float(summary.get("weld_tolerance_mm") or 0.5)
    return [
        write_risk(out / "risk.png", weldmap_M, summary),
        write_errors(out / "errors.png", ok, list(summary["seams"]), tol),
    ]
