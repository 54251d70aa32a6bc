"""The overview PNGs of a run (matplotlib, Agg): top view, perspective view and one close-up per seam.

matplotlib is imported inside the functions, so importing this module costs nothing; figures are drawn on
matplotlib's Agg canvas directly (no pyplot, no global state, no display needed). Input in the robot frame R
[m], drawn in millimetres.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray
from cell.outputs import make_folder, replacing
from cell.preview.labels import place_labels
from cell.preview.views import (
    AXIS_COLOURS,
    BOX_COLOUR,
    MM,
    PATH_COLOUR,
    STATUS_COLOURS,
    TRUTH_COLOUR,
    Line,
    SeamView,
    label_groups,
    seam_lines,
    thin,
    torch_glyphs,
)
from cell.types import WeldMap

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

_PANEL_POINTS = 6000  # cloud points drawn in one seam close-up


def _legend_handles(statuses: set[str], has_truth: bool, has_torch: bool, has_path: bool) -> list[Any]:
    """Legend entries for what is drawn only: the seam statuses present, truth, torch axes, tool paths."""
    from matplotlib.lines import Line2D

    h: list[Any] = []
    if "found" in statuses:
        h.append(Line2D([], [], color=STATUS_COLOURS["found"], lw=2.5, label="seam found (estimate)"))
    for status in ("not_found", "not_visible", "occluded"):
        if status in statuses:
            label = f"{status.replace('_', ' ')} (map)"
            h.append(Line2D([], [], color=STATUS_COLOURS[status], lw=2.0, ls="--", label=label))
    h.append(Line2D([], [], color=BOX_COLOUR, lw=0.8, label="map parts (aligned)"))
    if has_truth:
        h.append(Line2D([], [], color=TRUTH_COLOUR, marker="x", ls="", label="true seam ends"))
    if has_torch:
        h += [
            Line2D([], [], color=c, lw=1.5, label=f"torch {a} axis") for c, a in zip(AXIS_COLOURS, "xyz", strict=True)
        ]
    if has_path:
        h.append(Line2D([], [], color=PATH_COLOUR, lw=1.0, ls=":", label="tool path"))
    return h


def new_figure(width_in: float, height_in: float) -> Figure:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width_in, height_in), dpi=110, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def save_figure(fig: Figure, path: str | Path, **options: Any) -> Path:
    """Write ``fig`` to ``path`` whole (:func:`cell.outputs.replacing`; the format from its suffix)."""
    p = Path(path)
    with replacing(p, what="picture") as tmp:
        fig.savefig(tmp, **options)
    return p


def _draw_2d(
    ax: Axes,
    ij: tuple[int, int],
    cloud: FloatArray,
    weldmap: WeldMap,
    lines: list[Line],
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
        for e in part.edges() * MM:
            ax.plot(e[:, i], e[:, j], color=BOX_COLOUR, lw=0.6, zorder=2)
    for tcp in tcp_paths.values():
        p = np.asarray(tcp, dtype=float).reshape(-1, 3) * MM
        ax.plot(p[:, i], p[:, j], color=PATH_COLOUR, lw=1.0, ls=":", zorder=3)
    for poses in torch_poses.values():
        for glyph in torch_glyphs(poses):
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
    lines: list[Line],
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
        for e in part.edges() * MM:
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
        for glyph in torch_glyphs(poses):
            for seg, colour in zip(glyph, AXIS_COLOURS, strict=True):
                ax.plot(*seg.T, color=colour, lw=1.2)
    lo, hi = cloud.min(axis=0), cloud.max(axis=0)
    for part in weldmap.parts:
        c = part.vertices() * MM
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
    ln: Line,
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
    near = thin(cloud[np.all(np.abs(cloud - mid) < half, axis=1)], _PANEL_POINTS)
    sc = _draw_2d(
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
    if len(near):  # colour is the depth along the axis the panel does not show
        cb = ax.figure.colorbar(sc, ax=ax, shrink=0.8, pad=0.02, aspect=30)
        cb.set_label(f"{'xyz'[3 - ij[0] - ij[1]]}_R [mm]", fontsize=6)
        cb.ax.tick_params(labelsize=5)


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

    out = make_folder(out_dir, "picture folder")
    all_points = np.asarray(cloud_R, dtype=float).reshape(-1, 3) * MM
    if len(all_points) == 0:
        raise ValueError("render_overview: the cloud is empty; nothing to draw")
    cloud = thin(all_points, max_points)
    lines = seam_lines(seams, weldmap_R)
    n_found = sum(ln.status == "found" for ln in lines)
    handles = _legend_handles(
        {ln.status for ln in lines},
        any(ln.truth is not None for ln in lines),
        any(len(np.asarray(p).reshape(-1, 16)) for p in torch_poses.values()),
        any(len(np.asarray(p).reshape(-1, 3)) for p in tcp_paths.values()),
    )
    head = f"{title}: " if title else ""

    def caption(n: int) -> str:
        return f"{n_found}/{len(lines)} seams found; {n} of {len(all_points)} points shown"

    written = []
    fig = new_figure(12.0, 7.0)
    ax = fig.add_subplot()
    sc = _draw_2d(ax, (0, 1), cloud, weldmap_R, lines, torch_poses, tcp_paths, point_size=1.0)
    fig.colorbar(sc, ax=ax, label="height z_R [mm]", shrink=0.7, pad=0.02)
    fig.suptitle(f"{head}top view in the robot frame R")
    ax.set_title(caption(len(cloud)), fontsize=9)
    fig.legend(handles=handles, loc="outside right upper", fontsize=8, frameon=False)
    place_labels(fig, ax, label_groups(lines))
    written.append(out / "overview_top.png")
    save_figure(fig, written[-1])

    fig = new_figure(12.0, 8.0)
    ax3 = fig.add_subplot(projection="3d")
    cloud3 = thin(cloud, max_points // 2)
    sc = _draw_3d(ax3, cloud3, weldmap_R, lines, torch_poses, tcp_paths)
    ax3.zaxis.set_major_locator(MaxNLocator(3))
    fig.colorbar(sc, ax=ax3, label="height z_R [mm]", shrink=0.5, pad=0.08)
    fig.suptitle(f"{head}perspective view in the robot frame R")
    ax3.set_title(caption(len(cloud3)), fontsize=9)
    fig.legend(handles=handles, loc="outside right upper", fontsize=8, frameon=False)
    written.append(out / "overview_3d.png")
    save_figure(fig, written[-1])

    if lines:
        ncols = min(4, len(lines))
        nrows = -(-len(lines) // ncols)
        fig = new_figure(3.2 * ncols + 1.8, 3.1 * nrows + 0.6)
        grid = fig.subplots(nrows, ncols, squeeze=False)
        for i, ln in enumerate(lines):
            _draw_seam_panel(
                grid.flat[i], i + 1, ln, all_points, weldmap_R, torch_poses.get(ln.id), tcp_paths.get(ln.id)
            )
        for ax_unused in list(grid.flat)[len(lines) :]:
            ax_unused.set_axis_off()
        fig.suptitle(f"{head}every seam close up (R frame; colour = depth along the axis not shown)")
        fig.legend(handles=handles, loc="outside right upper", fontsize=8, frameon=False)
        written.append(out / "overview_seams.png")
        save_figure(fig, written[-1])
    return written
