"""Pictures of a run that a person would rather look at than read: PNGs (matplotlib, Agg) and one HTML (plotly).

Everything here takes plain values (arrays, a :class:`~cell.types.WeldMap`, seam tuples) in the robot frame R
[m, rad] and draws in millimetres and degrees. matplotlib and plotly are imported inside the functions, so
importing this module costs nothing; figures are drawn on matplotlib's Agg canvas directly (no pyplot, no global
state, no display needed). The cloud is thinned deterministically (every k-th point) to keep drawing fast.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray
from cell.motion.limits import JointLimits
from cell.types import Box, SeamEstimate, WeldMap

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from cell.pipeline import WeldRun

MM = 1000.0  # [mm/m]
STATUS_COLOURS = {"found": "#2ca02c", "not_found": "#d62728", "not_visible": "#ff7f0e", "occluded": "#9467bd"}
TRUTH_COLOUR = "#000000"
PATH_COLOUR = "#17becf"
BOX_COLOUR = "#555555"
# torch x, y, z axes: magenta, brown, blue (not red/green, which mean seam status here)
AXIS_COLOURS = ("#c51b7d", "#8c510a", "#2166ac")
ARC_COLOUR = "#ffd92f"
_GLYPHS_PER_SEAM = 6  # torch axis glyphs drawn along each seam
_GLYPH_M = 0.04  # [m] length of a torch axis glyph
_PANEL_POINTS = 6000  # cloud points drawn in one seam close-up


class SeamView(NamedTuple):
    """One seam to draw, in R [m]: its status (``found``/``not_found``/``not_visible``), the estimate's end
    points (empty arrays when not found) and the true end points (None when unknown)."""

    id: str
    status: str
    p_start: npt.ArrayLike
    p_end: npt.ArrayLike
    truth_start: npt.ArrayLike | None = None
    truth_end: npt.ArrayLike | None = None


def seam_views(
    estimates: Sequence[SeamEstimate], truths: Mapping[str, tuple[FloatArray, FloatArray]]
) -> list[SeamView]:
    """SeamViews from a locator's estimates and the true seams (id -> (start, end) in R)."""
    out = []
    for e in estimates:
        t = truths.get(e.id)
        out.append(SeamView(e.id, str(e.status), e.p_start, e.p_end, *(t if t is not None else (None, None))))
    return out


class _Line(NamedTuple):
    """A seam line ready to draw: (2, 3) [mm], solid when it is the estimate, dashed when it is the map's."""

    id: str
    status: str
    pts: FloatArray
    estimated: bool
    truth: FloatArray | None


def _seam_lines(seams: Sequence[SeamView | tuple[Any, ...]], weldmap: WeldMap) -> list[_Line]:
    lines = []
    for raw in seams:
        s = SeamView(*raw)
        status = str(s.status)
        if status not in STATUS_COLOURS:
            raise ValueError(f"seam {s.id}: status {status!r} unknown; valid: {', '.join(STATUS_COLOURS)}")
        a, b = np.asarray(s.p_start, dtype=float), np.asarray(s.p_end, dtype=float)
        estimated = a.shape == (3,) and b.shape == (3,)
        if not estimated:  # nothing found: draw where the map says the seam is
            ms = weldmap.seam(s.id)
            a, b = np.asarray(ms.p_start), np.asarray(ms.p_end)
        truth = None
        if s.truth_start is not None and s.truth_end is not None:
            truth = np.array([s.truth_start, s.truth_end], dtype=float) * MM
        lines.append(_Line(s.id, status, np.array([a, b]) * MM, estimated, truth))
    return lines


def _thin(points: npt.ArrayLike, max_points: int) -> FloatArray:
    """At most ``max_points`` rows of points (n, 3), every k-th one (deterministic)."""
    p = np.asarray(points, dtype=float).reshape(-1, 3)
    step = max(int(np.ceil(len(p) / max(max_points, 1))), 1)
    return p[::step]


def _box_edges(box: Box) -> FloatArray:
    """(12, 2, 3) edges of a box [m]: corner pairs whose indices differ in one bit."""
    c = box.corners()
    pairs = [(i, i | bit) for i in range(8) for bit in (1, 2, 4) if not i & bit]
    return np.array([[c[i], c[j]] for i, j in pairs])


def _glyphs(poses: npt.ArrayLike) -> FloatArray:
    """(k, 3, 2, 3) axis segments [mm] of a few torch poses X_RT (m, 4, 4): for each pose, x, y, z axes."""
    X = np.asarray(poses, dtype=float).reshape(-1, 4, 4)
    if len(X) == 0:
        return np.zeros((0, 3, 2, 3))
    X = X[np.unique(np.linspace(0, len(X) - 1, min(_GLYPHS_PER_SEAM, len(X))).round().astype(int))]
    origin = X[:, :3, 3]
    tips = origin[:, None, :] + _GLYPH_M * np.transpose(X[:, :3, :3], (0, 2, 1))  # (k, axis, 3)
    return np.stack([np.repeat(origin[:, None, :], 3, axis=1), tips], axis=2) * MM


def _label_groups(lines: list[_Line], radius_mm: float = 60.0) -> list[tuple[str, tuple[float, float]]]:
    """Seam numbers (1-based, as in the detail panels) grouped by nearby midpoints: one label per group."""
    groups: list[tuple[list[int], FloatArray]] = []
    for i, ln in enumerate(lines):
        mid = ln.pts.mean(axis=0)[:2]
        for members, centre in groups:
            if np.linalg.norm(mid - centre) < radius_mm:
                members.append(i + 1)
                break
        else:
            groups.append(([i + 1], mid))
    return [(",".join(str(m) for m in members), (float(c[0]), float(c[1]))) for members, c in groups]


def _legend_handles(has_truth: bool, has_torch: bool, has_path: bool) -> list[Any]:
    from matplotlib.lines import Line2D

    h: list[Any] = [
        Line2D([], [], color=STATUS_COLOURS["found"], lw=2.5, label="seam found (estimate)"),
        Line2D([], [], color=STATUS_COLOURS["not_found"], lw=2.0, ls="--", label="not found (map)"),
        Line2D([], [], color=STATUS_COLOURS["not_visible"], lw=2.0, ls="--", label="not visible (map)"),
        Line2D([], [], color=BOX_COLOUR, lw=0.8, label="map parts (aligned)"),
    ]
    if has_truth:
        h.append(Line2D([], [], color=TRUTH_COLOUR, marker="x", ls="", label="true seam ends"))
    if has_torch:
        h += [
            Line2D([], [], color=c, lw=1.5, label=f"torch {a} axis") for c, a in zip(AXIS_COLOURS, "xyz", strict=True)
        ]
    if has_path:
        h.append(Line2D([], [], color=PATH_COLOUR, lw=1.0, ls=":", label="tool path"))
    return h


def _new_figure(width_in: float, height_in: float) -> Figure:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width_in, height_in), dpi=110, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def _draw_2d(
    ax: Axes,
    ij: tuple[int, int],
    cloud: FloatArray,
    weldmap: WeldMap,
    lines: list[_Line],
    torch_poses: Mapping[str, npt.ArrayLike],
    tcp_paths: Mapping[str, npt.ArrayLike],
    point_size: float,
) -> Any:
    """Projection onto axes ij of R [mm]: cloud coloured by the third axis, then outlines, paths, torch glyphs,
    seams and true ends on top (in that order)."""
    i, j = ij
    k = 3 - i - j
    sc = ax.scatter(
        cloud[:, i], cloud[:, j], c=cloud[:, k], s=point_size, cmap="viridis", linewidths=0, rasterized=True, zorder=1
    )
    for part in weldmap.parts:
        for e in _box_edges(part.box) * MM:
            ax.plot(e[:, i], e[:, j], color=BOX_COLOUR, lw=0.6, zorder=2)
    for tcp in tcp_paths.values():
        p = np.asarray(tcp, dtype=float).reshape(-1, 3) * MM
        ax.plot(p[:, i], p[:, j], color=PATH_COLOUR, lw=1.0, ls=":", zorder=3)
    for poses in torch_poses.values():
        for glyph in _glyphs(poses):
            for seg, colour in zip(glyph, AXIS_COLOURS, strict=True):
                ax.plot(seg[:, i], seg[:, j], color=colour, lw=1.0, zorder=4)
    for ln in lines:
        ax.plot(
            ln.pts[:, i],
            ln.pts[:, j],
            color=STATUS_COLOURS[ln.status],
            lw=2.5,
            ls="-" if ln.estimated else "--",
            solid_capstyle="round",
            zorder=5,
        )
        if ln.truth is not None:
            ax.plot(ln.truth[:, i], ln.truth[:, j], "x", color=TRUTH_COLOUR, ms=6, mew=1.2, zorder=6)
    ax.set_aspect("equal")
    ax.set_xlabel(f"{'xyz'[i]}_R [mm]", fontsize=8)
    ax.set_ylabel(f"{'xyz'[j]}_R [mm]", fontsize=8)
    return sc


def _draw_3d(
    ax: Any,
    cloud: FloatArray,
    weldmap: WeldMap,
    lines: list[_Line],
    torch_poses: Mapping[str, npt.ArrayLike],
    tcp_paths: Mapping[str, npt.ArrayLike],
) -> Any:
    sc = ax.scatter(
        cloud[:, 0],
        cloud[:, 1],
        cloud[:, 2],
        c=cloud[:, 2],
        s=0.6,
        cmap="viridis",
        linewidths=0,
        alpha=0.5,
        depthshade=False,
        rasterized=True,
    )
    for part in weldmap.parts:
        for e in _box_edges(part.box) * MM:
            ax.plot(e[:, 0], e[:, 1], e[:, 2], color=BOX_COLOUR, lw=0.6)
    for ln in lines:
        ax.plot(
            *ln.pts.T,
            color=STATUS_COLOURS[ln.status],
            lw=3.0 if ln.estimated else 2.0,
            ls="-" if ln.estimated else "--",
        )
        if ln.truth is not None:
            ax.plot(*ln.truth.T, "x", color=TRUTH_COLOUR, ms=4)
    for path in tcp_paths.values():
        p = np.asarray(path, dtype=float).reshape(-1, 3) * MM
        ax.plot(*p.T, color=PATH_COLOUR, lw=1.0, ls=":")
    for poses in torch_poses.values():
        for glyph in _glyphs(poses):
            for seg, colour in zip(glyph, AXIS_COLOURS, strict=True):
                ax.plot(*seg.T, color=colour, lw=1.2)
    lo, hi = cloud.min(axis=0), cloud.max(axis=0)
    for part in weldmap.parts:
        c = part.box.corners() * MM
        lo, hi = np.minimum(lo, c.min(axis=0)), np.maximum(hi, c.max(axis=0))
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect(tuple(np.maximum(hi - lo, 1.0)), zoom=1.15)  # equal scale on all axes
    ax.view_init(elev=35.0, azim=-60.0)
    ax.set_xlabel("x_R [mm]")
    ax.set_ylabel("y_R [mm]")
    ax.set_zlabel("z_R [mm]")
    return sc


def _draw_seam_panel(
    ax: Axes,
    index: int,
    ln: _Line,
    cloud: FloatArray,
    weldmap: WeldMap,
    torch_poses: npt.ArrayLike | None,
    tcp_path: npt.ArrayLike | None,
) -> None:
    """One seam close up [mm]: seen from above, or from the side (x-z) for a vertical seam."""
    d = np.abs(ln.pts[1] - ln.pts[0])
    ij = (0, 1) if d[2] <= max(d[0], d[1]) else (0, 2)
    mid = ln.pts.mean(axis=0)
    half = max(0.6 * float(np.linalg.norm(ln.pts[1] - ln.pts[0])), 30.0) + 20.0  # [mm]
    near = _thin(cloud[np.all(np.abs(cloud - mid) < half, axis=1)], _PANEL_POINTS)
    _draw_2d(
        ax,
        ij,
        near,
        weldmap,
        [ln],
        {} if torch_poses is None else {ln.id: torch_poses},
        {} if tcp_path is None else {ln.id: tcp_path},
        point_size=3.0,
    )
    detail = ln.status.replace("_", " ")
    if ln.truth is not None and ln.estimated:
        err = np.linalg.norm(ln.pts - ln.truth, axis=1)
        detail = f"ends off by {err[0]:.1f} / {err[1]:.1f} mm"
    ax.set_xlim(mid[ij[0]] - half, mid[ij[0]] + half)
    ax.set_ylim(mid[ij[1]] - half, mid[ij[1]] + half)
    ax.tick_params(labelsize=6)
    ax.set_title(f"{index}. {ln.id}\n{detail}", fontsize=7, color=STATUS_COLOURS[ln.status])


def render_overview(
    cloud_R: npt.ArrayLike,
    weldmap_R: WeldMap,
    seams: Sequence[SeamView | tuple[Any, ...]],
    torch_poses: Mapping[str, npt.ArrayLike],
    tcp_paths: Mapping[str, npt.ArrayLike],
    out_dir: str | Path,
    *,
    title: str = "",
    max_points: int = 25_000,
) -> list[Path]:
    """Pictures of the perceived cell in the robot frame R [mm], written to ``out_dir``:

    ``overview_top.png`` (top view), ``overview_3d.png`` (perspective view) and, when there are seams,
    ``overview_seams.png`` (one close-up per seam, numbered as in the top view, with its end point errors).

    cloud_R : (n, 3) perceived points in R [m] (thinned to ``max_points``), coloured by height.
    weldmap_R : the aligned map (part boxes drawn as outlines; seams not found are drawn where the map has them).
    seams : :class:`SeamView` tuples (id, status, p_start, p_end, truth_start, truth_end) in R [m].
    torch_poses : seam id -> (m, 4, 4) torch poses X_RT (a few drawn as x/y/z axis glyphs); may be empty.
    tcp_paths : seam id (or any key) -> (k, 3) tool path in R [m]; may be empty.
    Returns the paths written.
    """
    from matplotlib.ticker import MaxNLocator

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    all_points = np.asarray(cloud_R, dtype=float).reshape(-1, 3) * MM
    if len(all_points) == 0:
        raise ValueError("render_overview: the cloud is empty; nothing to draw")
    cloud = _thin(all_points, max_points)
    lines = _seam_lines(seams, weldmap_R)
    n_found = sum(ln.status == "found" for ln in lines)
    handles = _legend_handles(
        any(ln.truth is not None for ln in lines),
        any(len(np.asarray(p).reshape(-1, 16)) for p in torch_poses.values()),
        any(len(np.asarray(p).reshape(-1, 3)) for p in tcp_paths.values()),
    )
    head = f"{title}: " if title else ""

    def caption(n: int) -> str:
        return f"{n_found}/{len(lines)} seams found; {n} of {len(all_points)} points shown"

    written = []
    fig = _new_figure(12.0, 7.0)
    ax = fig.add_subplot()
    sc = _draw_2d(ax, (0, 1), cloud, weldmap_R, lines, torch_poses, tcp_paths, point_size=1.0)
    for text, (x, y) in _label_groups(lines):
        ax.annotate(
            text,
            (x, y),
            xytext=(5, 5),
            textcoords="offset points",
            fontsize=7,
            zorder=7,
            bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none", "alpha": 0.7},
        )
    fig.colorbar(sc, ax=ax, label="height z_R [mm]", shrink=0.7, pad=0.02)
    fig.suptitle(f"{head}top view in the robot frame R")
    ax.set_title(caption(len(cloud)), fontsize=9)
    fig.legend(handles=handles, loc="outside right upper", fontsize=8, frameon=False)
    written.append(out / "overview_top.png")
    fig.savefig(written[-1])

    fig = _new_figure(12.0, 8.0)
    ax3 = fig.add_subplot(projection="3d")
    cloud3 = _thin(cloud, max_points // 2)
    sc = _draw_3d(ax3, cloud3, weldmap_R, lines, torch_poses, tcp_paths)
    ax3.zaxis.set_major_locator(MaxNLocator(3))
    fig.colorbar(sc, ax=ax3, label="height z_R [mm]", shrink=0.5, pad=0.08)
    fig.suptitle(f"{head}perspective view in the robot frame R")
    ax3.set_title(caption(len(cloud3)), fontsize=9)
    fig.legend(handles=handles, loc="outside right upper", fontsize=8, frameon=False)
    written.append(out / "overview_3d.png")
    fig.savefig(written[-1])

    if lines:
        ncols = min(4, len(lines))
        nrows = -(-len(lines) // ncols)
        fig = _new_figure(3.2 * ncols + 1.8, 3.1 * nrows + 0.6)
        grid = fig.subplots(nrows, ncols, squeeze=False)
        for i, ln in enumerate(lines):
            _draw_seam_panel(
                grid.flat[i], i + 1, ln, all_points, weldmap_R, torch_poses.get(ln.id), tcp_paths.get(ln.id)
            )
        for ax_unused in list(grid.flat)[len(lines) :]:
            ax_unused.set_axis_off()
        fig.suptitle(f"{head}every seam close up (R frame; colour = depth along the unseen axis)")
        fig.legend(handles=handles, loc="outside right upper", fontsize=8, frameon=False)
        written.append(out / "overview_seams.png")
        fig.savefig(written[-1])
    return written


def render_joint_plots(
    times: npt.ArrayLike,
    q: npt.ArrayLike,
    qd: npt.ArrayLike,
    limits: JointLimits,
    out_path: str | Path,
    *,
    arc_on: npt.ArrayLike | None = None,
    title: str = "",
) -> Path:
    """Joint positions [deg] and velocities [deg/s] over time, one row per joint, limits shaded red.

    times : (n,) [s]; q : (n, dof) [rad]; qd : (n, dof) [rad/s]; arc_on : optional (n,) bool, shaded yellow.
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
    fig = _new_figure(11.0, 1.6 * dof + 1.0)
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
    axes[-1][0].set_xlabel("time [s]")
    axes[-1][1].set_xlabel("time [s]")
    handles = [Patch(color="#d62728", alpha=0.15, label="outside the limits")]
    if arc is not None:
        handles.append(Patch(color=ARC_COLOUR, alpha=0.35, label="arc on"))
    fig.legend(handles=handles, loc="outside lower center", ncols=len(handles), fontsize=8, frameon=False)
    head = f"{title}: " if title else ""
    fig.suptitle(f"{head}joint trajectory, {t[-1] - t[0]:.1f} s, {len(t)} samples")
    path = Path(out_path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)
    return path


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


def _segments_trace(segs: FloatArray) -> tuple[list[float | None], list[float | None], list[float | None]]:
    """Line segments (m, 2, 3) as one polyline with None breaks (what plotly draws as separate lines)."""
    xs: list[float | None] = []
    ys: list[float | None] = []
    zs: list[float | None] = []
    for a, b in segs:
        xs += [float(a[0]), float(b[0]), None]
        ys += [float(a[1]), float(b[1]), None]
        zs += [float(a[2]), float(b[2]), None]
    return xs, ys, zs


def render_html(
    cloud_R: npt.ArrayLike,
    weldmap_R: WeldMap,
    seams: Sequence[SeamView | tuple[Any, ...]],
    torch_poses: Mapping[str, npt.ArrayLike],
    tcp_paths: Mapping[str, npt.ArrayLike],
    out_path: str | Path,
    *,
    title: str = "",
    max_points: int = 30_000,
) -> Path:
    """One interactive 3D view (cloud, part boxes, seams by status, true ends, torch axes, tool paths) in R [mm],
    as a self-contained HTML file (plotly.js inline: it opens without a network). Arguments as
    :func:`render_overview`. Returns ``out_path``."""
    import plotly.graph_objects as go

    cloud = _thin(cloud_R, max_points) * MM
    lines = _seam_lines(seams, weldmap_R)
    traces: list[Any] = [
        go.Scatter3d(
            x=cloud[:, 0],
            y=cloud[:, 1],
            z=cloud[:, 2],
            mode="markers",
            name="cloud",
            marker={
                "size": 1.5,
                "color": cloud[:, 2],
                "colorscale": "Viridis",
                "opacity": 0.6,
                "colorbar": {"title": "z_R [mm]", "x": 1.0},
            },
            hoverinfo="skip",
        )
    ]
    edges = np.concatenate([_box_edges(p.box) for p in weldmap_R.parts]) * MM if weldmap_R.parts else None
    if edges is not None:
        x, y, z = _segments_trace(edges)
        traces.append(
            go.Scatter3d(
                x=x, y=y, z=z, mode="lines", name="map parts", line={"color": BOX_COLOUR, "width": 2}, hoverinfo="skip"
            )
        )
    for status, colour in STATUS_COLOURS.items():
        mine = [ln for ln in lines if ln.status == status]
        if not mine:
            continue
        x, y, z = _segments_trace(np.array([ln.pts for ln in mine]))
        text: list[str | None] = []
        for ln in mine:
            text += [ln.id, ln.id, None]
        traces.append(
            go.Scatter3d(
                x=x,
                y=y,
                z=z,
                mode="lines",
                name=f"seams {status.replace('_', ' ')}",
                text=text,
                hoverinfo="text+name",
                line={"color": colour, "width": 8 if status == "found" else 5},
            )
        )
    truth = [ln.truth for ln in lines if ln.truth is not None]
    if truth:
        t = np.concatenate(truth)
        traces.append(
            go.Scatter3d(
                x=t[:, 0],
                y=t[:, 1],
                z=t[:, 2],
                mode="markers",
                name="true seam ends",
                marker={"size": 3, "color": TRUTH_COLOUR, "symbol": "x"},
            )
        )
    glyphs = [g for poses in torch_poses.values() for g in _glyphs(poses)]
    if glyphs:
        g = np.array(glyphs)  # (k, 3 axes, 2, 3)
        for i, axis in enumerate("xyz"):
            x, y, z = _segments_trace(g[:, i])
            traces.append(
                go.Scatter3d(
                    x=x,
                    y=y,
                    z=z,
                    mode="lines",
                    name=f"torch {axis} axis",
                    line={"color": AXIS_COLOURS[i], "width": 4},
                    hoverinfo="skip",
                )
            )
    for key, tcp in tcp_paths.items():
        p = np.asarray(tcp, dtype=float).reshape(-1, 3) * MM
        if len(p):
            traces.append(
                go.Scatter3d(
                    x=p[:, 0],
                    y=p[:, 1],
                    z=p[:, 2],
                    mode="lines",
                    name=f"tool path {key}",
                    line={"color": PATH_COLOUR, "width": 3},
                )
            )
    fig = go.Figure(traces)
    fig.update_layout(
        title=title or "weld cell preview (robot frame R, mm)",
        scene={"aspectmode": "data", "xaxis_title": "x_R [mm]", "yaxis_title": "y_R [mm]", "zaxis_title": "z_R [mm]"},
        legend={"itemsizing": "constant"},
        margin={"l": 0, "r": 0, "t": 40, "b": 0},
    )
    path = Path(out_path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.write_html(str(path), include_plotlyjs=True, full_html=True)
    return path


def write_run(run: WeldRun, out_dir: str | Path) -> list[Path]:
    """Every picture of a ``cell weld`` / ``cell preview`` run: overview PNGs, joint plots and the HTML 3D view.

    Tool paths are the executed ones when the arm moved, else the planned torch positions.
    """
    from cell.geometry import invert, transform_points

    det = run.detection
    assert det.scene is not None
    cloud = det.scene.perceived.dense.points
    views = seam_views(det.estimates, det.truths)
    poses = dict(run.torch_paths)
    if run.execution is not None:
        ex = run.execution
        X_RW = invert(det.scenario.X_WR)
        tcp = {"executed": transform_points(X_RW, ex.tcp_W[ex.arc_on])}
    else:
        tcp = {sid: np.asarray(X)[:, :3, 3] for sid, X in poses.items()}
    title = f"{det.scenario.name} · {det.method} · {det.scenario.noise} noise"
    out = Path(out_dir)
    paths = render_overview(cloud, det.weldmap_R, views, poses, tcp, out, title=title)
    if run.plan is not None and run.plan.segments and run.arm is not None:
        limits = run.arm.model.limits
        traj, arc = run.plan.joint_trajectory()
        k = max(1, len(traj.times) // 4000)  # 1 kHz samples: a few thousand are plenty for a plot
        paths.append(
            render_joint_plots(
                traj.times[::k], traj.q[::k], traj.qd[::k], limits, out / "joints.png", arc_on=arc[::k], title=title
            )
        )
    paths.append(render_html(cloud, det.weldmap_R, views, poses, tcp, out / "cell.html", title=title))
    return paths
