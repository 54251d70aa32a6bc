"""The cell around the part in the 3D view (plotly): table, robot links, camera frusta, a slider along the path,
and a camera framed to the part.

Traces are plain dicts (plotly's JSON), so this module needs no plotly import. Input in the robot frame R [m]
as :class:`~cell.types.CellView` values; drawn in millimetres.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from cell.geometry import FloatArray
from cell.preview.solids import Mesh, box_mesh, frustum_segments, link_colour, link_meshes
from cell.preview.views import MM
from cell.types import CellView

TABLE_COLOUR = "#c8b89a"
CAMERA_COLOUR = "#6a3d9a"
_FOVY = math.pi / 4.0  # plotly's vertical field of view
_VIEW_DIR = np.array([0.55, 1.0, 1.15])  # from the far side of the table, above: the robot behind the part
_FRAME_MARGIN = 1.6  # the part's bounding sphere fills 1/1.6 of the view's height: the robot behind it in view


def _r(a: FloatArray) -> list[float]:
    return [round(float(v), 1) for v in a]


def _mesh_trace(mesh: Mesh, name: str, colour: str, opacity: float = 1.0, **extra: Any) -> dict[str, Any]:
    v, f = mesh.vertices, mesh.triangles
    return {
        "type": "mesh3d",
        "name": name,
        "x": _r(v[:, 0]),
        "y": _r(v[:, 1]),
        "z": _r(v[:, 2]),
        "i": f[:, 0].tolist(),
        "j": f[:, 1].tolist(),
        "k": f[:, 2].tolist(),
        "color": colour,
        "opacity": opacity,
        "flatshading": True,
        "showlegend": True,
        "hoverinfo": "name",
        **extra,
    }


def cell_traces(view: CellView) -> tuple[list[dict[str, Any]], list[str]]:
    """The table, one mesh per robot link (at the first pose: the scan pose) and one line trace per camera
    frustum; with the names of the link traces in order (the slider moves them)."""
    traces: list[dict[str, Any]] = []
    if view.table is not None:
        traces.append(_mesh_trace(box_mesh(view.table), "table", TABLE_COLOUR, 0.45))
    links: list[str] = []
    if view.poses:
        meshes = link_meshes(view.shapes, view.poses[0])
        for k, (link, mesh) in enumerate(meshes.items()):
            name = f"robot {link}"
            colour = link_colour(view.shapes, link)
            extra: dict[str, Any] = {"legendgrouptitle": {"text": "robot (URDF shapes)"}} if k == 0 else {}
            traces.append(_mesh_trace(mesh, name, colour, legendgroup="robot", **extra))
            links.append(link)
    for cam in view.cameras:
        segs = frustum_segments(cam)
        xs: list[float | None] = []
        ys: list[float | None] = []
        zs: list[float | None] = []
        for a, b in segs:
            xs += [round(float(a[0]), 1), round(float(b[0]), 1), None]
            ys += [round(float(a[1]), 1), round(float(b[1]), 1), None]
            zs += [round(float(a[2]), 1), round(float(b[2]), 1), None]
        ki = cam.intrinsics
        hover = f"camera {cam.name} ({cam.mount}), {ki.width}x{ki.height} px, fx {ki.fx:.0f} px"
        traces.append(
            {
                "type": "scatter3d",
                "mode": "lines",
                "name": f"camera {cam.name}",
                "legendgroup": "cameras",
                "x": xs,
                "y": ys,
                "z": zs,
                "line": {"color": CAMERA_COLOUR, "width": 3, "dash": "dash" if cam.mount == "eye_in_hand" else "solid"},
                "hovertext": hover,
                "hoverinfo": "text",
            }
        )
    return traces, links


def path_slider(view: CellView, links: list[str], first_index: int) -> dict[str, Any] | None:
    """A slider over the robot's poses (scan pose, then along the plan) moving the link traces, which are
    ``first_index`` onwards in the figure's data; None with one pose or none."""
    if len(view.poses) < 2 or not links:
        return None
    idx = list(range(first_index, first_index + len(links)))
    steps = []
    for pose in view.poses:
        meshes = link_meshes(view.shapes, pose)
        xs = [_r(meshes[link].vertices[:, 0]) for link in links]
        ys = [_r(meshes[link].vertices[:, 1]) for link in links]
        zs = [_r(meshes[link].vertices[:, 2]) for link in links]
        steps.append({"method": "restyle", "label": pose.label, "args": [{"x": xs, "y": ys, "z": zs}, idx]})
    return {
        "active": 0,
        "steps": steps,
        "currentvalue": {"prefix": "robot: "},
        "pad": {"t": 10},
        "len": 0.9,
        "x": 0.05,
    }


def view_points(view: CellView) -> FloatArray:
    """(n, 3) [mm]: the table's corners, the robot's vertices at every pose and the camera frusta ((0, 3) when
    the view has none): what the axes must hold."""
    pts: list[FloatArray] = [np.zeros((0, 3))]
    if view.table is not None:
        pts.append(view.table.corners() * MM)
    for pose in view.poses:
        pts += [m.vertices for m in link_meshes(view.shapes, pose).values()]
    pts += [cam.frustum() * MM for cam in view.cameras]
    return np.vstack(pts)


def framed_scene(lo: FloatArray, hi: FloatArray, part_lo: FloatArray, part_hi: FloatArray) -> dict[str, Any]:
    """Scene layout [mm]: axes over lo..hi at equal scale, the camera looking at the part's box part_lo..part_hi
    from above the table's far side, close enough that the part fills most of the view (plotly's camera
    vectors live in the scene's unit box: each axis spans its aspect ratio, centred on 0)."""
    lo, hi = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
    span = np.maximum(hi - lo, 1.0)
    pad = 0.02 * span
    lo, hi = lo - pad, hi + pad
    span = hi - lo
    scale = 1.0 / float(span.max())  # scene units per mm (equal on every axis)
    aspect = span * scale
    mid = (lo + hi) / 2.0
    c_mm = (np.asarray(part_lo) + np.asarray(part_hi)) / 2.0
    radius = 0.5 * float(np.linalg.norm(np.asarray(part_hi) - np.asarray(part_lo))) * scale
    centre = (c_mm - mid) * scale
    eye = centre + _VIEW_DIR / np.linalg.norm(_VIEW_DIR) * (_FRAME_MARGIN * radius / math.sin(_FOVY / 2.0))

    def vec(v: FloatArray) -> dict[str, float]:
        return {"x": float(v[0]), "y": float(v[1]), "z": float(v[2])}

    return {
        "aspectmode": "manual",
        "aspectratio": vec(aspect),
        "xaxis": {"title": {"text": "x_R [mm]"}, "range": [float(lo[0]), float(hi[0])], "autorange": False},
        "yaxis": {"title": {"text": "y_R [mm]"}, "range": [float(lo[1]), float(hi[1])], "autorange": False},
        "zaxis": {"title": {"text": "z_R [mm]"}, "range": [float(lo[2]), float(hi[2])], "autorange": False},
        "camera": {"center": vec(centre), "eye": vec(eye), "up": {"x": 0.0, "y": 0.0, "z": 1.0}},
    }
