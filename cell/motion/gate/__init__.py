"""The safety gate before motion (docs/reference.md section 7): find every way a plan could hurt, refuse to run it.

:func:`find_violations` returns one :class:`Violation` per problem; :func:`check_plan` raises
:class:`GateRefusedError` when there is any. One check per module, :data:`DEFAULT_CHECKS` in their order (the
list: docs/planning.md section 6; a new check: docs/architecture.md, "A safety-gate check")."""

from cell.motion.gate.arc import ArcSwitching
from cell.motion.gate.base import (
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
from cell.motion.gate.bodies import BodyEntry
from cell.motion.gate.collisions import Collisions
from cell.motion.gate.continuity import SampleJumps, SegmentJoins
from cell.motion.gate.gate import DEFAULT_CHECKS, GateRefusedError, check_plan, find_violations
from cell.motion.gate.position import PositionLimits
from cell.motion.gate.rates import AccelerationLimit, JerkLimit, VelocityLimit
from cell.motion.gate.singularity import Singularity
from cell.motion.gate.start import StartState

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
