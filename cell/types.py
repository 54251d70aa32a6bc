"""The vocabulary of the cell: frozen dataclasses with read-only arrays.

Frames: ``W`` world, ``R`` robot base (KUKA $ROBROOT), ``M`` welding map (DXF drawing), ``C`` camera optical frame
(z forward, x right, y down), ``B`` a box part's own frame (axes along its edges, origin at its centre).
Units: metres and radians everywhere inside; millimetres and degrees only at the edges (DXF, reports, KRL).
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray, invert, readonly, transform_points

# The six faces of a box, named by the outward normal in the box frame B.
BOX_FACES: tuple[str, ...] = ("+x", "-x", "+y", "-y", "+z", "-z")


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


@dataclass(frozen=True)
class Part:
    """A designed part of the welding map: a closed body, fitted by an oriented box.

    name : stable identifier (DXF layer or block name, upper case).
    box : the box in the frame the owning map is expressed in.
    """

    name: str
    box: Box


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


@dataclass(frozen=True)
class WeldMap:
    """A welding map: designed parts and weld seams, all in ``frame`` (``M`` as drawn, ``R`` once aligned).

    units : the drawing units the file declared (or the scenario stated), e.g. ``"mm"``; geometry here is in metres.
    source : where it was read from.
    """

    parts: tuple[Part, ...]
    seams: tuple[MapSeam, ...]
    units: str
    source: str
    frame: str = "M"

    def transformed(self, X_AF: FloatArray, frame: str) -> WeldMap:
        """The whole map expressed in frame ``frame`` given the pose X_AF of its current frame F in A."""
        return WeldMap(
            parts=tuple(Part(p.name, p.box.transformed(X_AF)) for p in self.parts),
            seams=tuple(s.transformed(X_AF) for s in self.seams),
            units=self.units,
            source=self.source,
            frame=frame,
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


@dataclass(frozen=True)
class CameraIntrinsics:
    """Pinhole intrinsics [px] of a depth image, optical frame z forward, x right, y down."""

    width: int
    height: int
    fx: float
    fy: float
    cx: float
    cy: float

    @property
    def K(self) -> FloatArray:
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])


@dataclass(frozen=True)
class DepthImage:
    """One depth capture.

    depth : (height, width) float32 metric depth along the optical axis [m]; 0 marks an invalid pixel.
    X_WC : (4, 4) pose of the optical frame in the world *as calibrated* (what perception may use; in simulation
        it can differ from the true pose by the scenario's extrinsic error).
    mount : ``"fixed"`` or ``"eye_in_hand"``.
    """

    camera: str
    depth: npt.NDArray[np.float32]
    intrinsics: CameraIntrinsics
    X_WC: FloatArray
    mount: str = "fixed"

    def __post_init__(self) -> None:
        object.__setattr__(self, "depth", readonly(self.depth, np.float32))
        object.__setattr__(self, "X_WC", readonly(self.X_WC))
        if self.depth.shape != (self.intrinsics.height, self.intrinsics.width):
            raise ValueError(
                f"depth image of camera {self.camera!r} is {self.depth.shape}, intrinsics say "
                f"{(self.intrinsics.height, self.intrinsics.width)}"
            )


@dataclass(frozen=True)
class Cloud:
    """A point cloud in ``frame``.

    points : (n, 3) [m].
    camera : (n,) int16 index of the capture each point came from (-1 when unknown or mixed).
    cameras : names of the captures, indexed by ``camera``.
    """

    points: FloatArray
    frame: str
    camera: npt.NDArray[np.int16] = field(default_factory=lambda: np.zeros(0, np.int16))
    cameras: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        pts = readonly(self.points)
        if pts.ndim != 2 or pts.shape[1] != 3:
            raise ValueError(f"Cloud points must be (n, 3), got {pts.shape}")
        cam = np.asarray(self.camera, dtype=np.int16)
        if cam.size == 0:
            cam = np.full(len(pts), -1, np.int16)
        if cam.shape != (len(pts),):
            raise ValueError(f"Cloud camera indices must be ({len(pts)},), got {cam.shape}")
        object.__setattr__(self, "points", pts)
        object.__setattr__(self, "camera", readonly(cam, np.int16))

    def __len__(self) -> int:
        return len(self.points)

    def select(self, mask: npt.NDArray[np.bool_] | npt.NDArray[np.intp]) -> Cloud:
        return Cloud(self.points[mask], self.frame, self.camera[mask], self.cameras)

    def transformed(self, X_AF: FloatArray, frame: str) -> Cloud:
        return Cloud(transform_points(X_AF, self.points), frame, self.camera, self.cameras)


class SeamStatus(enum.StrEnum):
    """What became of a seam."""

    FOUND = "found"
    NOT_VISIBLE = "not_visible"  # no camera can see it by design (against the table): flip the part
    NOT_FOUND = "not_found"  # visible, but the data does not support a seam there
    OCCLUDED = "occluded"  # visible by design, but something the map does not know is in the way: clear it


@dataclass(frozen=True)
class SeamEstimate:
    """A locator's answer for one seam, in frame ``R``.

    p_start, p_end : (3,) [m] when ``status`` is FOUND; empty arrays otherwise.
    confidence : in [0, 1]; 0 when not found.
    time_s : wall time the locator spent on this seam [s].
    """

    id: str
    status: SeamStatus
    reason: str = ""
    p_start: FloatArray = field(default_factory=lambda: np.zeros(0))
    p_end: FloatArray = field(default_factory=lambda: np.zeros(0))
    confidence: float = 0.0
    time_s: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "p_start", readonly(self.p_start))
        object.__setattr__(self, "p_end", readonly(self.p_end))
        if self.status is SeamStatus.FOUND and (self.p_start.shape != (3,) or self.p_end.shape != (3,)):
            raise ValueError(f"seam {self.id}: a found seam needs start and end points")
