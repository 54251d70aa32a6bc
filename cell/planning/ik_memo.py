"""The reach map's IK answers kept for the plans of one job: the safety gate's rounds plan the same curves again
with the same arm, scene and options, and every station's IK asked again gives the same joints
(docs/curves-welding.md section 10). An answer is kept by the exact bytes of what it was asked (target, seeds or
last joints, jump bound) and by where the arm's base stands, and only for the arm, collision checker and IK
options it was built for.

Frames: targets X_RT in the robot base frame R [m]; joints [rad]."""

from __future__ import annotations

from collections.abc import Callable
from typing import TypeVar

import numpy as np

from cell.config.motion import PlanOptions
from cell.geometry import FloatArray
from cell.motion.collision import CollisionChecker
from cell.motion.robot import RobotModel

T = TypeVar("T")


class IKMemo:
    """IK answers of the reach map (joints, a miss or None) for one arm, checker and plan options: a memo handed
    to the plans of one job (:func:`cell.planning.plan.plan_welds`'s ``memo``). Holds no random state: what it
    keeps was computed without a generator."""

    def __init__(self, robot: RobotModel, checker: CollisionChecker, options: PlanOptions) -> None:
        self.robot, self.checker = robot, checker
        self._ik, self._min_manip = options.ik, options.min_manipulability
        self._kept: dict[tuple[object, ...], object] = {}
        self.hits = 0

    def fits(self, robot: RobotModel, checker: CollisionChecker, options: PlanOptions) -> bool:
        """Whether answers kept here are the answers for this arm, checker and options."""
        return (
            robot is self.robot
            and checker is self.checker
            and options.ik == self._ik
            and options.min_manipulability == self._min_manip
        )

    def answer(self, kind: str, arrays: tuple[FloatArray, ...], extra: float, solve: Callable[[], T]) -> T:
        """What ``solve()`` gives for the question ``kind`` on ``arrays`` (their exact float64 bytes) and
        ``extra``, with the checker's base where it stands now: kept from the first time it was asked."""
        asked = (np.ascontiguousarray(a, dtype=float).tobytes() for a in arrays)
        key = (kind, float(extra), self.checker.base_key(), *asked)
        if key in self._kept:
            self.hits += 1
            return self._kept[key]  # type: ignore[return-value]
        got = solve()
        self._kept[key] = got
        return got
