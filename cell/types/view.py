"""What a picture of the cell shows besides the part: the table, the robot's shapes at its poses, the cameras.

Values computed once by the pipeline (the robot's link poses by its forward kinematics, its shapes from the
URDF) so that pictures read values only. Frame ``R`` (robot base), metres.
"""

from __future__ import annotations

import enum
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray, readonly
from cell.types.map import Box
from cell.types.robot import JointLimits
from cell.types.sensing import CameraIntrinsics

MOTION_HZ = 20.0  # the arm's poses per second of motion a picture is given (plus every arc switch)
TCP = "torch_tcp"  # the arm's frame at the torch's tool centre point
EYE = "camera_optical"  # the arm's optical frame of its eye-in-hand camera (as the simulator names it)


class ShapeKind(enum.StrEnum):
    """The primitive solids of a URDF's geometry that a picture draws."""

    BOX = "box"
    CYLINDER = "cylinder"  # along its own z
    SPHERE = "sphere"


@dataclass(frozen=True)
class Shape:
    """One solid fixed to a robot link L.

    X_LS : (4, 4) pose of the solid's own frame S in L [m]. size : (3,) [m]: a box's edge lengths along S's axes;
    a cylinder's diameter, diameter and length (along S's z); a sphere's diameter three times.
    rgba : its colour (0..1 each).
    """

    link: str
    kind: ShapeKind
    X_LS: FloatArray
    size: FloatArray
    rgba: tuple[float, float, float, float] = (0.6, 0.6, 0.6, 1.0)

    def __post_init__(self) -> None:
        object.__setattr__(self, "X_LS", readonly(self.X_LS))
        object.__setattr__(self, "size", readonly(self.size))


@dataclass(frozen=True)
class RobotPose:
    """The arm's links at one instant: ``X_RL`` link name -> (4, 4) pose in R [m]; ``t_s`` the plan time [s]
    (nan for a pose off the plan, e.g. the scan pose); ``label`` what it is ("scan pose", "weld S3" ...)."""

    label: str
    X_RL: Mapping[str, FloatArray]
    t_s: float = float("nan")


@dataclass(frozen=True)
class CameraView:
    """A camera of the cell: its optical frame X_RC (4, 4) in R (z forward, x right, y down), its intrinsics,
    how it is mounted (``fixed`` / ``eye_in_hand``) and the depth ``range_m`` [m] to draw its frustum to."""

    name: str
    X_RC: FloatArray
    intrinsics: CameraIntrinsics
    mount: str = "fixed"
    range_m: float = 1.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "X_RC", readonly(self.X_RC))

    def frustum(self) -> FloatArray:
        """(5, 3) [m] in R: the optical centre, then the far corners (top-left, top-right, bottom-right,
        bottom-left in the image) at depth ``range_m``."""
        k = self.intrinsics
        u = np.array([-0.5, k.width - 0.5, k.width - 0.5, -0.5])
        v = np.array([-0.5, -0.5, k.height - 0.5, k.height - 0.5])
        z = self.range_m
        p_C = np.column_stack([(u - k.cx) / k.fx * z, (v - k.cy) / k.fy * z, np.full(4, z)])
        p_C = np.vstack([np.zeros(3), p_C])
        return np.asarray(p_C @ self.X_RC[:3, :3].T + self.X_RC[:3, 3])


@dataclass(frozen=True)
class ArmMotion:
    """The arm's motion as pictures show it: what it did when it moved, else the plan's (the move from the scan
    pose home, then the program), on one time axis [s] (0 where the move home starts).

    At the instants ``times_s`` (k,) (every 1 / ``rate_hz`` and both sides of every arc switch): the joints ``q``
    (k, dof) [rad], the arc ``arc`` (k,) and, per frame name, ``X_RL`` (k, 4, 4) in R [m] (the links that carry a
    shape, the TCP, the eye-in-hand camera's optical frame: those the arm has). The whole tool path ``tool_R``
    (m, 3) [m] in R with its arc ``tool_arc`` (m,): the executed one, else the planned TCP. ``marks``: (time [s],
    text) of every move and arc switch.
    """

    times_s: FloatArray
    q: FloatArray
    arc: npt.NDArray[np.bool_]
    X_RL: Mapping[str, FloatArray]
    tool_R: FloatArray
    tool_arc: npt.NDArray[np.bool_]
    marks: tuple[tuple[float, str], ...] = ()
    rate_hz: float = MOTION_HZ

    def __post_init__(self) -> None:
        for key in ("times_s", "q", "tool_R"):
            object.__setattr__(self, key, readonly(getattr(self, key)))
        for key in ("arc", "tool_arc"):
            object.__setattr__(self, key, readonly(getattr(self, key), bool))
        object.__setattr__(self, "X_RL", {k: readonly(v) for k, v in self.X_RL.items()})


@dataclass(frozen=True)
class CellView:
    """The cell around the part, in R: the table (a box, None when unknown), the robot's shapes (by link), its
    poses (the first is where it stands when the cloud is taken: the scan pose), the cameras; the arm's motion
    (None without a plan) and its joint limits (None without an arm)."""

    table: Box | None = None
    shapes: tuple[Shape, ...] = ()
    poses: tuple[RobotPose, ...] = ()
    cameras: tuple[CameraView, ...] = field(default_factory=tuple)
    motion: ArmMotion | None = None
    limits: JointLimits | None = None

    @property
    def links(self) -> tuple[str, ...]:
        """The links that carry a shape, in the order of their first shape."""
        return tuple(dict.fromkeys(s.link for s in self.shapes))
