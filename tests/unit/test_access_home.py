"""A seam joined to home neither way, found from the transfers' own searches; the transfers' vertical lines solved
once per end, and not at all when their top is beyond reach (tiny inline cell)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest
from tiny_cell import HOME, OBSTACLES, URDF

import cell.planning.moves.lifts as lifts_module
from cell import scenario as sc
from cell.config.motion import PlanOptions
from cell.errors import TimingError
from cell.geometry import FloatArray
from cell.motion.collision import CollisionChecker
from cell.motion.robot import RobotModel
from cell.planning.access.home import cut_off, first_cut_off
from cell.planning.failures import LineError
from cell.planning.moves.pieces import Piece
from cell.planning.moves.strategies import Mover
from cell.planning.short_lines import LineEnd, SeamLines
from cell.planning.transfers import Direct, TransferFail, Transfers, TransferStrategy
from cell.process.torch import WeldProcess
from cell.types.plan import PlanReason

PROCESS = WeldProcess.from_spec(sc.ProcessSpec())
Q_SEAM = HOME + np.radians([30.0, 0.0, 0.0, 0.0, 0.0, 0.0])


@pytest.fixture(scope="module")
def robot() -> RobotModel:
    return RobotModel.from_urdf(URDF)


@dataclass(frozen=True)
class _NotFrom:
    """A direct move, refused when it leaves one of ``qs`` (a one-way door)."""

    qs: tuple[tuple[float, ...], ...]
    name: str = "not_from"

    def pieces(self, mover: Mover, q_a: FloatArray, q_b: FloatArray) -> list[Piece]:
        if any(np.allclose(q_a, q) for q in self.qs):
            raise TimingError("refused")
        return Direct().pieces(mover, q_a, q_b)


def _transfers(robot: RobotModel, *strategies: TransferStrategy) -> Transfers:
    checker = CollisionChecker(robot, OBSTACLES)
    return Transfers(robot, PROCESS, checker, PlanOptions(), OBSTACLES, HOME, strategies)


def _lines(q: FloatArray) -> SeamLines:
    """A seam whose approach starts and depart ends at q (one knot each: no shorter lines)."""
    knots = np.asarray(q, dtype=float)[None, :]
    end = LineEnd("approach", knots, 0.0, np.array([0.0, 0.0, -1.0]), np.eye(4), True)
    return SeamLines((end,), (LineEnd("depart", knots, 0.0, np.array([0.0, 0.0, 1.0]), np.eye(4), True),))


def test_a_seam_joined_to_home_either_way_is_not_cut_off(robot: RobotModel) -> None:
    assert cut_off(_transfers(robot, Direct()), _lines(Q_SEAM), HOME) is None
    # in from home refused, out to home free: still joined (the plan may end at it)
    assert cut_off(_transfers(robot, _NotFrom((tuple(HOME),))), _lines(Q_SEAM), HOME) is None
    # in from home free, out refused: joined too
    assert cut_off(_transfers(robot, _NotFrom((tuple(Q_SEAM),))), _lines(Q_SEAM), HOME) is None


def test_a_seam_no_transfer_joins_to_home_is_cut_off_with_the_way_ins_failure(robot: RobotModel) -> None:
    tr = _transfers(robot, _NotFrom((tuple(HOME), tuple(Q_SEAM))))
    why = cut_off(tr, _lines(Q_SEAM), HOME)
    assert isinstance(why, TransferFail) and why.reason == "not_from: refused"
    lines = {"A": _lines(Q_SEAM)}
    got = first_cut_off(tr, lines, HOME, ("", "A"))  # "" is home: skipped
    assert got is not None and got[0] == "A"
    assert first_cut_off(_transfers(robot, Direct()), lines, HOME, ("A", "")) is None


def test_a_vertical_line_is_solved_once_per_end_height_and_direction(
    robot: RobotModel, monkeypatch: pytest.MonkeyPatch
) -> None:
    calls: list[float] = []
    solve = lifts_module.solve_line

    def counted(*args: object, **kwargs: object) -> FloatArray:
        calls.append(1.0)
        return solve(*args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(lifts_module, "solve_line", counted)
    tr = _transfers(robot, Direct())
    z = float(robot.fk(HOME)[2, 3])
    up = tr.vertical(HOME, z + 0.1, True)
    assert up is not None and up is tr.vertical(HOME, z + 0.1, True) and len(calls) == 1
    assert float(robot.fk(up.trajectory.q[-1])[2, 3]) == pytest.approx(z + 0.1, abs=1e-4)
    for _ in range(2):  # the top 5 m up: beyond the shoulder's reach, refused before any IK
        with pytest.raises(LineError) as err:
            tr.vertical(HOME, z + 5.0, False)
        assert err.value.failure.code is PlanReason.BEYOND_REACH
    assert len(calls) == 1


def test_a_seam_joined_between_its_planned_lines_and_home_is_not_searched_over_its_shorter_lines(
    robot: RobotModel, monkeypatch: pytest.MonkeyPatch
) -> None:
    asked: list[tuple[int, int]] = []
    between = Transfers.between

    def counted(self: Transfers, outs: list[FloatArray], ins: list[FloatArray]) -> object:
        asked.append((len(outs), len(ins)))
        return between(self, outs, ins)

    monkeypatch.setattr(Transfers, "between", counted)
    full = _lines(Q_SEAM)
    knots = np.stack([Q_SEAM + 0.01, Q_SEAM])  # a shorter line's knots, ending at the seam
    shorter = LineEnd("approach", knots, 0.01, np.array([0.0, 0.0, -1.0]), np.eye(4), False)
    lines = SeamLines((shorter, *full.entries), full.exits)
    assert cut_off(_transfers(robot, Direct()), lines, HOME) is None
    assert asked == [(1, 1)]  # the planned pair only: the search over both lengths would make it too
    asked.clear()  # refused from home: then every length in, and out to home
    assert cut_off(_transfers(robot, _NotFrom((tuple(HOME),))), lines, HOME) is None
    assert asked == [(1, 1), (1, 2), (1, 1)]


def test_a_failed_search_is_placed_only_when_its_reason_is_read(
    robot: RobotModel, monkeypatch: pytest.MonkeyPatch
) -> None:
    placed: list[int] = []
    failure = Transfers._failure

    def counted(self: Transfers, q_a: FloatArray, q_b: FloatArray) -> TransferFail:
        placed.append(1)
        return failure(self, q_a, q_b)

    monkeypatch.setattr(Transfers, "_failure", counted)
    tr = _transfers(robot, _NotFrom((tuple(HOME), tuple(Q_SEAM))))
    got = tr.between([HOME], [Q_SEAM])
    assert isinstance(got, TransferFail) and placed == []
    assert got.reason == "not_from: refused" and placed == [1]
    assert got.p_R.shape == (3,) and got.reason == "not_from: refused" and placed == [1]
    assert tr.between([HOME], [Q_SEAM]) is got and placed == [1]
