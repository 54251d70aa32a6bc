"""Refusing a seam no torch can be placed on in a few broad-phase queries (cell.planning.placement.sweep) gives the
failure the group-by-group torch search gives, and a seam some torch can be placed on is still placed."""

from __future__ import annotations

import math

import numpy as np
import pytest
from tiny_cell import HOME, OBSTACLES, SIDE_SEAM, TOP_SEAM, URDF

from cell import scenario as sc
from cell.config.motion import PlanOptions
from cell.motion.collision import CollisionChecker
from cell.motion.robot import RobotModel
from cell.planning.failures import SeamFailure, better
from cell.planning.placement import Rotations, place, torch_tests, wording
from cell.planning.plan import reach_model
from cell.planning.seam_search import SeamSearch
from cell.process.torch import WeldProcess
from cell.process.torch_orientations import candidate_groups
from cell.types import Box, Part
from cell.types.plan import PlanReason, SeamTask

STIFF = WeldProcess.from_spec(sc.ProcessSpec(travel_angle_tol_deg=0.0, work_angle_tol_deg=0.0))
WIDE = WeldProcess.from_spec(sc.ProcessSpec())
SIDE, TOP = SeamTask(*SIDE_SEAM), SeamTask(*TOP_SEAM)
# A seam in a 20 mm slot between the post and a second post beside it: no torch fits at its foot.
NEIGHBOUR = Part(
    "POST2",
    Box(np.array([[1, 0, 0, 0.08], [0, 1, 0, 0.769], [0, 0, 1, 0.03], [0, 0, 0, 1.0]]), np.array([0.04, 0.2, 0.06])),
)


@pytest.fixture(scope="module")
def robot() -> RobotModel:
    return RobotModel.from_urdf(URDF)


class _Counting(CollisionChecker):
    """A checker that counts its broad-phase queries of torch poses."""

    queries = 0

    def torch_clear_many(self, X_RT, q_ref, first=False):  # type: ignore[no-untyped-def]
        self.queries += 1
        return super().torch_clear_many(X_RT, q_ref, first)


def _group_by_group(search: SeamSearch, task: SeamTask) -> SeamFailure | None:
    """The placement test one candidate group at a time (the torch search's order before the sweep): None when
    a candidate is placed, else the failure kept."""
    best: SeamFailure | None = None
    rotations: Rotations = {}
    for group in candidate_groups(search.process, search.opt):
        for cand, test in zip(group, torch_tests(search, task, group, rotations, HOME, wording(best)), strict=True):
            placed = place(search, task, cand, test, best)
            if isinstance(placed, np.ndarray):
                return None
            if placed is not None:
                best = better(best, placed)
    return best


@pytest.mark.parametrize(
    ("process", "task", "obstacles", "refused"),
    [(STIFF, SIDE, OBSTACLES, True), (WIDE, SIDE, (*OBSTACLES, NEIGHBOUR), True), (WIDE, TOP, OBSTACLES, False)],
    ids=["stiff-side", "slot-side", "top"],
)
def test_the_sweep_keeps_the_group_by_group_verdict(
    robot: RobotModel, process: WeldProcess, task: SeamTask, obstacles: tuple[Part, ...], refused: bool
) -> None:
    opt = PlanOptions()
    checker = CollisionChecker(robot, obstacles, opt.collision)
    search = SeamSearch(robot, process, checker, opt, np.random.default_rng(0), reach_model(robot))
    expected = _group_by_group(search, task)
    got = search.placeable(task, HOME)
    assert (expected is not None) is refused
    if expected is None:
        assert got is None
        return
    assert got is not None and (got.code, got.where, got.progress) == (expected.code, expected.where, expected.progress)
    np.testing.assert_array_equal(got.p_R, expected.p_R)
    planned = search.plan_seam(task, HOME)  # the torch search refuses it with the same words
    assert isinstance(planned, SeamFailure) and planned.reason() == expected.reason()


def test_a_seam_in_a_slot_is_refused_in_a_few_queries(robot: RobotModel) -> None:
    opt = PlanOptions()
    checker = _Counting(robot, (*OBSTACLES, NEIGHBOUR), opt.collision)
    search = SeamSearch(robot, WIDE, checker, opt, np.random.default_rng(0), reach_model(robot))
    groups = len(candidate_groups(WIDE, opt))
    assert groups > 40  # every work and travel angle setting the process allows
    fail = search.plan_seam(SIDE, HOME)
    assert isinstance(fail, SeamFailure) and fail.code is PlanReason.COLLISION
    assert "torch vs" in fail.where and "at the weld" in fail.where
    # the nominal group, then chunks of 1, 2, 4 ... groups (starts, and the ends of those clear), and the words
    assert checker.queries <= 2 * (2 + math.ceil(math.log2(groups))) + 2 < groups
