"""The torch search refuses a candidate whose arm lies deep in something at its weld start before solving its
lines (cell.planning.seam_search.SeamSearch.arm_at_start), reports that collision, and keeps the plan it found."""

from __future__ import annotations

import numpy as np
import pytest
from tiny_cell import HOME, OBSTACLES, TOP_SEAM, URDF

from cell import scenario as sc
from cell.config.motion import PlanOptions
from cell.errors import IKError
from cell.geometry import FloatArray, make_pose
from cell.motion.collision import CollisionChecker
from cell.motion.robot import RobotModel
from cell.planning.failures import SeamFailure, better, unreachable
from cell.planning.plan import reach_model
from cell.planning.seam_search import SeamSearch, SeamSolution
from cell.process.torch import WeldProcess
from cell.process.torch_orientations import Candidate
from cell.types import Box, Part
from cell.types.plan import PlanReason, SeamTask

TOP = SeamTask(*TOP_SEAM)
# A box around the forearm of the top seam's first-ranked candidate, well above the torch at both weld ends.
BLOCK = Part("BLOCK", Box(make_pose(p=[-0.17, 0.52, 0.73]), np.array([0.15, 0.15, 0.15])))


class _Solved(SeamSearch):
    """A torch search that keeps the weld-start configuration of every candidate whose lines it solves."""

    def __init__(self, *args, **kwargs) -> None:  # type: ignore[no-untyped-def]
        super().__init__(*args, **kwargs)
        self.solved: list[FloatArray] = []

    def solve_candidate(
        self, task: SeamTask, cand: Candidate, X: FloatArray, q0: FloatArray
    ) -> SeamSolution | SeamFailure:
        self.solved.append(np.array(q0))
        return super().solve_candidate(task, cand, X, q0)


def _search(robot: RobotModel, checker: CollisionChecker) -> _Solved:
    opt = PlanOptions()
    process = WeldProcess.from_spec(sc.ProcessSpec())
    return _Solved(robot, process, checker, opt, np.random.default_rng(0), reach_model(robot))


@pytest.fixture(scope="module")
def robot() -> RobotModel:
    return RobotModel.from_urdf(URDF)


def test_an_arm_in_a_box_at_its_weld_start_is_refused_before_its_lines(robot: RobotModel) -> None:
    checker = CollisionChecker(robot, (*OBSTACLES, BLOCK), PlanOptions().collision)
    search = _search(robot, checker)
    sol = search.plan_seam(TOP, HOME)
    assert isinstance(sol, SeamSolution)
    # every candidate whose lines were solved is clear of a deep contact at its weld start
    assert search.solved and all(checker.deep_contact(q0[None]) is None for q0 in search.solved)
    # without the check, the first-ranked candidate (its arm in the box) is solved in full first, to the same plan
    plain = _search(robot, checker)
    plain.arm_at_start = lambda task, q0: None  # type: ignore[method-assign]
    same = plain.plan_seam(TOP, HOME)
    assert isinstance(same, SeamSolution) and len(plain.solved) == len(search.solved) + 1
    np.testing.assert_array_equal(same.q_weld, sol.q_weld)
    np.testing.assert_array_equal(same.q_approach, sol.q_approach)
    # the refused one's failure: its arm (not the torch) against the box where the weld starts
    fail = search.arm_at_start(TOP, plain.solved[0])
    assert fail is not None and fail.code is PlanReason.COLLISION
    assert fail.where.startswith("link_") and " vs BLOCK at 0.0 mm along the seam" in fail.where
    assert checker.torch_clear(sol.X_weld[0], HOME) is None
    # it ranks above a candidate whose IK fails at the weld start, below one that fails a step along the seam
    no_ik = IKError("did not converge")
    assert better(unreachable(no_ik, sol.X_weld[0], 0.0, 0.0), fail) is fail
    assert better(fail, unreachable(no_ik, sol.X_weld[1], 0.002, 0.002)) is not fail


def test_an_arm_clear_at_its_weld_start_passes_the_check(robot: RobotModel) -> None:
    search = _search(robot, CollisionChecker(robot, OBSTACLES, PlanOptions().collision))
    sol = search.plan_seam(TOP, HOME)
    assert isinstance(sol, SeamSolution) and search.arm_at_start(TOP, sol.q_weld[0]) is None
