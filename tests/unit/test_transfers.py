"""Transfers between seams as typed strategies, tried in order; failure reasons as codes (tiny inline cell)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest
from tiny_cell import HOME, OBSTACLES, URDF

from cell import scenario as sc
from cell.config.motion import PlanOptions
from cell.errors import TimingError
from cell.geometry import FloatArray, make_pose
from cell.motion.collision import CollisionChecker
from cell.motion.robot import RobotModel
from cell.motion.timing import ptp
from cell.planning.failures import SeamFailure, better, reason_text
from cell.planning.memo import TransferAnswers
from cell.planning.moves.strategies import Mover
from cell.planning.transfers import DEFAULT_STRATEGIES, Direct, Lift, Piece, TransferFail, Transfers, TransferStrategy
from cell.process.torch import WeldProcess
from cell.types import Box, Part
from cell.types.plan import PlanReason

PROCESS = WeldProcess.from_spec(sc.ProcessSpec())
Q_B = HOME + np.radians([30.0, 0.0, 0.0, 0.0, 0.0, 0.0])


@pytest.fixture(scope="module")
def robot() -> RobotModel:
    return RobotModel.from_urdf(URDF)


@dataclass(frozen=True)
class _Untimeable:
    name: str = "broken"

    def pieces(self, mover: Mover, q_a: FloatArray, q_b: FloatArray) -> list[Piece]:
        raise TimingError("no profile")


def _mover(robot: RobotModel, obstacles: tuple[Part, ...], *strategies: TransferStrategy) -> Transfers:
    checker = CollisionChecker(robot, obstacles)
    return Transfers(robot, PROCESS, checker, PlanOptions(), obstacles, HOME, strategies or DEFAULT_STRATEGIES)


def test_the_default_strategies_in_their_order() -> None:
    names = ["direct", "hop_down", "hop_up", "hop_mid", "hop_low", "hop", "lift", "hop_high", "lift_high", "home"]
    assert [s.name for s in DEFAULT_STRATEGIES] == names
    assert DEFAULT_STRATEGIES[6] == Lift() and DEFAULT_STRATEGIES[8] == Lift("lift_high", extra=1)


def test_a_free_direct_move_is_one_ptp(robot: RobotModel) -> None:
    moves = _mover(robot, OBSTACLES).move(HOME, Q_B)
    assert not isinstance(moves, TransferFail)
    assert [p.kind for p in moves] == ["move"] and moves[0].speed == 0.0
    np.testing.assert_allclose(moves[0].trajectory.q[-1], Q_B, atol=1e-9)


def test_a_strategy_that_fails_hands_on_to_the_next(robot: RobotModel) -> None:
    moves = _mover(robot, OBSTACLES, _Untimeable(), Direct()).move(HOME, Q_B)
    assert not isinstance(moves, TransferFail) and [p.kind for p in moves] == ["move"]
    fail = _mover(robot, OBSTACLES, _Untimeable()).move(HOME, Q_B)
    assert isinstance(fail, TransferFail) and fail.reason == "broken: no profile"


def test_a_blocked_direct_move_is_lifted_over_the_obstacle(robot: RobotModel) -> None:
    # A wall between the two configurations' torches, a little higher than the TCP: up, across, down.
    mid = 0.5 * (robot.fk(HOME)[:3, 3] + robot.fk(Q_B)[:3, 3])
    wall = Part("WALL", Box(make_pose(p=[mid[0], mid[1], 0.4]), np.array([0.02, 0.3, 0.8])))
    blocked = _mover(robot, (*OBSTACLES, wall), Direct()).move(HOME, Q_B)
    assert isinstance(blocked, TransferFail) and "WALL" in blocked.reason
    mover = _mover(robot, (*OBSTACLES, wall))
    assert mover.checker.check(HOME) is None and mover.checker.check(Q_B) is None
    moves = mover.move(HOME, Q_B)
    assert not isinstance(moves, TransferFail)
    # PTPs through one via point over the middle of the two ends, the lowest that clears it: 20 mm over the wall
    # (a via point above one end only still sweeps the torch through the wall)
    assert [p.kind for p in moves] == ["move", "move"]
    assert mover.lift_z == pytest.approx(0.8 + PlanOptions().transfer_lift)
    via = robot.fk(moves[0].trajectory.q[-1])[:3, 3]
    assert via[2] == pytest.approx(0.82, abs=1e-4)
    np.testing.assert_allclose(via[:2], mid[:2], atol=1e-4)
    np.testing.assert_allclose(moves[-1].trajectory.q[-1], Q_B, atol=1e-6)


def test_reasons_are_codes_with_the_report_text() -> None:
    assert reason_text(PlanReason.BEYOND_REACH, "x") == "unreachable: x"
    assert reason_text(PlanReason.TRANSFER_COLLISION, "no free transfer move") == "collision: no free transfer move"
    assert all(isinstance(reason_text(c, ""), str) for c in PlanReason)  # every code has its word
    near = SeamFailure(PlanReason.IK_FAILED, "a", np.zeros(3), 0.01)
    far = SeamFailure(PlanReason.COLLISION, "b", np.zeros(3), 0.02)
    assert better(None, near) is near and better(near, far) is far and better(far, near) is far
    assert better(near, SeamFailure(PlanReason.FLIP, "c", np.zeros(3), 0.01)) is near  # ties: the earlier


def test_a_failure_names_the_last_strategy_s_first_contact(robot: RobotModel) -> None:
    # The search asks only whether each way collides; the failure it reports is still the last strategy's first
    # contact along its motion, and an error without a place keeps the contact of the strategy before it.
    mid = 0.5 * (robot.fk(HOME)[:3, 3] + robot.fk(Q_B)[:3, 3])
    wall = Part("WALL", Box(make_pose(p=[mid[0], mid[1], 0.4]), np.array([0.02, 0.3, 0.8])))
    obstacles = (*OBSTACLES, wall)
    direct = ptp(HOME, Q_B, robot.limits, dt=PlanOptions().dt)
    first = CollisionChecker(robot, obstacles).check_path(direct.q, direct.times)
    assert first is not None and first.b == "WALL"
    fail = _mover(robot, obstacles, _Untimeable(), Direct()).move(HOME, Q_B)
    assert isinstance(fail, TransferFail) and fail.reason == first.describe()
    np.testing.assert_allclose(fail.p_R, first.p_R, atol=1e-12)
    fail = _mover(robot, obstacles, Direct(), _Untimeable()).move(HOME, Q_B)
    assert isinstance(fail, TransferFail) and fail.reason == "broken: no profile"
    np.testing.assert_allclose(fail.p_R, first.p_R, atol=1e-12)
    fail = _mover(robot, obstacles, _Untimeable()).move(HOME, Q_B)
    assert isinstance(fail, TransferFail) and not np.any(fail.p_R)  # no place at all: the origin


@dataclass(frozen=True)
class _FreeThenWall:
    """Two motions: a free one out and back, then the direct move through the wall."""

    name: str = "free_then_wall"

    def pieces(self, mover: Mover, q_a: FloatArray, q_b: FloatArray) -> list[Piece]:
        out = Direct().pieces(mover, q_a, HOME + np.radians([5.0, 0.0, 0.0, 0.0, 0.0, 0.0]))
        back = Direct().pieces(mover, out[0].trajectory.q[-1], q_a)
        return [*out, *back, *Direct().pieces(mover, q_a, q_b)]


def test_a_search_checks_no_motion_in_full_when_another_of_its_way_runs_deep(robot: RobotModel) -> None:
    mid = 0.5 * (robot.fk(HOME)[:3, 3] + robot.fk(Q_B)[:3, 3])
    wall = Part("WALL", Box(make_pose(p=[mid[0], mid[1], 0.4]), np.array([0.02, 0.3, 0.8])))
    mover = _mover(robot, (*OBSTACLES, wall), _FreeThenWall(), Direct())
    asked: list[int] = []
    check_path = mover.checker.check_path

    def counted(q: FloatArray, *args: object, **kwargs: object) -> object:
        asked.append(len(q))
        return check_path(q, *args, **kwargs)  # type: ignore[arg-type]

    mover.checker.check_path = counted  # type: ignore[method-assign, assignment]
    fail = mover.move(HOME, Q_B)
    assert isinstance(fail, TransferFail) and "WALL" in fail.reason
    # the free motions out and back are never advanced along (the wall's move runs deep); only the failure
    # reported, the last strategy's, is placed: one full check
    assert len(asked) == 1


def test_a_strategy_is_asked_once_between_the_same_ends(robot: RobotModel) -> None:
    # The wall blocks the direct move: a search, then another whose lists end in the same pair (the order search's
    # screen, then the shorter lines), asks each strategy between those ends once, and probes no motion twice.
    mid = 0.5 * (robot.fk(HOME)[:3, 3] + robot.fk(Q_B)[:3, 3])
    wall = Part("WALL", Box(make_pose(p=[mid[0], mid[1], 0.4]), np.array([0.02, 0.3, 0.8])))
    mover = _mover(robot, (*OBSTACLES, wall), _FreeThenWall(), Direct())
    asked: list[tuple[str, bytes, bytes]] = []
    probed: list[int] = []
    deep = mover.checker.deep_contact
    plain = mover.strategies

    @dataclass(frozen=True)
    class Counted:
        inner: TransferStrategy
        name: str = "counted"

        def pieces(self, m: Mover, q_a: FloatArray, q_b: FloatArray) -> list[Piece]:
            asked.append((self.inner.name, q_a.tobytes(), q_b.tobytes()))
            return self.inner.pieces(m, q_a, q_b)

    def counted_deep(q: FloatArray, *args: object, **kwargs: object) -> object:
        probed.append(len(q))
        return deep(q, *args, **kwargs)  # type: ignore[arg-type]

    mover.strategies = tuple(Counted(s) for s in plain)
    mover.checker.deep_contact = counted_deep  # type: ignore[method-assign, assignment]
    first = mover.between([HOME], [Q_B])
    n_asked, n_probed = len(asked), len(probed)
    again = mover.between([HOME, HOME], [Q_B + np.radians([0.0, 0.0, 0.0, 0.0, 0.0, 1.0]), Q_B])
    assert isinstance(first, TransferFail) and isinstance(again, TransferFail)
    assert len(asked) == len(set(asked)) == n_asked + 2  # the new pair with either strategy, the old one never
    assert n_probed == 3 and len(probed) == n_probed + 1  # the free motions out and back probed once


def test_the_ways_out_of_an_exit_at_fault_are_tried_from_it_alone(robot: RobotModel) -> None:
    """retreat_from adds ways (after every strategy) for the transfers out of the given configurations only, and
    searches again what failed before; a second call for the same configurations adds nothing."""
    from cell.planning.access.openings import RETREATS, Retreat

    assert RETREATS[:3] == (Retreat("retreat_250", 0.25), Retreat("retreat_350", 0.35), Retreat("retreat_450", 0.45))
    assert RETREATS[3:] == tuple(Retreat(f"retreat_{d}_home", d / 1000, True) for d in (250, 350, 450))
    mover = _mover(robot, OBSTACLES, _Untimeable())
    other = HOME + np.radians([0.0, 0.0, 0.0, 0.0, 0.0, 5.0])
    assert isinstance(mover.move(HOME, Q_B), TransferFail)
    assert mover.retreat_from([HOME], [Direct("way_out")]) and not mover.retreat_from([HOME], [Direct("way_out")])
    moves = mover.move(HOME, Q_B)  # out of HOME: the way out is free
    assert not isinstance(moves, TransferFail) and [p.kind for p in moves] == ["move"]
    assert isinstance(mover.move(other, Q_B), TransferFail)  # out of another configuration: as before


def test_a_later_plan_with_the_same_set_up_answers_from_the_first_plans_searches(robot: RobotModel) -> None:
    """The safety gate's next round (another Transfers, the same arm, process, checker, options, obstacles and
    home, the first one's answers handed over): the same way over the wall, found without one motion checked
    again; with another home (or the base moved), nothing is taken from them."""
    mid = 0.5 * (robot.fk(HOME)[:3, 3] + robot.fk(Q_B)[:3, 3])
    wall = Part("WALL", Box(make_pose(p=[mid[0], mid[1], 0.4]), np.array([0.02, 0.3, 0.8])))
    obstacles, opt = (*OBSTACLES, wall), PlanOptions()
    checker = CollisionChecker(robot, obstacles)
    kept = TransferAnswers()
    first = Transfers(robot, PROCESS, checker, opt, obstacles, HOME, answers=kept).move(HOME, Q_B)
    assert not isinstance(first, TransferFail) and len(first) == 2 and kept.pieces and kept.tried
    checked: list[int] = []
    path = checker.check_path

    def counted(q: FloatArray, *args: object, **kwargs: object) -> object:
        checked.append(len(q))
        return path(q, *args, **kwargs)  # type: ignore[arg-type]

    checker.check_path = counted  # type: ignore[method-assign, assignment]
    again = Transfers(robot, PROCESS, checker, opt, obstacles, HOME, answers=kept).move(HOME, Q_B)
    assert not isinstance(again, TransferFail) and checked == []
    for a, b in zip(first, again, strict=True):
        np.testing.assert_array_equal(a.trajectory.q, b.trajectory.q)
    Transfers(robot, PROCESS, checker, opt, obstacles, Q_B, answers=kept).move(HOME, Q_B)
    assert checked  # another home: searched afresh
    same = Transfers(robot, PROCESS, checker, opt, obstacles, HOME)
    checker.set_base(np.array([0.0, 0.0, 0.001]))
    try:
        assert not kept.fits(same)
    finally:
        checker.set_base(np.zeros(3))
    assert kept.fits(same)
