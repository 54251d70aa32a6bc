"""Curved seams and round bodies: typed curves (an arc or circle, an ellipse, a sampled polyline with its chord
error), a cylinder recognised in a tessellated body, and a curved seam with its joint. Frames as in
:mod:`cell.types.map` (``M`` as drawn, ``R`` or ``W`` once moved); metres and radians. Numpy only."""

from __future__ import annotations

import enum
import itertools
import math
from dataclasses import dataclass

import numpy as np

from cell.geometry import FloatArray, readonly, transform_points

__all__ = [
    "ArcCurve",
    "CurvedJoint",
    "CurvedSeam",
    "Cylinder",
    "EllipseCurve",
    "SampledCurve",
    "Surface",
]

_TWO_PI = 2.0 * math.pi


def _unit(v: FloatArray) -> FloatArray:
    v = np.asarray(v, dtype=float)
    return np.asarray(v / np.linalg.norm(v))


def _count(length_m: float, step_m: float) -> int:
    if step_m <= 0.0:
        raise ValueError(f"a sampling step must be positive, got {step_m} m")
    return max(2, math.ceil(length_m / step_m) + 1)


@dataclass(frozen=True)
class ArcCurve:
    """A circular arc, or a full circle: p(t) = centre + radius (cos t x_axis + sin t (normal x x_axis)), t from 0 to
    ``sweep_rad`` (> 0, counter-clockwise about ``normal``; 2 pi: a circle). The start is at t = 0.

    centre (3,) [m]; normal (3,) unit; x_axis (3,) unit, in the plane (towards the start); radius [m].
    """

    centre: FloatArray
    normal: FloatArray
    x_axis: FloatArray
    radius: float
    sweep_rad: float

    def __post_init__(self) -> None:
        n = _unit(self.normal)
        x = _unit(self.x_axis - (self.x_axis @ n) * n)
        object.__setattr__(self, "centre", readonly(np.asarray(self.centre, dtype=float)))
        object.__setattr__(self, "normal", readonly(n))
        object.__setattr__(self, "x_axis", readonly(x))
        if not (self.radius > 0.0 and 0.0 < self.sweep_rad <= _TWO_PI + 1e-12):
            raise ValueError(
                f"an arc needs a positive radius and a sweep in (0, 2 pi], got {self.radius}, {self.sweep_rad}"
            )

    @property
    def kind(self) -> str:
        """``"circle"`` or ``"arc"``."""
        return "circle" if self.closed else "arc"

    @property
    def closed(self) -> bool:
        return self.sweep_rad >= _TWO_PI - 1e-9

    @property
    def length(self) -> float:
        return self.radius * self.sweep_rad

    @property
    def start_angle_rad(self) -> float:
        """0 by construction: the angles are measured from ``x_axis`` (the end angle is ``sweep_rad``)."""
        return 0.0

    def at(self, t: FloatArray) -> FloatArray:
        """(n, 3) the points at parameters t (n,) [rad]."""
        y = np.cross(self.normal, self.x_axis)
        t = np.asarray(t, dtype=float)[:, None]
        return np.asarray(self.centre + self.radius * (np.cos(t) * self.x_axis + np.sin(t) * y))

    def sample(self, step_m: float) -> FloatArray:
        """(n, 3) points at most ``step_m`` apart along the curve, start and end included (a circle repeats none)."""
        n = _count(self.length, step_m)
        t = np.linspace(0.0, self.sweep_rad, n, endpoint=not self.closed)
        return self.at(t)

    def transformed(self, X_CA: FloatArray) -> ArcCurve:
        """The arc in frame C (a rigid X_CA)."""
        R = np.asarray(X_CA)[:3, :3]
        return ArcCurve(
            transform_points(X_CA, self.centre), R @ self.normal, R @ self.x_axis, self.radius, self.sweep_rad
        )

    def scaled(self, s: float) -> ArcCurve:
        """The arc with every coordinate multiplied by ``s`` (drawing units to metres)."""
        return ArcCurve(self.centre * s, self.normal, self.x_axis, self.radius * s, self.sweep_rad)


@dataclass(frozen=True)
class EllipseCurve:
    """An elliptical arc: p(t) = centre + cos t major + sin t minor, t from ``start_rad`` over ``sweep_rad`` (> 0).

    centre (3,) [m]; major, minor (3,) the semi-axes as vectors (perpendicular, |minor| <= |major|) [m].
    """

    centre: FloatArray
    major: FloatArray
    minor: FloatArray
    start_rad: float
    sweep_rad: float

    def __post_init__(self) -> None:
        for name in ("centre", "major", "minor"):
            object.__setattr__(self, name, readonly(np.asarray(getattr(self, name), dtype=float)))
        if not 0.0 < self.sweep_rad <= _TWO_PI + 1e-12:
            raise ValueError(f"an ellipse needs a sweep in (0, 2 pi], got {self.sweep_rad}")

    kind = "ellipse"

    @property
    def normal(self) -> FloatArray:
        return _unit(np.cross(self.major, self.minor))

    @property
    def closed(self) -> bool:
        return self.sweep_rad >= _TWO_PI - 1e-9

    @property
    def length(self) -> float:
        t = np.linspace(self.start_rad, self.start_rad + self.sweep_rad, 2049)
        return float(np.linalg.norm(np.diff(self.at(t), axis=0), axis=1).sum())

    def at(self, t: FloatArray) -> FloatArray:
        t = np.asarray(t, dtype=float)[:, None]
        return np.asarray(self.centre + np.cos(t) * self.major + np.sin(t) * self.minor)

    def sample(self, step_m: float) -> FloatArray:
        """(n, 3) points at most ``step_m`` apart along the curve (evenly in the parameter: the step is the largest)."""
        speed = max(float(np.linalg.norm(self.major)), float(np.linalg.norm(self.minor)))  # the largest |dp/dt|
        n = _count(speed * self.sweep_rad, step_m)
        t = np.linspace(self.start_rad, self.start_rad + self.sweep_rad, n, endpoint=not self.closed)
        return self.at(t)

    def transformed(self, X_CA: FloatArray) -> EllipseCurve:
        R = np.asarray(X_CA)[:3, :3]
        return EllipseCurve(
            transform_points(X_CA, self.centre), R @ self.major, R @ self.minor, self.start_rad, self.sweep_rad
        )

    def scaled(self, s: float) -> EllipseCurve:
        return EllipseCurve(self.centre * s, self.major * s, self.minor * s, self.start_rad, self.sweep_rad)


@dataclass(frozen=True)
class SampledCurve:
    """A free curve (a spline, a helix) as a polyline: ``points`` (n, 3) [m] within ``chord_error_m`` of the drawn
    curve (the largest distance between a chord and the curve it stands for); ``closed``: the last point joins the
    first."""

    points: FloatArray
    chord_error_m: float
    closed: bool = False

    def __post_init__(self) -> None:
        p = np.asarray(self.points, dtype=float)
        if p.ndim != 2 or p.shape[1] != 3 or len(p) < 2:
            raise ValueError("a sampled curve needs (n >= 2, 3) points")
        object.__setattr__(self, "points", readonly(p))

    kind = "curve"

    def _loop(self) -> FloatArray:
        return np.vstack([self.points, self.points[:1]]) if self.closed else np.asarray(self.points)

    @property
    def length(self) -> float:
        return float(np.linalg.norm(np.diff(self._loop(), axis=0), axis=1).sum())

    def sample(self, step_m: float) -> FloatArray:
        """(n, 3) points at most ``step_m`` apart along the polyline, its own points included."""
        p = self._loop()
        out = []
        for a, b in itertools.pairwise(p):
            k = max(1, math.ceil(float(np.linalg.norm(b - a)) / step_m)) if step_m > 0 else 1
            out.append(a + (b - a) * (np.arange(k) / k)[:, None])
        if not self.closed:
            out.append(p[-1:])
        return np.vstack(out)

    def transformed(self, X_CA: FloatArray) -> SampledCurve:
        return SampledCurve(transform_points(X_CA, self.points), self.chord_error_m, self.closed)

    def scaled(self, s: float) -> SampledCurve:
        return SampledCurve(self.points * s, self.chord_error_m * s, self.closed)


Curve = ArcCurve | EllipseCurve | SampledCurve


@dataclass(frozen=True)
class Cylinder:
    """A round body recognised in a tessellated part (a tube, a pipe, a bar): its axis from ``p_base`` along
    ``axis`` (unit) for ``length`` [m], its outer ``radius`` [m] and its bore (``inner_radius``, 0 for a solid
    bar); ``facets``: how many flat faces stand for its round side in the drawing."""

    p_base: FloatArray
    axis: FloatArray
    radius: float
    length: float
    inner_radius: float = 0.0
    facets: int = 0

    def __post_init__(self) -> None:
        object.__setattr__(self, "p_base", readonly(np.asarray(self.p_base, dtype=float)))
        object.__setattr__(self, "axis", readonly(_unit(self.axis)))

    def distance_to_axis(self, p: FloatArray) -> FloatArray:
        """(n,) distance [m] of points (n, 3) from the axis line."""
        d = np.asarray(p, dtype=float) - self.p_base
        return np.asarray(np.linalg.norm(d - np.outer(d @ self.axis, self.axis), axis=1))

    def along(self, p: FloatArray) -> FloatArray:
        """(n,) position [m] of points (n, 3) along the axis from ``p_base``."""
        return np.asarray((np.asarray(p, dtype=float) - self.p_base) @ self.axis)

    @property
    def sagitta_m(self) -> float:
        """How far the drawn facets lie inside the true round surface at their middles [m]."""
        return self.radius * (1.0 - math.cos(math.pi / self.facets)) if self.facets else 0.0

    def transformed(self, X_CA: FloatArray) -> Cylinder:
        R = np.asarray(X_CA)[:3, :3]
        p = transform_points(X_CA, self.p_base)
        return Cylinder(p, R @ self.axis, self.radius, self.length, self.inner_radius, self.facets)


class Surface(enum.StrEnum):
    """The kind of surface a curved seam lies on, on one of its two parts."""

    PLANE = "plane"
    CYLINDER = "cylinder"


@dataclass(frozen=True)
class CurvedJoint:
    """Which parts a curved seam joins and on which surfaces: ``abutting`` (the part whose end or edge meets the
    other) on its ``abutting_surface``, ``receiving`` on its ``receiving_surface``; ``kind`` the joint type
    (``T``, ``corner``, ``lap``: a tube standing on a plate is a T fillet) and the dihedral's range along the seam
    [rad] (90 degrees all round for a tube square on a plate, 90 +- the lean for a leaning one)."""

    abutting: str
    receiving: str
    abutting_surface: Surface
    receiving_surface: Surface
    kind: str
    dihedral_min_rad: float
    dihedral_max_rad: float

    @property
    def surfaces(self) -> str:
        """``cylinder_on_plane``, ``cylinder_on_cylinder``, ``plane_on_cylinder``."""
        return f"{self.abutting_surface}_on_{self.receiving_surface}"

    def __str__(self) -> str:
        lo, hi = math.degrees(self.dihedral_min_rad), math.degrees(self.dihedral_max_rad)
        angle = f"{lo:.0f} deg" if hi - lo < 0.5 else f"{lo:.0f}-{hi:.0f} deg"
        return f"{self.kind} {self.abutting} > {self.receiving} ({self.surfaces}, {angle})"


@dataclass(frozen=True)
class CurvedSeam:
    """A curved weld seam of the welding map: its stable ``id``, its ``curve`` (in the owning map's frame), where it
    was drawn (``drawn``: entity, handle, layer) and its ``joint`` (None: no two parts hold it; ``note`` says why)."""

    id: str
    curve: Curve
    drawn: str
    joint: CurvedJoint | None = None
    note: str = ""

    @property
    def kind(self) -> str:
        """``circle``, ``arc``, ``ellipse`` or ``curve``."""
        return self.curve.kind

    @property
    def length(self) -> float:
        return self.curve.length

    def sample(self, step_m: float) -> FloatArray:
        """(n, 3) points at most ``step_m`` apart along the seam [m]."""
        return self.curve.sample(step_m)

    def transformed(self, X_CA: FloatArray) -> CurvedSeam:
        return CurvedSeam(self.id, self.curve.transformed(X_CA), self.drawn, self.joint, self.note)
