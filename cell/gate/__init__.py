"""The safety gate before motion (docs/reference.md section 7): find every way a plan could hurt, refuse to run it.

:func:`find_violations` returns one :class:`Violation` per problem (the worst instance of each kind and joint),
each saying what, where (time, joint) and by how much; :func:`check_plan` raises :class:`GateRefusedError` (a
:class:`~cell.errors.PlanError`) when there is any. One check per module, each a :class:`Check` (one method,
``violations``) or a :class:`SegmentCheck` run segment by segment; :data:`DEFAULT_CHECKS` in their order:

* :class:`StartState` (``start``): the plan starts at rest at the current state (within ``start_tol``) and
  inside the position limits;
* :class:`SegmentJoins`, :class:`SampleJumps` (``continuity``): consecutive segments meet (same time, same
  configuration), no stored sample jumps further than the velocity limit allows over its interval;
* :class:`PositionLimits` (``position``), :class:`VelocityLimit`, :class:`AccelerationLimit`,
  :class:`JerkLimit` (``rates``): the limits at every sample when re-sampled at ``rate_hz`` (1 kHz, on a grid
  that keeps every stored sample); jerk is the finite difference of the re-sampled acceleration. ``rel_tol``
  (1 %) covers rounding and the quintic interpolation of a plan stored coarser than 1 kHz;
* :class:`Singularity` (``singularity``): along Cartesian (LIN) segments, the manipulability stays above
  ``min_manipulability`` (joint-interpolated PTP moves may pass through singular poses harmlessly);
* :class:`ArcSwitching` (``arc``): arc on only during weld segments, switched on and off at exact stops
  (run with the singularity check, segment by segment);
* :class:`Collisions` (``collisions``): robot against the obstacles and itself along every segment
  (conservative advancement, see :mod:`cell.motion.collision`), when a checker is given;
* :class:`BodyEntry` (``bodies``): the TCP and the wire behind it never inside a part's body by more than
  ``body_depth`` along any segment, when the bodies are given (what the collision model's cut-back torch leaves
  out: a weld running on through a tube's wall).

A new check: a frozen dataclass with ``violations(gate: GateInput) -> list[Violation]`` in a module of its own,
added to the ``checks`` passed to :func:`find_violations` (or to :data:`DEFAULT_CHECKS`).
Units: SI (rad, rad/s, rad/s^2, rad/s^3, m, s) in the fields; degrees and mm in the messages.
"""

from cell.gate.arc import ArcSwitching
from cell.gate.base import (
    Check,
    GateInput,
    GateOptions,
    PerSegment,
    Resampled,
    SegmentCheck,
    Violation,
    ViolationKind,
    resample_times,
)
from cell.gate.bodies import BodyEntry
from cell.gate.collisions import Collisions
from cell.gate.continuity import SampleJumps, SegmentJoins
from cell.gate.gate import DEFAULT_CHECKS, GateRefusedError, check_plan, find_violations
from cell.gate.position import PositionLimits
from cell.gate.rates import AccelerationLimit, JerkLimit, VelocityLimit
from cell.gate.singularity import Singularity
from cell.gate.start import StartState

__all__ = [
    "DEFAULT_CHECKS",
    "AccelerationLimit",
    "ArcSwitching",
    "BodyEntry",
    "Check",
    "Collisions",
    "GateInput",
    "GateOptions",
    "GateRefusedError",
    "JerkLimit",
    "PerSegment",
    "PositionLimits",
    "Resampled",
    "SampleJumps",
    "SegmentCheck",
    "SegmentJoins",
    "Singularity",
    "StartState",
    "VelocityLimit",
    "Violation",
    "ViolationKind",
    "check_plan",
    "find_violations",
    "resample_times",
]
