"""The welding map's vocabulary: boxes, parts, seams and the map that holds them. A part's body is a :class:`Box` (the
fast special case) or a :class:`Polyhedron` (any closed planar-faced body), both with the same methods.
Frames: ``M`` welding map, ``R`` robot base, ``W`` world, ``B`` a box's own frame. Metres and radians."""

from __future__ import annotations

import enum
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray, invert, readonly, transform_points
from cell.types.curves import CurvedSeam, Cylinder
from cell.types.solid import Polyhedron

__all__ = ["BOX_FACES", "Box", "MapSeam", "Part", "Polyhedron", "Unsupported", "UnsupportedSeam", "WeldMap"]

# The six faces of a box, named by the outward normal in the box frame B.
BOX_FACES: tuple[str, ...] = ("+x", "-x", "+y", "-y", "+z", "-z")
# Each face's corners (indices into Box.corners(), bits (x, y, z)), counter-clockwise seen from outside.
_BOX_POLYGONS: tuple[tuple[int, ...], ...] = (
    (4, 6, 7, 5),
    (0, 1, 3, 2),
    (2, 3, 7, 6),
    (0, 4, 5, 1),
    (1, 5, 7, 3),
    (0, 2, 6, 4),
)


def _face_axis_sign(face: str) -> tuple[int, float]:
    if face not in BOX_FACES:
        raise ValueError(f"unknown box face {face!r}; valid: {', '.join(BOX_FACES)}")
    return "xyz".index(face[1]), (1.0 if face[0] == "+" else -1.0)


@dataclass(frozen=True)
class Box:
    """An oriented box (a box tube drawn as a solid).

    X_AB : (4, 4) pose of the box frame B (centre, axes along the edges) in the frame A it is given in.
    size : (3,) edge lengths along B's x, y, z [m].
    """

    X_AB: FloatArray
    size: FloatArray

    def __post_init__(self) -> None:
        object.__setattr__(self, "X_AB", readonly(self.X_AB))
        object.__setattr__(self, "size", readonly(self.size))
        if self.X_AB.shape != (4, 4) or self.size.shape != (3,) or np.any(self.size <= 0):
            raise ValueError("Box needs a (4, 4) pose and three positive edge lengths")

    @property
    def center(self) -> FloatArray:
        return self.X_AB[:3, 3]

    def corners(self) -> FloatArray:
        """(8, 3) corners in A; index bits (i, j, k) choose -/+ half-size along x, y, z."""
        signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=float)
        return transform_points(self.X_AB, signs * (self.size / 2.0))

    def face_plane(self, face: str) -> tuple[FloatArray, float]:
        """Outward unit normal n_A (3,) and offset d [m] of a face, so that the face lies in n . p = d."""
        axis, sign = _face_axis_sign(face)
        n = sign * self.X_AB[:3, axis]
        d = float(n @ self.center + self.size[axis] / 2.0)
        return n, d

    def transformed(self, X_CA: FloatArray) -> Box:
        """The same box expressed in frame C."""
        return Box(X_CA @ self.X_AB, self.size)

    def contains(self, p_A: npt.ArrayLike, margin: float = 0.0) -> npt.NDArray[np.bool_]:
        """Which points (n, 3) lie inside the box grown by ``margin`` [m]."""
        p_B = transform_points(invert(self.X_AB), p_A)
        return np.all(np.abs(p_B) <= self.size / 2.0 + margin, axis=-1)

    def face_names(self) -> tuple[str, ...]:
        """The six faces' names (:data:`BOX_FACES`)."""
        return BOX_FACES

    def face_polygon(self, face: str) -> FloatArray:
        """(4, 3) the face's corners, counter-clockwise seen from outside [m]."""
        _face_axis_sign(face)
        return np.array(self.corners()[list(_BOX_POLYGONS[BOX_FACES.index(face)])])

    def triangles(self) -> npt.NDArray[np.intp]:
        """(12, 3) indices into :meth:`corners`, two triangles per face, outward winding."""
        return np.array([(f[0], f[k], f[k + 1]) for f in _BOX_POLYGONS for k in (1, 2)], dtype=np.intp)

    @property
    def radius(self) -> float:
        """The radius [m] of the sphere about the centre through the corners."""
        return 0.5 * float(np.linalg.norm(self.size))

    def edges(self) -> FloatArray:
        """(12, 2, 3) the box's edges as end-point pairs [m]."""
        c = self.corners()  # corner pairs whose indices differ in one bit
        pairs = [(i, i | bit) for i in range(8) for bit in (1, 2, 4) if not i & bit]
        return np.array([[c[i], c[j]] for i, j in pairs])

    def to_polyhedron(self) -> Polyhedron:
        """The same body as a :class:`Polyhedron` whose faces keep the box's names (``"+x"``, ...)."""
        return Polyhedron(self.corners(), _BOX_POLYGONS, BOX_FACES)


@dataclass(frozen=True)
class Part:
    """A designed part of the welding map: a closed body, in the frame the owning map is expressed in.

    name : stable identifier (DXF layer or block name, in the drawing's case).
    body : the body, a :class:`Box` (the fast special case) or a :class:`Polyhedron` (any closed planar-faced body).
    drawn_as : how the map drew it (``"3DSOLID"``, ``"MESH"``, ``"POLYFACE"``, ``"3DFACE"``; ``""`` when not read
        from a drawing).
    cylinder : the round body its tessellated faces stand for (a tube, a pipe, a bar), when it is one; else None.

    The methods below are what a stage may ask of any body (its faces by name, their planes and polygons, which
    points lie inside, its vertices, triangles and edges, its centre and bounding radius, the body in another frame);
    stages use them so a polyhedral body can take the box's place. What still reads :attr:`box` is box-specific by
    nature and fails loudly (``TypeError``) on a polyhedral part: such a stage must check :attr:`is_box` first.
    """

    name: str
    body: Box | Polyhedron
    drawn_as: str = ""
    cylinder: Cylinder | None = None

    @property
    def is_box(self) -> bool:
        """Whether the body is a :class:`Box`."""
        return isinstance(self.body, Box)

    @property
    def box(self) -> Box:
        """The body as a :class:`Box`; a ``TypeError`` naming the part when it is a polyhedron."""
        if not isinstance(self.body, Box):
            raise TypeError(f"part {self.name} is not a box (drawn as {self.drawn_as or 'a polyhedron'})")
        return self.body

    @property
    def kind(self) -> str:
        """``"box"`` or ``"mesh"`` (a polyhedron), for reports."""
        return "box" if self.is_box else "mesh"

    def face_names(self) -> tuple[str, ...]:
        """The names of the body's faces (:data:`BOX_FACES` for a box, ``"f0"``, ``"f1"``, ... for a polyhedron)."""
        return self.body.face_names()

    def face_plane(self, face: str) -> tuple[FloatArray, float]:
        """Outward unit normal n (3,) and offset d [m] of the face named ``face``: it lies in n . p = d."""
        return self.body.face_plane(face)

    def face_polygon(self, face: str) -> FloatArray:
        """(m, 3) the face's vertices in order, counter-clockwise seen from outside [m]."""
        return self.body.face_polygon(face)

    def contains(self, p: npt.ArrayLike, margin: float = 0.0) -> npt.NDArray[np.bool_]:
        """Which points (n, 3) lie inside the body grown by ``margin`` [m]."""
        return self.body.contains(p, margin)

    def vertices(self) -> FloatArray:
        """(k, 3) the body's vertices [m] (a box's eight corners)."""
        return self.body.corners() if isinstance(self.body, Box) else np.array(self.body.vertices)

    def triangles(self) -> tuple[FloatArray, npt.NDArray[np.intp]]:
        """The body's surface as triangles: vertices (k, 3) [m] and (t, 3) indices into them, outward winding."""
        return self.vertices(), self.body.triangles()

    def edges(self) -> FloatArray:
        """(m, 2, 3) the body's (feature) edges as end-point pairs [m]."""
        return self.body.edges()

    @property
    def center(self) -> FloatArray:
        """(3,) the body's centre [m] (the centroid of its volume)."""
        return np.asarray(self.body.center)

    @property
    def radius(self) -> float:
        """The radius [m] of a sphere about :attr:`center` that holds the whole body."""
        return self.body.radius

    @property
    def volume(self) -> float:
        """The body's volume [m^3]."""
        return float(np.prod(self.body.size)) if isinstance(self.body, Box) else self.body.volume

    def transformed(self, X_CA: FloatArray) -> Part:
        """The same part expressed in frame C, given the pose X_CA of its current frame A in C."""
        cylinder = self.cylinder.transformed(X_CA) if self.cylinder is not None else None
        return Part(self.name, self.body.transformed(X_CA), self.drawn_as, cylinder)

    def moved(self, X_CA: FloatArray) -> Part:
        """:meth:`transformed` for a part moved rigidly many times (:meth:`Polyhedron.moved`)."""
        cylinder = self.cylinder.transformed(X_CA) if self.cylinder is not None else None
        body = self.body.moved(X_CA) if isinstance(self.body, Polyhedron) else self.body.transformed(X_CA)
        return Part(self.name, body, self.drawn_as, cylinder)


@dataclass(frozen=True)
class MapSeam:
    """A weld seam of the welding map (a red 3D line), in the owning map's frame.

    id : stable identifier taken from the map.
    p_start, p_end : (3,) end points [m].
    """

    id: str
    p_start: FloatArray
    p_end: FloatArray

    def __post_init__(self) -> None:
        object.__setattr__(self, "p_start", readonly(self.p_start))
        object.__setattr__(self, "p_end", readonly(self.p_end))

    @property
    def length(self) -> float:
        return float(np.linalg.norm(self.p_end - self.p_start))

    @property
    def direction(self) -> FloatArray:
        d = self.p_end - self.p_start
        return np.asarray(d / np.linalg.norm(d))

    def transformed(self, X_CA: FloatArray) -> MapSeam:
        return MapSeam(self.id, transform_points(X_CA, self.p_start), transform_points(X_CA, self.p_end))


class Unsupported(enum.StrEnum):
    """Why a seam the map draws is not one the cell can weld, as a code that code and tests read."""

    # A curved seam (an arc, circle, ellipse, spline, helix or bulged polyline segment) not located: no two parts
    # hold it (no joint), the locator cannot take it, or the run never came to locate it.
    CURVED_NOT_LOCATED = "curved_not_located"
    # A curved seam located (its CurveEstimate found) by a run that plans no weld (a detection, a locate): no torch
    # path was planned for it, so it is not welded by this run.
    CURVED_NO_TORCH_PATH = "curved_no_torch_path"
    ON_FIXTURE = "on_fixture"  # it lies on a fixture, not between two parts


class UnsupportedSeam(NamedTuple):
    """A seam the map draws that the cell cannot weld: its id, why in one line (``reason``, for people) and why as a
    code (``code``: an :class:`Unsupported`; a located curve the run could not weld: the planner's or the weld's
    code)."""

    id: str
    reason: str
    code: enum.StrEnum


@dataclass(frozen=True)
class WeldMap:
    """A welding map: designed parts and weld seams, all in ``frame`` (``M`` as drawn, ``R`` once aligned).

    units : the drawing units used (the file's ``$INSUNITS`` or the caller's override), e.g. ``"mm"``; geometry here
        is in metres.
    source : where it was read from.
    fixtures : clamps, stops and jigs drawn on the fixture layers: obstacles for the arm, never parts (never
        aligned, never welded).
    unsupported : seams drawn but not weldable (seams on a fixture), each with its reason.
    curved : the curved seams (arcs, circles, ellipses, splines, bulged polyline segments), typed curves with their
        joints; one that no two parts hold (no joint) cannot be located (:attr:`not_welded` lists it with code
        ``curved_not_located``); the others are located and welded or refused by a run, each with its reason.
    warnings : one line each: what the reader skipped or doubted (also logged on ``cell.weldmap``).
    """

    parts: tuple[Part, ...]
    seams: tuple[MapSeam, ...]
    units: str
    source: str
    frame: str = "M"
    fixtures: tuple[Part, ...] = ()
    unsupported: tuple[UnsupportedSeam, ...] = ()
    warnings: tuple[str, ...] = ()
    curved: tuple[CurvedSeam, ...] = ()

    @property
    def not_straight(self) -> tuple[UnsupportedSeam, ...]:
        """Every seam of the map outside :attr:`seams`, map order: each curved seam (what and where it is; a run
        locates it and welds or refuses it with its reason, :attr:`Detection.not_welded`), then
        :attr:`unsupported`."""
        curved = tuple(
            UnsupportedSeam(
                c.id,
                f"{c.drawn}: a curved seam ({c.kind}, {c.length * 1000:.0f} mm"
                + (f", {c.joint}" if c.joint is not None else "")
                + ("); not located in this run" if c.joint is not None else "); no two parts hold it: not located"),
                Unsupported.CURVED_NOT_LOCATED,
            )
            for c in self.curved
        )
        return curved + self.unsupported

    @property
    def not_welded(self) -> tuple[UnsupportedSeam, ...]:
        """Every seam of the map the cell will not weld whatever a run finds, with its reason: the curved seams no
        two parts hold (nothing to locate), then :attr:`unsupported`."""
        held = {c.id for c in self.curved if c.joint is not None}
        return tuple(u for u in self.not_straight if u.id not in held)

    def transformed(self, X_AF: FloatArray, frame: str) -> WeldMap:
        """The whole map expressed in frame ``frame`` given the pose X_AF of its current frame F in A."""
        return WeldMap(
            parts=tuple(p.transformed(X_AF) for p in self.parts),
            seams=tuple(s.transformed(X_AF) for s in self.seams),
            units=self.units,
            source=self.source,
            frame=frame,
            fixtures=tuple(f.transformed(X_AF) for f in self.fixtures),
            unsupported=self.unsupported,
            warnings=self.warnings,
            curved=tuple(c.transformed(X_AF) for c in self.curved),
        )

    def part(self, name: str) -> Part:
        for p in self.parts:
            if p.name == name:
                return p
        raise KeyError(f"no part {name!r}; parts: {', '.join(p.name for p in self.parts)}")

    def seam(self, seam_id: str) -> MapSeam:
        for s in self.seams:
            if s.id == seam_id:
                return s
        raise KeyError(f"no seam {seam_id!r}; seams: {', '.join(s.id for s in self.seams)}")
