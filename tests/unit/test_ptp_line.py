"""A rest-to-rest PTP is timed as a KRC4 drives it: a straight line in joint space, every axis starting and
stopping together, the leading axis at its limits and the others scaled."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from cell.motion.limits import JointLimits
from cell.motion.robot import RobotModel
from cell.motion.timing import ptp, ptp_duration, ptp_line_deviation

URDF = Path(__file__).resolve().parents[2] / "robots" / "kr5_arc.urdf"


@pytest.fixture(scope="module")
def limits() -> JointLimits:
    return RobotModel.from_urdf(URDF).limits


def _moves(limits: JointLimits, n: int, seed: int) -> list[tuple[np.ndarray, np.ndarray]]:
    rng = np.random.default_rng(seed)
    return [(limits.sample(rng, margin=0.3), limits.sample(rng, margin=0.3)) for _ in range(n)]


def _single_axis_duration(dq: float, v: float, a: float, j: float) -> float:
    """Rest-to-rest time of one axis alone over dq [rad] (a one-joint ptp)."""
    one = JointLimits(("j",), np.array([-10.0]), np.array([10.0]), np.array([v]), np.array([a]), np.array([j]))
    return ptp_duration(np.zeros(1), np.array([dq]), one)


@pytest.mark.parametrize("scale_a3_accel", [1.0, 0.3])  # proportional limits, and an axis with low acceleration
def test_rest_to_rest_ptp_is_the_synchronised_joint_line(limits: JointLimits, scale_a3_accel: float) -> None:
    a_max = limits.a_max.copy()
    a_max[2] *= scale_a3_accel
    lim = replace(limits, a_max=a_max)
    for q0, q1 in _moves(lim, 25, seed=7):
        tr = ptp(q0, q1, lim, dt=0.002)
        assert ptp_line_deviation(tr.q) <= 1e-12  # on the line q0 -> q1 up to rounding
        dq = q1 - q0
        u = (tr.q - q0) @ dq / (dq @ dq)
        assert np.all(np.diff(u) >= 0.0) and u[0] == 0.0 and u[-1] == pytest.approx(1.0, abs=1e-15)
        # every axis moves in proportion: velocities and accelerations are multiples of dq
        np.testing.assert_allclose(tr.qd, np.outer(tr.qd @ dq / (dq @ dq), dq), atol=1e-12)
        np.testing.assert_allclose(tr.qdd, np.outer(tr.qdd @ dq / (dq @ dq), dq), atol=1e-10)
        assert np.all(np.abs(tr.qd) <= lim.v_max * (1 + 1e-9))
        assert np.all(np.abs(tr.qdd) <= lim.a_max * (1 + 1e-9))
        # the leading axis: some axis reaches its velocity or acceleration limit (the move is as fast as the
        # line allows), and no axis alone could be slower than the move
        use = np.maximum(np.max(np.abs(tr.qd), axis=0) / lim.v_max, np.max(np.abs(tr.qdd), axis=0) / lim.a_max)
        assert np.max(use) > 0.98
        axes = zip(dq, lim.v_max, a_max, lim.j_max, strict=True)
        alone = [_single_axis_duration(float(d), float(v), float(a), float(j)) for d, v, a, j in axes]
        assert tr.duration >= max(alone) - 1e-9
        if scale_a3_accel == 1.0:  # proportional limits: the line is exactly as fast as the slowest axis
            assert tr.duration == pytest.approx(max(alone), rel=1e-9)
        assert ptp_duration(q0, q1, lim) == tr.duration


def test_line_deviation_measures_distance_from_the_segment() -> None:
    q = np.array([[0.0, 0.0], [0.5, 0.5], [1.0, 1.0]])
    assert ptp_line_deviation(q) == 0.0
    bent = np.array([[0.0, 0.0], [0.5, 0.6], [1.0, 1.0]])
    assert ptp_line_deviation(bent) == pytest.approx(0.05)
    past = np.array([[0.0, 0.0], [1.2, 1.2], [1.0, 1.0]])  # beyond the goal: off the segment
    assert ptp_line_deviation(past) == pytest.approx(0.2)
