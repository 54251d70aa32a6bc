"""Running the gate: every check in turn (:func:`find_violations`), and the refusal (:func:`check_plan`)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import numpy.typing as npt

from cell.errors import PlanError
from cell.gate.arc import ArcSwitching
from cell.gate.base import Check, GateInput, GateOptions, PerSegment, Violation
from cell.gate.bodies import BodyEntry
from cell.gate.collisions import Collisions
from cell.gate.continuity import SampleJumps, SegmentJoins
from cell.gate.position import PositionLimits
from cell.gate.rates import AccelerationLimit, JerkLimit, VelocityLimit
from cell.gate.singularity import Singularity
from cell.gate.start import StartState
from cell.motion.collision import CollisionChecker
from cell.motion.robot import RobotModel
from cell.types import Part
from cell.types.plan import WeldPlan

# The gate's checks, in the order their violations are listed.
DEFAULT_CHECKS: tuple[Check, ...] = (
    StartState(),
    SegmentJoins(),
    SampleJumps(),
    PositionLimits(),
    VelocityLimit(),
    AccelerationLimit(),
    JerkLimit(),
    PerSegment((Singularity(), ArcSwitching())),
    Collisions(),
    BodyEntry(),
)


class GateRefusedError(PlanError):
    """The safety gate refused a plan; ``violations`` lists every problem found, in the gate's order."""

    def __init__(self, message: str, *, violations: Sequence[Violation]) -> None:
        super().__init__(message)
        self.violations = tuple(violations)


def find_violations(
    robot: RobotModel,
    plan: WeldPlan,
    q_current: npt.ArrayLike,
    *,
    checker: CollisionChecker | None = None,
    options: GateOptions | None = None,
    checks: Sequence[Check] = DEFAULT_CHECKS,
    bodies: Sequence[Part] = (),
    wire_m: float = 0.0,
    joint_parts: Mapping[str, tuple[str, ...]] | None = None,
) -> list[Violation]:
    """Every violation of the gate's checks (see :mod:`cell.gate`); an empty list means go.

    q_current : (dof,) [rad] where the arm is now. checker : collisions are checked only when one is given.
    bodies : the parts (the aligned map's, in R) no TCP or wire may enter, checked only when given; wire_m : the
    wire's stick-out behind the TCP [m]; joint_parts : per seam id its joint's two parts, left out along its own
    approach, weld and depart (:mod:`cell.gate.bodies`).
    """
    if not plan.segments:
        return []
    opts = options or GateOptions()
    q = np.asarray(q_current, dtype=float)
    gate = GateInput(robot, plan, q, checker, opts, tuple(bodies), wire_m, dict(joint_parts or {}))
    return [v for check in checks for v in check.violations(gate)]


def check_plan(
    robot: RobotModel,
    plan: WeldPlan,
    q_current: npt.ArrayLike,
    *,
    checker: CollisionChecker | None = None,
    options: GateOptions | None = None,
    bodies: Sequence[Part] = (),
    wire_m: float = 0.0,
    joint_parts: Mapping[str, tuple[str, ...]] | None = None,
) -> None:
    """Raise GateRefusedError (a PlanError) naming the violations (the first five and a count) unless the plan
    passes the gate (:func:`find_violations`)."""
    found = find_violations(
        robot, plan, q_current, checker=checker, options=options, bodies=bodies, wire_m=wire_m, joint_parts=joint_parts
    )
    if found:
        shown = "; ".join(str(v) for v in found[:5])
        more = f" (+{len(found) - 5} more)" if len(found) > 5 else ""
        raise GateRefusedError(
            f"plan refused by the safety gate, {len(found)} violation(s): {shown}{more}", violations=found
        )
