"""The order's transfers screened between the planned lines before the full search (tiny inline cell)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest
from tiny_cell import HOME, OBSTACLES, URDF

from cell import scenario as sc
from cell.config.motion import PlanOptions
from cell.errors import TimingError
from cell.geometry import FloatArray
from cell.motion.collision import CollisionChecker
from cell.motion.robot import RobotModel
from cell.planning.access.screen import first_unjoined
from cell.planning.moves.pieces import Piece
from cell.planning.moves.strategies import Mover
from cell.planning.short_lines import LineEnd, SeamLines
from cell.planning.transfers import Direct, TransferFail, Transfers
from cell.process.torch import WeldProcess

PROCESS = WeldProcess.from_spec(sc.ProcessSpec())
Q_A = HOME + np.radians([30.0, 0.0, 0.0, 0.0, 0.0, 0.0])
Q_B = HOME + np.radians([-30.0, 0.0, 0.0, 0.0, 0.0, 0.0])
SHORT = np.radians([0.0, 0.0, 0.0, 0.0, 2.0, 0.0])  # a shorter line's end, a little off the planned one's


@dataclass(frozen=True)
class _NotFrom:
    """A direct move, refused when it leaves q."""

    q: tuple[float, ...]
    name: str = "not_from"

    def pieces(self, mover: Mover, q_a: FloatArray, q_b: FloatArray) -> list[Piece]:
        if np.allclose(q_a, self.q):
            raise TimingError("refused")
        return Direct().pieces(mover, q_a, q_b)


@pytest.fixture(scope="module")
def robot() -> RobotModel:
    return RobotModel.from_urdf(URDF)


def _lines(q: FloatArray) -> SeamLines:
    """A seam whose planned approach starts and depart ends at q, a shorter line each a little off it."""

    def end(kind: str, at: FloatArray, full: bool) -> LineEnd:
        return LineEnd(kind, np.asarray(at, dtype=float)[None, :], 0.0, np.zeros(3), np.eye(4), full)

    return SeamLines(
        (end("approach", q + SHORT, False), end("approach", q, True)),
        (end("depart", q + SHORT, False), end("depart", q, True)),
    )


def test_a_transfer_refused_between_the_planned_lines_is_the_first_unjoined(robot: RobotModel) -> None:
    lines = {"A": _lines(Q_A), "B": _lines(Q_B)}
    tr = Transfers(
        robot, PROCESS, CollisionChecker(robot, OBSTACLES), PlanOptions(), OBSTACLES, HOME, [_NotFrom(tuple(Q_A))]
    )
    got = first_unjoined(tr, ["A", "B"], lines, HOME)
    assert got is not None and got[:2] == ("A", "B") and got[2].reason == "not_from: refused"
    # the full search makes it between the shorter lines, and fails as the screen did where it fails
    assert not isinstance(tr.between([Q_A + SHORT, Q_A], [Q_B + SHORT, Q_B]), TransferFail)
    assert tr.between([Q_A], [Q_B]) is got[2]  # the same search, remembered
    # home to A and B back home are made; A -> B skipped (already refused): nothing left to screen
    assert first_unjoined(tr, ["A", "B"], lines, HOME, skip={("A", "B")}) is None
    last = first_unjoined(tr, ["B", "A"], lines, HOME)  # B -> A made; the way home from A, the last, refused
    assert last is not None and last[:2] == ("A", "") and last[2].reason == "not_from: refused"
