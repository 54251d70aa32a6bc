"""A welding map written for a person to review: parts as MESH bodies on layers named after them, fixtures as
blocks inserted on a fixture layer, proposed seams red on ``WELD_SEAMS`` (lines; arcs and circles in their plane),
rejected ones grey on ``WELD_REJECTED``, each with its id and a note as XDATA. Millimetres; the file is byte-stable.

Moving a seam between the two layers, or an INSERT between ``PARTS`` and a fixture layer, is the whole edit."""

from __future__ import annotations

import math
from collections import OrderedDict
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import ezdxf
import numpy as np
from ezdxf.entities import DXFGraphic
from ezdxf.math import OCS, Vec3
from ezdxf.render import MeshBuilder

from cell.geometry import FloatArray
from cell.weldmap._walk import SEAM_APPID

SEAM_LAYER = "WELD_SEAMS"
REJECTED_LAYER = "WELD_REJECTED"
FIXTURE_LAYER = "FIXTURES"
FASTENER_LAYER = "FIXTURE_FASTENERS"
NOTE_APPID = "WELDCELL_NOTE"
_RED, _GREY, _BLUE, _WHITE = 1, 8, 5, 7
MM_PER_M = 1000.0


@dataclass(frozen=True)
class DrawnBody:
    """A body to draw: ``layer`` None for a part (its own layer), else the fixture layer its INSERT goes on."""

    name: str
    vertices: FloatArray  # (k, 3) [m]
    triangles: np.ndarray  # (t, 3)
    layer: str | None = None


@dataclass(frozen=True)
class DrawnSeam:
    """A seam to draw [m]: a line (``points`` its ends), an arc (``centre``, unit ``axis``, ``radius``, unit
    ``start``, ``sweep`` [rad], a full circle at 2 pi) or a curve (``points`` (n, 3), drawn as a spline)."""

    id: str
    kind: str  # "line", "arc" or "curve"
    points: FloatArray
    rejected: bool
    note: str
    centre: FloatArray | None = None
    axis: FloatArray | None = None
    radius: float = 0.0
    start: FloatArray | None = None
    sweep: float = 0.0


def _mm(p: FloatArray) -> Vec3:
    return Vec3(*(float(x) * MM_PER_M for x in p))


def _mesh(body: DrawnBody) -> MeshBuilder:
    mesh = MeshBuilder()
    mesh.vertices = [_mm(v) for v in body.vertices]
    mesh.faces = [tuple(int(i) for i in t) for t in body.triangles]
    return mesh


def _seam(msp: ezdxf.layouts.Modelspace, s: DrawnSeam) -> None:
    attribs: dict[str, object] = {"layer": REJECTED_LAYER if s.rejected else SEAM_LAYER, "color": 256}
    e: DXFGraphic
    if s.kind == "line":
        e = msp.add_line(_mm(s.points[0]), _mm(s.points[1]), dxfattribs=attribs)
    elif s.kind == "arc" and s.centre is not None and s.axis is not None and s.start is not None:
        ocs = OCS(Vec3(*s.axis))
        centre = ocs.from_wcs(_mm(s.centre))
        attribs["extrusion"] = Vec3(*s.axis)
        if s.sweep >= 2.0 * math.pi - 1e-9:
            e = msp.add_circle(centre, s.radius * MM_PER_M, dxfattribs=attribs)
        else:
            u = ocs.from_wcs(Vec3(*s.start))
            a0 = math.degrees(math.atan2(u.y, u.x))
            e = msp.add_arc(centre, s.radius * MM_PER_M, a0, a0 + math.degrees(s.sweep), dxfattribs=attribs)
    else:
        e = msp.add_spline([_mm(p) for p in s.points], dxfattribs=attribs)
    e.set_xdata(SEAM_APPID, [(1000, s.id)])
    e.set_xdata(NOTE_APPID, [(1000, s.note[:250])])


def build(bodies: Sequence[DrawnBody], seams: Sequence[DrawnSeam]) -> ezdxf.document.Drawing:
    """The drawing (millimetres, ``$INSUNITS`` 4)."""
    doc = ezdxf.new("R2018", units=4)
    doc.appids.add(SEAM_APPID)
    doc.appids.add(NOTE_APPID)
    doc.layers.add(SEAM_LAYER, color=_RED)
    doc.layers.add(REJECTED_LAYER, color=_GREY)
    msp = doc.modelspace()
    for body in bodies:
        if body.layer is None:
            doc.layers.add(body.name, color=_WHITE)
            _mesh(body).render_mesh(msp, dxfattribs={"layer": body.name, "color": 256})
            continue
        if body.layer not in doc.layers:
            doc.layers.add(body.layer, color=_BLUE)
        block = doc.blocks.new(body.name)
        _mesh(body).render_mesh(block, dxfattribs={"layer": "0", "color": 0})
        msp.add_blockref(body.name, (0.0, 0.0, 0.0), dxfattribs={"layer": body.layer, "color": 256})
    for s in seams:
        _seam(msp, s)
    return doc


def write_map(path: str | Path, bodies: Sequence[DrawnBody], seams: Sequence[DrawnSeam]) -> Path:
    """Write the drawing of :func:`build` to ``path`` (byte-stable: ezdxf's fixed metadata, sorted classes)."""
    path = Path(path)
    fixed = ezdxf.options.write_fixed_meta_data_for_testing
    ezdxf.options.write_fixed_meta_data_for_testing = True
    try:
        doc = build(bodies, seams)
        doc.classes.add_required_classes(doc.dxfversion)
        doc.classes.classes = OrderedDict(sorted(doc.classes.classes.items()))
        path.parent.mkdir(parents=True, exist_ok=True)
        doc.saveas(path)
    finally:
        ezdxf.options.write_fixed_meta_data_for_testing = fixed
    return path
