"""The path check's bound per class of pairs: two links of the arm move apart only by the joints between them, so a
self pair's distance changes by at most its class's share of the whole arm's bound; the path check steps by it and
finds what the whole arm's bound found, in fewer checks (tiny cell, random boxes)."""

from __future__ import annotations

import numpy as np
import pytest
from tiny_cell import URDF

from cell.geometry import make_pose
from cell.motion.collision import CollisionChecker
from cell.motion.collision.contact import advance_along
from cell.motion.robot import RobotModel
from cell.types import Box, Part


@pytest.fixture(scope="module")
def robot() -> RobotModel:
    return RobotModel.from_urdf(URDF)


def _boxes(seed: int, n: int) -> list[Part]:
    rng = np.random.default_rng(seed)
    return [
        Part(f"B{k}", Box(make_pose(p=rng.uniform([-0.8, 0.3, 0.0], [0.8, 1.3, 0.5])), rng.uniform(0.02, 0.2, 3)))
        for k in range(n)
    ]


def test_a_self_pairs_distance_changes_by_at_most_its_class_bound(robot: RobotModel) -> None:
    checker = CollisionChecker(robot, [])
    rel, lim = checker._relative, robot.limits
    pairs = np.array(checker._pairs.self_)
    row = np.empty(len(pairs), dtype=int)  # each self pair's class, from the bounds' own order
    for c, (a, b) in enumerate(zip(rel.starts, [*rel.starts[1:], len(pairs)], strict=True)):
        row[rel.order[a:b]] = c + (len(rel.starts) < len(rel.weights))
    assert rel.weights[-1].sum() < 0.2 * rel.weights[0].sum()  # the wrist's links: a fifth of the arm's bound
    rng = np.random.default_rng(3)
    worst = 0.0
    for _ in range(200):
        q = lim.q_min + (lim.q_max - lim.q_min) * rng.random(6)
        dq = rng.normal(0.0, 0.05, 6)
        d0, d1 = checker._distances(q)[pairs], checker._distances(q + dq)[pairs]
        bound = (rel.weights @ np.abs(dq))[row]
        assert np.all(np.abs(d1 - d0) <= bound + 2e-6)
        worst = max(worst, float(np.max(np.abs(d1 - d0) / bound)))
    assert worst > 0.4  # not loose by far: measured 0.67


def test_the_path_check_finds_what_the_whole_arms_bound_found_in_fewer_checks(robot: RobotModel) -> None:
    checker = CollisionChecker(robot, _boxes(5, 12))
    rng, lim = np.random.default_rng(8), robot.limits
    calls = {"budgets": 0, "step": 0}
    budgets, step = checker._budgets, checker._step_bound

    def counted_budgets(q: np.ndarray) -> tuple:
        calls["budgets"] += 1
        return budgets(q)

    def counted_step(q: np.ndarray) -> tuple:
        calls["step"] += 1
        return step(q)

    checker._budgets = counted_budgets  # type: ignore[method-assign]
    hits = 0
    for _ in range(12):
        q_a = lim.q_min + (lim.q_max - lim.q_min) * rng.random(6)
        path = q_a + np.linspace(0.0, 1.0, 50)[:, None] * rng.normal(0.0, 0.2, 6)
        new = checker.check_path(path)
        old = advance_along(counted_step, checker.motion_bound, path)
        assert (new is None) == (old is None)
        if new is not None and old is not None:
            hits += 1
            assert abs((new.index + 0.5) - (old.index + 0.5)) <= 1  # the same first contact, to a sample
    assert 4 <= hits <= 10  # measured 7 of 12
    assert 0 < calls["budgets"] < 0.5 * calls["step"]  # measured 443 against 1171
