"""The turn of the part for its second side: the plan made before anything moves, and what the second alignment
measured after the operator set the part down.

Frame R (robot base), metres and radians; millimetres and degrees only where a name says so.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from cell.geometry import FloatArray, invert, readonly


@dataclass(frozen=True)
class TurnoverPlan:
    """How the part is turned over so that the seams left after side A face up.

    axis : the part's principal axis turned about (``"x"``, ``"y"`` or ``"z"`` of the map's box frame P), with
        ``axis_R`` (3,) its direction in R and ``angle_rad`` the turn about it (pi: upside down).
    tilt_rad : how far the part leans after the turn, resting on the convex hull facet under its centre of mass
        (0 when its new lowest faces lie flat on the table).
    X_RM_after : (4, 4) the map's nominal pose after the turn (turned about the part's centre, set down at the
        same place); the second alignment starts from it. X_RM_before : (4, 4) the aligned map on side A.
    exposed : seam ids (left after side A) that face up after the turn and will be searched on side B.
    left : seam id -> why it stays out even after the turn (still against the table, facing down, out of the
        table).
    stable : the part rests with its centre of mass over its support; ``allowed`` : the scenario lets the part
        be turned; ``reason`` : why no turn is made ("" when it is).
    """

    axis: str
    axis_R: FloatArray
    angle_rad: float
    tilt_rad: float
    X_RM_after: FloatArray
    X_RM_before: FloatArray
    exposed: tuple[str, ...]
    left: Mapping[str, str] = field(default_factory=dict)
    stable: bool = True
    allowed: bool = True
    reason: str = ""

    def __post_init__(self) -> None:
        object.__setattr__(self, "axis_R", readonly(self.axis_R))
        object.__setattr__(self, "X_RM_after", readonly(self.X_RM_after))
        object.__setattr__(self, "X_RM_before", readonly(self.X_RM_before))

    @property
    def X_R_turn(self) -> FloatArray:
        """(4, 4) the nominal rigid motion of the part in R the turn makes (X_R_after_before)."""
        return np.asarray(self.X_RM_after @ invert(self.X_RM_before))

    @property
    def go(self) -> bool:
        """The part is to be turned: allowed, stable, and at least one seam exposed."""
        return self.allowed and self.stable and bool(self.exposed) and not self.reason


@dataclass(frozen=True)
class TurnoverResult:
    """What the second alignment found: where the part really lies after the turn, against its nominal pose.

    offset_m : horizontal distance [m] of the aligned map's centre from its nominal place after the turn.
    rotation_rad : the aligned map's turn about the vertical from its nominal pose [rad] (signed).
    fitness : the second alignment's fitness (the fraction of the cloud on the map's surfaces).
    X_RM : (4, 4) the aligned map after the turn.
    """

    offset_m: float
    rotation_rad: float
    fitness: float
    X_RM: FloatArray

    def __post_init__(self) -> None:
        object.__setattr__(self, "X_RM", readonly(self.X_RM))
