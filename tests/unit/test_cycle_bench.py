"""The cycle benchmark's bound (benchmarks/cycle_bound.py): its tour is the best over every order and direction of
the seams, its lower bound below it, and a plan's time falls into its bins whole."""

from __future__ import annotations

import itertools
from pathlib import Path
from types import ModuleType

import numpy as np
import pytest
from tools_loader import load_bench

from cell.motion.limits import JointLimits
from cell.motion.robot import RobotModel
from cell.motion.timing import ptp, ptp_duration
from cell.types.plan import Segment, WeldPlan
from cell.types.trajectory import Trajectory

URDF = Path(__file__).resolve().parents[2] / "robots" / "kr5_arc.urdf"


@pytest.fixture(scope="module")
def bound() -> ModuleType:
    return load_bench("cycle_bound")


@pytest.fixture(scope="module")
def limits() -> JointLimits:
    return RobotModel.from_urdf(URDF).limits


def _nodes(bound: ModuleType, limits: JointLimits, m: int, seed: int) -> object:
    rng = np.random.default_rng(seed)
    mid = 0.5 * (limits.q_min + limits.q_max)
    span = 0.2 * (limits.q_max - limits.q_min)
    starts = mid + rng.uniform(-1, 1, (m, 6)) * span
    ends = starts + rng.uniform(-0.2, 0.2, (m, 6))
    home = mid.copy()
    return bound.Nodes(tuple(f"s{k}" for k in range(m)), starts, ends, np.zeros(m), home, home)


def _brute(n: object, limits: JointLimits) -> float:
    best = np.inf
    m = len(n.ids)  # type: ignore[attr-defined]
    for order in itertools.permutations(range(m)):
        for flips in itertools.product((False, True), repeat=m):
            q, t = n.q_start, 0.0  # type: ignore[attr-defined]
            for k, f in zip(order, flips, strict=True):
                a, b = (n.ends[k], n.starts[k]) if f else (n.starts[k], n.ends[k])  # type: ignore[attr-defined]
                t += ptp_duration(q, a, limits)
                q = b
            best = min(best, t + ptp_duration(q, n.q_end, limits))  # type: ignore[attr-defined]
    return best


@pytest.mark.parametrize("seed", [0, 1])
def test_the_exact_tour_is_the_best_order_and_direction(bound: ModuleType, limits: JointLimits, seed: int) -> None:
    n = _nodes(bound, limits, 4, seed)
    tour = bound.best_tour(n, limits)
    assert tour.exact and tour.air_s == pytest.approx(_brute(n, limits), rel=1e-9)
    assert 0.0 < tour.lower_s <= tour.air_s
    assert sorted(tour.order) == sorted(n.ids)  # type: ignore[attr-defined]


def test_the_local_tour_is_no_better_than_the_exact_one(bound: ModuleType, limits: JointLimits) -> None:
    n = _nodes(bound, limits, 7, 3)
    exact = bound.best_tour(n, limits)
    old, bound.EXACT_MAX = bound.EXACT_MAX, 3  # type: ignore[attr-defined]
    try:
        local = bound.best_tour(n, limits)
    finally:
        bound.EXACT_MAX = old  # type: ignore[attr-defined]
    assert not local.exact and exact.air_s <= local.air_s + 1e-9 and local.lower_s <= exact.air_s + 1e-9


def test_a_plan_falls_into_its_bins_whole(bound: ModuleType, limits: JointLimits) -> None:
    q = np.radians([[0, -90, 90, 0, 45, 0], [20, -80, 85, 0, 40, 0], [20, -80, 86, 0, 40, 0], [40, -85, 90, 0, 45, 0]])
    still = Trajectory(
        np.arange(101, dtype=float) * 0.001, np.repeat(q[2:3], 101, 0), np.zeros((101, 6)), np.zeros((101, 6))
    )
    parts = [("move", ptp(q[0], q[1], limits)), ("approach", ptp(q[1], q[2], limits)), ("weld", still)]
    parts += [("depart", ptp(q[2], q[3], limits)), ("move", ptp(q[3], q[0], limits))]
    segs, t = [], 0.0
    for kind, tr in parts:
        segs.append(Segment(kind, "s", tr, t, np.eye(4), arc_on=kind == "weld"))  # type: ignore[arg-type]
        t += tr.duration
    plan = WeldPlan(tuple(f"a{k}" for k in range(6)), q[0], tuple(segs), (), ("s",))
    b = bound.breakdown(plan)
    assert b.arc_s == pytest.approx(0.1) and b.crater_dwell_s == pytest.approx(0.1)  # the weld stood still
    assert b.approach_s == pytest.approx(parts[1][1].duration) and b.depart_s == pytest.approx(parts[3][1].duration)
    assert b.home_s == pytest.approx(parts[0][1].duration + parts[4][1].duration) and b.transfer_s == 0.0
    assert b.air_s == pytest.approx(b.approach_s + b.depart_s + b.home_s)
