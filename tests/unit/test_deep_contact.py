"""A motion's deep contact found by probing a few samples coarse to fine, never one the advancement misses."""

from __future__ import annotations

import numpy as np
import pytest
from tiny_cell import HOME, OBSTACLES, URDF

from cell.geometry import FloatArray, make_pose
from cell.motion.collision import CollisionChecker
from cell.motion.collision.contact import Contact, coarse_to_fine, deep_sample
from cell.motion.robot import RobotModel
from cell.motion.timing import ptp
from cell.types import Box, Part

Q_B = HOME + np.radians([30.0, 0.0, 0.0, 0.0, 0.0, 0.0])


@pytest.mark.parametrize("n", [0, 1, 2, 3, 9, 10, 1000])
def test_coarse_to_fine_visits_every_sample_once_the_middle_first(n: int) -> None:
    order = list(coarse_to_fine(n))
    assert sorted(order) == list(range(n))
    if n >= 3:
        assert order[0] == (n - 1) // 2 and set(order[-2:]) == {0, n - 1}  # the ends (known free) last


def test_deep_sample_takes_only_a_contact_deeper_than_asked() -> None:
    path = np.linspace(0.0, 1.0, 101)[:, None]
    asked: list[float] = []

    def check(q: FloatArray) -> Contact | None:  # in contact from 0.7 on, 10 mm deep at 0.9
        asked.append(float(q[0]))
        depth = -(q[0] - 0.7) / 20.0
        return Contact("a", "b", float(depth), np.zeros(3), q) if q[0] >= 0.7 else None

    hit = deep_sample(check, path, 0.003)
    assert hit is not None and hit.depth <= -0.003
    assert asked == [0.5, 0.25, 0.75, 0.12, 0.37, 0.62, 0.87]  # at 0.75 only 2.5 mm deep
    assert deep_sample(check, path, 0.02) is None  # never that deep
    asked.clear()
    assert deep_sample(check, path, 0.02, probes=5) is None and len(asked) == 5


def test_a_deep_contact_is_one_the_advancement_finds_too() -> None:
    robot = RobotModel.from_urdf(URDF)
    mid = 0.5 * (robot.fk(HOME)[:3, 3] + robot.fk(Q_B)[:3, 3])
    tr = ptp(HOME, Q_B, robot.limits, dt=0.004)
    free = CollisionChecker(robot, OBSTACLES)
    assert free.deep_contact(tr.q) is None and not free.collides(tr.q) and free.check_path(tr.q) is None
    for top, deep_enough in ((0.8, True), (0.76, False)):  # a wall across the move; then grazed by the torch
        wall = Part("WALL", Box(make_pose(p=[mid[0], mid[1], top / 2.0]), np.array([0.02, 0.3, top])))
        checker = CollisionChecker(robot, (*OBSTACLES, wall))
        deep, first = checker.deep_contact(tr.q), checker.check_path(tr.q, tr.times)
        assert first is not None and first.b == "WALL" and checker.collides(tr.q)  # the advancement's answer
        assert (deep is not None) is deep_enough
        if deep is not None:
            assert deep.depth < -0.003 and deep.b == "WALL" and deep.t != deep.t  # a sample's, not placed in time


def test_check_deep_is_check_s_contact_when_that_deep() -> None:
    # Along a move through a wall: the deep probe's contact is check's (pair, depth) where that lies 3 mm or more
    # deep, and None elsewhere, though it queries only the pairs whose bounding spheres overlap by that much.
    robot = RobotModel.from_urdf(URDF)
    mid = 0.5 * (robot.fk(HOME)[:3, 3] + robot.fk(Q_B)[:3, 3])
    wall = Part("WALL", Box(make_pose(p=[mid[0], mid[1], 0.4]), np.array([0.02, 0.3, 0.8])))
    checker = CollisionChecker(robot, (*OBSTACLES, wall))
    deep_seen = 0
    for q in ptp(HOME, Q_B, robot.limits, dt=0.004).q[::10]:
        full, deep = checker.check(q), checker.check_deep(q, 0.003)
        if full is not None and full.depth <= -0.003:
            deep_seen += 1
            assert deep is not None and (deep.a, deep.b) == (full.a, full.b)
            assert deep.depth == pytest.approx(full.depth, abs=1e-7)  # coal warm-starts from the query before
        else:
            assert deep is None
    assert deep_seen > 0
