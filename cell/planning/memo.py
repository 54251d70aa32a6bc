"""Answers kept for the plans of one job: the safety gate's rounds plan the same seams again with the same arm,
scene and options, and the reach map's IK (docs/curves-welding.md section 10) and the transfers' searches
(docs/planning.md section 1) asked again give the same answers. Each is kept by the exact bytes of what it was
asked and only for the arm, collision checker (where its base stands) and options it was built for.

Frames: targets X_RT in the robot base frame R [m]; joints [rad]."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Protocol, TypeVar

import numpy as np

from cell.config.motion import PlanOptions
from cell.geometry import FloatArray
from cell.motion.collision import CollisionChecker
from cell.motion.robot import RobotModel

if TYPE_CHECKING:
    from cell.process.torch import WeldProcess
    from cell.types import Part


class SetUp(Protocol):
    """What a transfers' search is for (:class:`~cell.planning.transfers.Transfers` has it)."""

    robot: RobotModel
    process: WeldProcess
    checker: CollisionChecker
    opt: PlanOptions
    obstacles: tuple[Part, ...]
    q_home: FloatArray


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


@dataclass
class TransferAnswers:
    """What :class:`~cell.planning.transfers.Transfers` remembers of its searches (each motion's check, the lifts'
    IK and lines, each strategy's motions between two ends), for the one set-up it was first used with."""

    pieces: dict[Any, Any] = field(default_factory=dict)
    shallow: set[Any] = field(default_factory=set)
    above: dict[Any, Any] = field(default_factory=dict)
    vertical: dict[Any, Any] = field(default_factory=dict)
    tried: dict[Any, Any] = field(default_factory=dict)
    _owner: tuple[object, ...] | None = None

    def fits(self, mover: SetUp) -> bool:
        """Whether these answers are a search's with ``mover``'s set-up (the same arm, process, checker with its base
        where it stood, options, obstacles and home); the first set-up asked is the one they keep."""
        owner = (mover.robot, mover.process, mover.checker, mover.checker.base_key(), mover.opt, *mover.obstacles)
        owner += (np.asarray(mover.q_home).tobytes(),)
        if self._owner is None:
            self._owner = owner
        return len(owner) == len(self._owner) and all(
            a is b or (isinstance(a, bytes) and a == b) for a, b in zip(owner, self._owner, strict=True)
        )


class PlanMemo:
    """The answers one job's plans share (:func:`cell.planning.plan.plan_welds`'s ``memo``): the reach map's IK
    (:class:`IKMemo`) and the transfers' searches (:class:`TransferAnswers`)."""

    def __init__(self, robot: RobotModel, checker: CollisionChecker, options: PlanOptions) -> None:
        self.ik = IKMemo(robot, checker, options)
        self.transfers = TransferAnswers()
