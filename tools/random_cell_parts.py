"""The bodies and seams of a generated welding map, and the DXF that draws them (used by ``tools/random_cells.py``).

Everything here is in the map frame M in millimetres, z = 0 on the table top (the conventions of
``tools/make_maps.py``). A :class:`Body` is a closed polyhedron (vertices, faces counter-clockwise seen from outside)
built by :func:`prism` (an outline extruded, then moved) or :func:`hollow` (two outlines, an open-ended tube); a
:class:`Seam` is a straight fillet line with the two parts it joins and its dihedral; a :class:`Circle` is a curved
seam the cell reads and lists as not welded. :func:`write_map` draws them: each body on a layer named after it (MESH or
3DFACE), fixtures on ``FIXTURE_*`` layers, seams as red LINEs (circles as red CIRCLEs) on ``WELD_SEAMS`` with their
ids as ``WELDCELL`` XDATA, byte-stable.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

import ezdxf
import numpy as np
import numpy.typing as npt
from ezdxf.document import Drawing
from ezdxf.render import MeshBuilder
from make_maps import APPID, PART_LAYER_COLOR, SEAM_LAYER_COLOR, write_stable

SEAM_LAYER = "WELD_SEAMS"
DrawnAs = Literal["mesh", "3dface"]


@dataclass(frozen=True)
class Body:
    """One closed body of the map [mm, frame M].

    name : its layer. kind : plate, box, rhs, flat, brace, tube, pipe (parts) or fixture. vertices : (k, 3).
    faces : vertex-index tuples, counter-clockwise seen from outside. centre_mm, rpy_deg : the pose the generator
    built it at (its own frame: x along its length, z up for a standing member). size_mm : its extents in that
    frame. drawn_as : MESH or 3DFACE entities. extra : kind-specific figures for the truth (wall, radius, angle).
    """

    name: str
    kind: str
    vertices: np.ndarray
    faces: tuple[tuple[int, ...], ...]
    centre_mm: tuple[float, float, float]
    rpy_deg: tuple[float, float, float]
    size_mm: tuple[float, float, float]
    drawn_as: DrawnAs = "mesh"
    extra: dict[str, float] = field(default_factory=dict)

    @property
    def is_fixture(self) -> bool:
        return self.kind == "fixture"


@dataclass(frozen=True)
class Seam:
    """A straight fillet [mm, frame M]: ``abutting`` meets ``receiving`` along p0 -> p1; ``dihedral_deg`` between
    the weld faces, ``joint`` T, corner or lap (as drawn; the reader's joint finder must agree)."""

    id: str
    p0: tuple[float, float, float]
    p1: tuple[float, float, float]
    abutting: str
    receiving: str
    dihedral_deg: float
    joint: str = "T"

    @property
    def length_mm(self) -> float:
        return math.dist(self.p0, self.p1)


@dataclass(frozen=True)
class Circle:
    """A curved seam drawn as a red CIRCLE (centre, radius [mm], horizontal): read as a curved seam, not welded."""

    id: str
    centre: tuple[float, float, float]
    radius: float


def rot_z(deg: float) -> np.ndarray:
    """(3, 3) rotation about z by ``deg`` degrees."""
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def pose(R: npt.ArrayLike, t: npt.ArrayLike) -> np.ndarray:
    """(4, 4) pose from a rotation (3, 3) and a translation (3,)."""
    X = np.eye(4)
    X[:3, :3], X[:3, 3] = np.asarray(R, dtype=float), np.asarray(t, dtype=float)
    return X


def moved(X: np.ndarray, p: npt.ArrayLike) -> np.ndarray:
    """Points (n, 3) or (3,) moved by the pose X (4, 4)."""
    q = np.asarray(p, dtype=float)
    return q @ X[:3, :3].T + X[:3, 3]


def vec(p: npt.ArrayLike) -> tuple[float, float, float]:
    """A point as a plain tuple, rounded to 1 nm (so that the drawing is the same on every machine)."""
    a = np.asarray(p, dtype=float).reshape(3)
    return (round(float(a[0]), 6) + 0.0, round(float(a[1]), 6) + 0.0, round(float(a[2]), 6) + 0.0)


def prism(
    outline: npt.ArrayLike, z0: float, z1: float, X: np.ndarray
) -> tuple[np.ndarray, tuple[tuple[int, ...], ...]]:
    """A convex outline (n, 2), counter-clockwise in its (x, y) plane, extruded from z0 to z1 in its own frame and
    moved by X (4, 4): vertices (2n, 3) and faces (bottom, top, n sides), outward."""
    o = np.asarray(outline, dtype=float)
    n = len(o)
    v = np.array([[x, y, z] for z in (z0, z1) for x, y in o])
    faces = [tuple(range(n - 1, -1, -1)), tuple(range(n, 2 * n))]
    faces += [(i, (i + 1) % n, n + (i + 1) % n, n + i) for i in range(n)]
    return moved(X, v), tuple(faces)


def hollow(
    outer: npt.ArrayLike, inner: npt.ArrayLike, z0: float, z1: float, X: np.ndarray
) -> tuple[np.ndarray, tuple[tuple[int, ...], ...]]:
    """An open-ended tube between two outlines (m, 2) of as many points, both counter-clockwise, extruded from z0
    to z1 and moved by X: one closed body (outer and inner shells, a ring of quads at each end), outward."""
    o, i = np.asarray(outer, dtype=float), np.asarray(inner, dtype=float)
    m = len(o)
    v = np.array([[x, y, z] for ring in (o, i) for z in (z0, z1) for x, y in ring])
    o0, o1, i0, i1 = 0, m, 2 * m, 3 * m
    faces: list[tuple[int, ...]] = []
    for p in range(m):
        q = (p + 1) % m
        faces += [
            (o0 + p, o0 + q, o1 + q, o1 + p),  # outer shell
            (i0 + p, i1 + p, i1 + q, i0 + q),  # inner shell, facing the hollow
            (o1 + p, o1 + q, i1 + q, i1 + p),  # end ring at z1
            (o0 + q, o0 + p, i0 + p, i0 + q),  # end ring at z0
        ]
    return moved(X, v), tuple(faces)


def rectangle(a: float, b: float) -> np.ndarray:
    """(4, 2) an a x b rectangle about the origin, counter-clockwise."""
    return np.array([[-a / 2, -b / 2], [a / 2, -b / 2], [a / 2, b / 2], [-a / 2, b / 2]])


def rounded_rectangle(a: float, b: float, radius: float, facets: int = 4) -> np.ndarray:
    """(4 (facets + 1), 2) an a x b rectangle about the origin with corners rounded to ``radius``, each quarter
    round ``facets`` flat facets, counter-clockwise (the flats join consecutive rounds)."""
    pts = []
    for q, (sa, sb) in enumerate(((1, 1), (-1, 1), (-1, -1), (1, -1))):
        ca, cb = sa * (a / 2 - radius), sb * (b / 2 - radius)
        for k in range(facets + 1):
            ang = math.radians(90.0 * q + 90.0 * k / facets)
            pts.append((ca + radius * math.cos(ang), cb + radius * math.sin(ang)))
    return np.array(pts)


def polygon(radius: float, n: int, phase_deg: float = 0.0) -> np.ndarray:
    """(n, 2) a regular n-gon with its corners on a circle of ``radius``, counter-clockwise, the first at
    ``phase_deg``."""
    t = np.radians(phase_deg) + 2.0 * np.pi * np.arange(n) / n
    return np.column_stack([radius * np.cos(t), radius * np.sin(t)])


def box_body(name: str, kind: str, size: Sequence[float], centre: Sequence[float], yaw_deg: float) -> Body:
    """An a x b x c box (its x along ``size[0]``) with its centre at ``centre``, turned ``yaw_deg`` about z."""
    a, b, c = size
    X = pose(rot_z(yaw_deg), centre)
    v, f = prism(rectangle(a, b), -c / 2, c / 2, X)
    return Body(name, kind, v, f, vec(centre), (0.0, 0.0, yaw_deg), (a, b, c))


def _layer_name(body: Body) -> str:
    return body.name


def _draw_body(msp: ezdxf.layouts.Modelspace, body: Body) -> None:
    attribs = {"layer": _layer_name(body), "color": 256}
    verts = [vec(p) for p in body.vertices]
    if body.drawn_as == "mesh":
        mesh = MeshBuilder()
        mesh.vertices = [ezdxf.math.Vec3(p) for p in verts]
        mesh.faces = [list(f) for f in body.faces]
        mesh.render_mesh(msp, dxfattribs=attribs)
        return
    for face in body.faces:  # 3DFACE: at most four corners each; larger faces as a fan of triangles
        corners = [verts[k] for k in face]
        if len(corners) <= 4:
            msp.add_3dface(corners + corners[-1:] * (4 - len(corners)), dxfattribs=attribs)
            continue
        for k in range(1, len(corners) - 1):
            msp.add_3dface([corners[0], corners[k], corners[k + 1], corners[k + 1]], dxfattribs=attribs)


def build_map(bodies: Sequence[Body], seams: Sequence[Seam], circles: Sequence[Circle] = ()) -> Drawing:
    """The drawing of a generated cell: bodies on their layers, seams and circles red on ``WELD_SEAMS``."""
    doc = ezdxf.new("R2018", units=4)
    doc.appids.add(APPID)
    msp = doc.modelspace()
    doc.layers.add(SEAM_LAYER, color=SEAM_LAYER_COLOR)
    for body in bodies:
        doc.layers.add(_layer_name(body), color=PART_LAYER_COLOR)
        _draw_body(msp, body)
    for s in seams:
        line = msp.add_line(s.p0, s.p1, dxfattribs={"layer": SEAM_LAYER, "color": 1})
        line.set_xdata(APPID, [(1000, s.id)])
    for c in circles:
        circle = msp.add_circle(c.centre, c.radius, dxfattribs={"layer": SEAM_LAYER, "color": 1})
        circle.set_xdata(APPID, [(1000, c.id)])
    return doc


def write_map(path: Path, bodies: Sequence[Body], seams: Sequence[Seam], circles: Sequence[Circle] = ()) -> Path:
    """Write :func:`build_map` to ``path``, byte-stable; returns the path."""
    return write_stable(lambda: build_map(bodies, seams, circles), path)


def foot_seams(member: Body, base: str, z: float, sides: Sequence[tuple[str, np.ndarray, np.ndarray]]) -> list[Seam]:
    """The fillets at a member's foot on the top face (height ``z``) of part ``base``: one per (face name, start,
    end) in ``sides``, the ends' xy [mm] taken at height z, dihedral 90 degrees."""
    out = []
    for face, a, b in sides:
        p0, p1 = vec((a[0], a[1], z)), vec((b[0], b[1], z))
        out.append(Seam(f"{member.name}>{base}:{face}", p0, p1, member.name, base, 90.0))
    return out
