"""The interactive 3D view of a run (plotly): the figure, or one self-contained HTML file, plotly.js inline.

plotly is imported inside the functions, so importing this module costs nothing. Input in the robot frame
R [m], drawn in millimetres.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray
from cell.outputs import write_text
from cell.preview.cell3d import cell_traces, framed_scene, path_slider, view_points
from cell.preview.views import (
    AXIS_COLOURS,
    BOX_COLOUR,
    MM,
    PATH_COLOUR,
    STATUS_COLOURS,
    TRUTH_COLOUR,
    SeamView,
    seam_lines,
    thin,
    torch_glyphs,
)
from cell.types import CellView, WeldMap


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


def figure_3d(
    cloud_R: npt.ArrayLike,
    weldmap_R: WeldMap,
    seams: Sequence[SeamView | tuple[Any, ...]],
    torch_poses: Mapping[str, npt.ArrayLike],
    tcp_paths: Mapping[str, npt.ArrayLike],
    *,
    title: str = "",
    max_points: int = 30_000,
    view: CellView | None = None,
    hover: Mapping[str, str] | None = None,
    extra: Sequence[Mapping[str, Any]] = (),
) -> Any:
    """The interactive 3D view (a plotly ``Figure``) in R [mm]: cloud, part boxes, seams by status (hover: the
    seam's ``hover`` text), true ends, torch axes, tool paths, the ``extra`` traces (plotly dicts: the curved seams,
    :mod:`cell.preview.curves3d`); with ``view`` also the table, the robot's links (a slider moves them along the
    path) and the camera frusta, and the camera framed to the part. Arguments as :func:`render_overview`."""
    import plotly.graph_objects as go

    cloud = thin(cloud_R, max_points) * MM
    lines = seam_lines(seams, weldmap_R)
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
                "colorbar": {"title": {"text": "z_R [mm]"}, "x": 1.0, "xanchor": "right", "len": 0.6},
            },
            hoverinfo="skip",
        )
    ]
    edges = np.concatenate([p.edges() for p in weldmap_R.parts]) * MM if weldmap_R.parts else None
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
            tip = (hover or {}).get(ln.id, "")
            tip = f"{ln.id}<br>{tip}" if tip else ln.id
            text += [tip, tip, None]
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
    glyphs = [g for poses in torch_poses.values() for g in torch_glyphs(poses)]
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
    paths = [(str(key), np.asarray(tcp, dtype=float).reshape(-1, 3) * MM) for key, tcp in tcp_paths.items()]
    paths = [(key, p) for key, p in paths if len(p)]
    if paths:  # one trace (one legend entry), the paths apart by None breaks, each named in its hover text
        xyz: list[list[float | None]] = [[], [], []]
        names: list[str | None] = []
        for key, p in paths:
            for i in range(3):
                xyz[i] += [*np.round(p[:, i], 1).tolist(), None]
            names += [f"tool path {key}"] * len(p) + [None]
        traces.append(
            go.Scatter3d(
                x=xyz[0],
                y=xyz[1],
                z=xyz[2],
                mode="lines",
                name="tool path",
                text=names,
                hoverinfo="text",
                line={"color": PATH_COLOUR, "width": 3},
            )
        )
    traces += [dict(t) for t in extra]
    layout: dict[str, Any] = {
        "title": {"text": title or "weld cell preview (robot frame R, mm)"},
        # legend on the left, the cloud's colour bar on the right: never over each other
        "legend": {
            "itemsizing": "constant",
            "groupclick": "togglegroup",
            "x": 0.0,
            "xanchor": "left",
            "y": 1.0,
            "bgcolor": "rgba(255,255,255,0.7)",
        },
        "margin": {"l": 0, "r": 0, "t": 40, "b": 0},
        "scene": {
            "aspectmode": "data",
            "xaxis": {"title": {"text": "x_R [mm]"}},
            "yaxis": {"title": {"text": "y_R [mm]"}},
            "zaxis": {"title": {"text": "z_R [mm]"}},
        },
    }
    part = np.vstack([p.vertices() for p in weldmap_R.parts]) * MM if weldmap_R.parts else cloud.reshape(-1, 3)
    drawn = [cloud.reshape(-1, 3), part]
    if view is not None:
        extra, links = cell_traces(view)
        first_link = len(traces) + (1 if view.table is not None else 0)
        traces += extra
        slider = path_slider(view, links, first_link)
        if slider is not None:
            layout["sliders"] = [slider]
        drawn.append(view_points(view))
    everything = np.vstack(drawn)
    if len(part) and len(everything):  # the camera framed to the part, the axes over everything drawn
        lo, hi = everything.min(axis=0), everything.max(axis=0)
        layout["scene"] = framed_scene(lo, hi, part.min(axis=0), part.max(axis=0))
    return go.Figure(traces, layout)


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
    view: CellView | None = None,
) -> Path:
    """The 3D view of :func:`figure_3d` alone, as a self-contained HTML file (plotly.js inline: it opens without
    a network). Returns ``out_path``."""
    fig = figure_3d(cloud_R, weldmap_R, seams, torch_poses, tcp_paths, title=title, max_points=max_points, view=view)
    return write_text(out_path, fig.to_html(include_plotlyjs=True, full_html=True), what="page")
