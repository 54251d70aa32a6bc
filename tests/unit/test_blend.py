"""Approximate positioning of the arc-off motions (cell/planning/blend.py): a run of PTP moves blended at the points
between them arrives sooner, within every limit, and the welds around it stay as they were."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest

from cell.motion.limits import JointLimits
from cell.motion.robot import RobotModel
from cell.motion.timing import ptp
from cell.planning.blend import blend_plan
from cell.types.plan import Segment, SegmentKind
from cell.types.trajectory import Trajectory

URDF = Path(__file__).resolve().parents[2] / "robots" / "kr5_arc.urdf"
DT = 0.001  # [s]
POINTS = np.radians(
    [[0, -90, 90, 0, 45, 0], [30, -80, 85, 10, 40, 5], [60, -70, 95, 0, 50, 0], [80, -95, 100, -10, 35, 0]]
)


@pytest.fixture(scope="module")
def limits() -> JointLimits:
    return RobotModel.from_urdf(URDF).limits


def _segments(limits: JointLimits) -> list[Segment]:
    """Three moves through POINTS, then a 'weld' standing still for 0.2 s, then a move back to the start."""
    moves = [ptp(a, b, limits, dt=DT) for a, b in itertools.pairwise(POINTS)]
    hold = np.repeat(POINTS[-1:], 201, axis=0)
    still = Trajectory(np.arange(201, dtype=float) * 0.001, hold, np.zeros_like(hold), np.zeros_like(hold))
    back = ptp(POINTS[-1], POINTS[0], limits, dt=DT)
    segs, t = [], 0.0
    kinds: list[tuple[SegmentKind, Trajectory]] = [*(("move", m) for m in moves), ("weld", still), ("move", back)]
    for kind, tr in kinds:
        segs.append(Segment(kind, "s", tr, t, np.eye(4), arc_on=kind == "weld"))
        t += tr.duration
    return segs


def _tcp(q: np.ndarray) -> np.ndarray:
    return np.asarray(q[:3], dtype=float)


def test_a_blended_run_is_faster_within_the_limits_and_meets_its_neighbours(limits: JointLimits) -> None:
    segs = _segments(limits)
    out = blend_plan(segs, limits, _tcp, lambda tr: True, fraction=0.5, dt=DT)
    assert [s.kind for s in out] == [s.kind for s in segs]
    before = sum(s.trajectory.duration for s in segs[:3])
    after = sum(s.trajectory.duration for s in out[:3])
    assert after < before - 0.1  # two points flown past: a tenth of a second or more saved
    # the middle move, joined at its half, is left right there: each blend takes up to half of each motion
    assert out[1].trajectory.duration - out[1].link_s < 0.005 < out[1].link_s
    for a, b in itertools.pairwise(out):
        np.testing.assert_allclose(a.trajectory.q[-1], b.trajectory.q[0], atol=1e-12)
        np.testing.assert_allclose(a.trajectory.qd[-1], b.trajectory.qd[0], atol=1e-9)
        assert b.t0 == pytest.approx(a.t1)
    q = np.concatenate([s.trajectory.q[int(k > 0) :] for k, s in enumerate(out[:3])])
    qd = np.concatenate([s.trajectory.qd[int(k > 0) :] for k, s in enumerate(out[:3])])
    qdd = np.concatenate([s.trajectory.qdd[int(k > 0) :] for k, s in enumerate(out[:3])])
    t = np.concatenate([s.trajectory.times[int(k > 0) :] + s.t0 for k, s in enumerate(out[:3])])
    assert np.all(np.abs(qd) <= limits.v_max * (1 + 1e-9)) and np.all(np.abs(qdd) <= limits.a_max * (1 + 1e-9))
    jerk = np.diff(qdd, axis=0) / np.diff(t)[:, None]
    assert np.all(np.abs(jerk) <= limits.j_max * 1.01)  # the safety gate's tolerance
    np.testing.assert_allclose(q[-1], POINTS[3], atol=1e-12)  # the weld's start reached exactly, at rest
    np.testing.assert_allclose(qd[-1], 0.0, atol=1e-12)
    for k in (0, 1):  # left before its point, the programmed point kept as its target
        target = out[k].q_target
        assert out[k].zone_m > 0.0 and target is not None
        np.testing.assert_allclose(target, POINTS[k + 1])
        assert out[k].zone_m == pytest.approx(float(np.linalg.norm(_tcp(out[k].trajectory.q[-1]) - POINTS[k + 1, :3])))
    assert out[2].zone_m == 0.0  # the weld's start: an exact stop
    assert out[3].trajectory is segs[3].trajectory and out[4].trajectory is segs[4].trajectory  # a lone move too
    assert out[3].t0 == pytest.approx(after)  # the weld comes sooner by what the blends saved


def test_a_blend_that_is_not_clear_stays_an_exact_stop(limits: JointLimits) -> None:
    segs = _segments(limits)
    out = blend_plan(segs, limits, _tcp, lambda tr: False, fraction=0.5, dt=DT)
    assert [s.trajectory for s in out] == [s.trajectory for s in segs]
    assert all(s.zone_m == 0.0 and s.q_target is None for s in out)
    with pytest.raises(ValueError, match="within"):
        blend_plan(segs, limits, _tcp, lambda tr: True, fraction=0.7)


def test_the_cuts_shorten_one_motion_before_both() -> None:
    """Where the longest link is not clear, the cut into one motion is shortened before both are (a link colliding
    near one motion's point need not lose the other's cut), and every cut down to a sixteenth is tried (three
    quarters and three eighths among them), longest first."""
    from cell.planning.blend import _CUTS

    assert _CUTS[0] == (1.0, 1.0) and len(set(_CUTS)) == len(_CUTS) == 49
    assert _CUTS.index((1.0, 0.75)) < _CUTS.index((0.75, 0.75)) < _CUTS.index((1.0, 0.5))
    assert _CUTS.index((1.0, 0.5)) < _CUTS.index((0.5, 0.5)) and _CUTS.index((0.5, 1.0)) < _CUTS.index((0.5, 0.5))
    totals = [a + b for a, b in _CUTS]
    assert totals == sorted(totals, reverse=True)
