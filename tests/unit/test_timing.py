"""Jerk-limited timing (Ruckig adapter): point-to-point moves and the weld path profile."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import ruckig

from cell.errors import TimingError
from cell.motion.limits import JointLimits
from cell.motion.robot import RobotModel
from cell.motion.timing import (
    Trajectory,
    _at_times,
    _at_times_loop,
    _solve,
    path_profile,
    ptp,
    ptp_duration,
)

URDF = Path(__file__).resolve().parents[2] / "robots" / "kr5_arc.urdf"
REL = 1e-9  # relative slack on limits for floating-point rounding


@pytest.fixture(scope="module")
def limits() -> JointLimits:
    return RobotModel.from_urdf(URDF).limits


def _cases(limits: JointLimits, n: int, seed: int) -> list[tuple[np.ndarray, ...]]:
    """Seeded random (q0, q1, v0, v1); velocities only where there is room to brake before a limit."""
    rng = np.random.default_rng(seed)
    out = []
    for k in range(n):
        q0, q1 = limits.sample(rng, margin=0.5), limits.sample(rng, margin=0.5)
        v0 = rng.uniform(-0.3, 0.3, limits.dof) * limits.v_max if k % 2 else np.zeros(limits.dof)
        v1 = rng.uniform(-0.3, 0.3, limits.dof) * limits.v_max if k % 3 == 0 else np.zeros(limits.dof)
        out.append((q0, q1, v0, v1))
    return out


def test_ptp_reaches_the_goal_within_limits(limits: JointLimits) -> None:
    dt = 0.001  # re-sampled at 1 kHz, exactly from the Ruckig profiles
    for q0, q1, v0, v1 in _cases(limits, 40, seed=1):
        tr = ptp(q0, q1, limits, v0=v0, v1=v1, dt=dt)
        assert tr.q.shape == (len(tr.times), 6) and tr.duration == tr.times[-1]
        np.testing.assert_allclose(tr.q[0], q0, atol=1e-12)
        np.testing.assert_allclose(tr.qd[0], v0, atol=1e-12)
        assert np.array_equal(tr.q[-1], q1) and np.array_equal(tr.qd[-1], v1)  # exactly the goal state
        assert np.all(np.abs(tr.qd) <= limits.v_max * (1 + REL))
        assert np.all(np.abs(tr.qdd) <= limits.a_max * (1 + REL))
        assert np.all(tr.q >= limits.q_min - 1e-9) and np.all(tr.q <= limits.q_max + 1e-9)
        # Continuity: no sample-to-sample jump beyond what the next-higher derivative's limit allows.
        h = np.diff(tr.times)[:, None]
        assert np.all(np.abs(np.diff(tr.q, axis=0)) <= limits.v_max * h * (1 + 1e-6) + 1e-12)
        assert np.all(np.abs(np.diff(tr.qd, axis=0)) <= limits.a_max * h * (1 + 1e-6) + 1e-12)
        assert np.all(np.abs(np.diff(tr.qdd, axis=0)) <= limits.j_max * h * (1 + 1e-6) + 1e-12)
        # No joint can arrive earlier than its own distance at full speed allows.
        assert tr.duration >= np.max(np.abs(q1 - q0) / limits.v_max) - 1e-9
        assert ptp_duration(q0, q1, limits, v0=v0, v1=v1) == tr.duration


def test_sample_interpolates_between_samples(limits: JointLimits) -> None:
    for q0, q1, v0, v1 in _cases(limits, 10, seed=2):
        coarse = ptp(q0, q1, limits, v0=v0, v1=v1)  # 4 ms
        fine = ptp(q0, q1, limits, v0=v0, v1=v1, dt=0.001)
        q, qd, qdd = coarse.sample(fine.times)
        np.testing.assert_allclose(q, fine.q, atol=1e-6)
        np.testing.assert_allclose(qd, fine.qd, atol=1e-3 * limits.v_max.max())
        assert np.all(np.abs(qdd - fine.qdd) <= 0.01 * limits.a_max)
        qs, qds, _ = coarse.sample(coarse.times[5])  # at a sample: the sample itself
        np.testing.assert_allclose(qs, coarse.q[5], atol=1e-12)
        np.testing.assert_allclose(qds, coarse.qd[5], atol=1e-12)
        assert np.array_equal(coarse.sample(coarse.duration + 1.0)[0], q1)  # clamped after the end


def test_vectorised_sampling_equals_ruckig_at_time(limits: JointLimits) -> None:
    q0, q1, v0, v1 = _cases(limits, 2, seed=3)[1]
    inp = ruckig.InputParameter(6)
    inp.current_position, inp.current_velocity = list(q0), list(v0)
    inp.target_position, inp.target_velocity = list(q1), list(v1)
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = (
        list(limits.v_max),
        list(limits.a_max),
        list(limits.j_max),
    )
    traj = _solve(inp, "test move")
    t = np.linspace(0.0, traj.duration, 777)
    for a, b in zip(_at_times(traj, t), _at_times_loop(traj, t), strict=True):
        np.testing.assert_allclose(a, b, atol=1e-12)


def test_ptp_rejects_infeasible_requests(limits: JointLimits) -> None:
    q = np.zeros(6)
    q_near = q.copy()
    q_near[0] = limits.q_max[0] - 0.01
    v_out = np.zeros(6)
    v_out[0] = 0.9 * limits.v_max[0]  # towards the limit 0.01 rad away: cannot brake in time
    with pytest.raises(TimingError, match="joint_a1"):
        ptp(q_near, q, limits, v0=v_out)
    q_out = q.copy()
    q_out[2] = limits.q_min[2] - 0.1
    with pytest.raises(TimingError, match="joint_a3"):
        ptp(q_out, q, limits)
    with pytest.raises(TimingError, match="velocity"):
        ptp(q, q, limits, v1=2.0 * limits.v_max)


def test_ruckig_errors_become_timing_errors(monkeypatch: pytest.MonkeyPatch) -> None:
    inp = ruckig.InputParameter(1)
    inp.current_position, inp.target_position = [0.0], [1.0]
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = (
        [-1.0],
        [1.0],
        [1.0],
    )  # negative limit: ruckig raises
    with pytest.raises(TimingError, match="maximum velocity limit"):
        _solve(inp, "bad move")

    class FailingRuckig:  # stands in for a solver that returns an error result instead of raising
        def __init__(self, dofs: int) -> None:
            pass

        def calculate(self, inp: object, traj: object) -> ruckig.Result:
            return ruckig.Result.ErrorSynchronizationCalculation

    monkeypatch.setattr(ruckig, "Ruckig", FailingRuckig)
    with pytest.raises(TimingError, match="ErrorSynchronizationCalculation"):
        path_profile(0.1, 0.01, 0.5, 5.0)


def test_zero_length_move_is_one_sample(limits: JointLimits) -> None:
    q = np.radians([10.0, -80.0, 90.0, 0.0, 20.0, 0.0])
    tr = ptp(q, q, limits)
    assert tr.duration == 0.0 and tr.q.shape == (1, 6)
    assert np.array_equal(tr.sample(0.3)[0], q)


def test_trajectory_is_validated_and_read_only() -> None:
    t = np.array([0.0, 0.1, 0.1])
    z = np.zeros((3, 2))
    with pytest.raises(ValueError, match="increase"):
        Trajectory(t, z, z, z)
    tr = Trajectory(np.array([0.0, 0.1]), z[:2], z[:2], z[:2])
    with pytest.raises(ValueError):
        tr.q[0, 0] = 1.0


@pytest.mark.parametrize(("length", "speed"), [(0.15, 0.008), (0.40, 0.010), (0.60, 0.25)])
def test_path_profile_travels_the_length_at_the_speed(length: float, speed: float) -> None:
    prof = path_profile(length, speed, a_max=0.5, j_max=5.0)
    assert prof.s[0] == 0.0 and prof.s[-1] == length and prof.sd[-1] == 0.0
    assert np.all(np.diff(prof.s) >= -1e-15) and np.all(prof.sd <= speed * (1 + REL))
    cruise = np.abs(prof.sdd) < 1e-12
    cruise[[0, -1]] = False
    assert cruise.sum() > 0.5 * len(prof.times)  # most of the weld at constant speed
    np.testing.assert_allclose(prof.sd[cruise], speed, rtol=0.01)
    assert prof(prof.duration / 2.0) == pytest.approx(length / 2.0, rel=1e-6)  # symmetric profile
    assert prof(prof.duration + 1.0) == length
    # A weld at constant speed takes at least length / speed.
    assert length / speed <= prof.duration <= length / speed + 2.0 * speed / 0.5 + 0.5


def test_path_profile_on_a_short_seam_stays_below_the_speed() -> None:
    prof = path_profile(0.004, 0.25, a_max=0.5, j_max=5.0)  # too short to reach 250 mm/s
    assert prof.s[-1] == 0.004 and np.all(prof.sd <= 0.25) and prof.sd.max() > 0.0
    assert np.all(np.abs(prof.sdd) <= 0.5 * (1 + REL))


def test_path_profile_rejects_bad_inputs() -> None:
    with pytest.raises(TimingError, match="speed_mps"):
        path_profile(0.1, 0.0, 0.5, 5.0)
