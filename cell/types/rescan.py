"""What a close-up re-scan did: the view it took of a seam, the estimates before and after, the moves it played.

Frame ``R`` (robot base) for every estimate and pose; metres, radians, seconds.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from cell.geometry import FloatArray, readonly
from cell.types.curve_estimate import CurveEstimate
from cell.types.execution import Execution
from cell.types.seams import SeamEstimate
from cell.types.trajectory import Trajectory


@dataclass(frozen=True)
class Viewpoint:
    """A checked close-up view of one seam.

    X_RC : (4, 4) pose of the camera's optical frame in R at the view (what IK reached).
    q : (dof,) [rad] the arm's configuration there; move : the checked jerk-limited move from the start.
    distance_m : from the camera to the seam's midpoint; incidence_deg : worst angle between a line of sight
    and face A's / face B's normal; tilt_deg, slant_deg, roll_deg : the candidate's angles; tried : candidates
    given IK and collision checks before this one passed, this one included.
    """

    seam_id: str
    X_RC: FloatArray
    q: FloatArray
    move: Trajectory
    distance_m: float
    incidence_deg: tuple[float, float]
    tilt_deg: float
    slant_deg: float
    roll_deg: float
    tried: int
    via: bool = False  # the move passes through q_via
    e1_m: float = 0.0  # [m] where a linear track's carriage stood for it (X_RC and q with the base there)

    def __post_init__(self) -> None:
        object.__setattr__(self, "X_RC", readonly(self.X_RC))
        object.__setattr__(self, "q", readonly(self.q))


@dataclass(frozen=True)
class SeamRescan:
    """What the re-scan did for one seam (all estimates in R).

    before : the first estimate; closeup : the close-up estimate (None when no image was taken); fused : what
    the cell should use now; weight : the close-up's share of the fused position (0: the first kept);
    viewpoint : the view (None when none was reachable); motion_s : robot time of the move to it [s];
    wall_s : wall time of planning, moving, capturing and locating [s]; reason : why the re-scan failed or was
    not used ('' when it was).
    """

    id: str
    before: SeamEstimate
    closeup: SeamEstimate | None
    fused: SeamEstimate
    weight: float
    viewpoint: Viewpoint | None
    motion_s: float
    wall_s: float
    reason: str = ""
    points: int = 0

    @property
    def used(self) -> bool:
        return self.weight > 0.0


@dataclass(frozen=True)
class CurveRescan:
    """What the re-scan did for one curved seam (all in R).

    before : the fixed cameras' curve (not found: as located); after : what the cell uses now (the fused curve, or
    ``before`` kept); views : the close-ups taken, in order; weight : the close-ups' share of the fused curve (0:
    ``before`` kept); motion_s : robot time of the moves for its views [s] (a track's carriage's too); chosen :
    whether the re-scan's choice took it (``cell rescan`` lists the curves it left, each with why); reason : why
    it was not re-scanned, or why the close-ups left it over the tolerance ('' when they brought it within).
    """

    id: str
    before: CurveEstimate
    after: CurveEstimate
    views: tuple[Viewpoint, ...] = ()
    weight: float = 0.0
    motion_s: float = 0.0
    chosen: bool = True
    reason: str = ""


@dataclass(frozen=True)
class Rescan:
    """The outcome of :func:`rescan_seams`.

    seams : one :class:`SeamRescan` per re-scanned seam, in the order visited.
    estimates : every seam of the detection, the re-scanned ones replaced by their fused estimate.
    moves : the moves played (to each view, then back), executions : what the simulated arm did.
    q_end : (dof,) [rad] where the arm was left; returned : whether that is the scan configuration; note : why
    not. escalated_mm : the close-up disagreement [mm] that made the re-scan take every seam (0: no escalation).
    curves : one :class:`CurveRescan` per curved seam the re-scan took (``cell rescan``: every curved seam).
    """

    seams: tuple[SeamRescan, ...]
    estimates: tuple[SeamEstimate, ...]
    moves: tuple[Trajectory, ...]
    executions: tuple[Execution, ...]
    q_end: FloatArray
    returned: bool
    note: str = ""
    timings: dict[str, float] = field(default_factory=dict)
    escalated_mm: float = 0.0
    curves: tuple[CurveRescan, ...] = ()

    @property
    def motion_s(self) -> float:
        """Robot time of every move of the re-scan [s]."""
        return float(sum(m.duration for m in self.moves))


@dataclass(frozen=True)
class PlannedCloseup:
    """A close-up view planned without moving the arm (``cell preview``, ``cell scenario check``): the view the
    re-scan would take of one seam (``viewpoint``), or why none works (``reason``), or the seam whose close-up
    would serve this one too (``served_by``: no view of its own)."""

    seam_id: str
    viewpoint: Viewpoint | None = None
    reason: str = ""
    served_by: str = ""

    @property
    def planned(self) -> bool:
        """A view of its own, or another seam's that sees it."""
        return self.viewpoint is not None or bool(self.served_by)
