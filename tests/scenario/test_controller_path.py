"""The path the controller drives, on the session's fence1 run (``fence1_run``): every PTP move the simulator
played lies on the straight joint line a KRC4 PTP drives between its programmed ends (outside the blends that
join and leave it within its zones), the gate checked those same samples, and the hose package's A6 window held."""

from __future__ import annotations

import numpy as np

from cell import pipeline
from cell.gate import GateInput, GateOptions
from cell.motion.timing import ptp_line_deviation

MAX_PTP_DEVIATION = np.radians(0.01)  # [rad] the acceptance bound (measured: 0 up to rounding, < 1e-12 deg)


def _executed(run: pipeline.WeldRun, t0: float, t1: float, ends: np.ndarray) -> np.ndarray:
    """The executed joint samples within [t0, t1] of the run's clock, with the planned ends (n, dof) [rad]."""
    ex = run.execution
    assert ex is not None
    inside = (ex.times >= t0 - 1e-9) & (ex.times <= t1 + 1e-9)
    return np.vstack([ends[0], ex.q[inside], ends[-1]])


def test_every_executed_ptp_move_is_the_krc_joint_line(fence1_run: pipeline.WeldRun) -> None:
    run = fence1_run
    plan, pre = run.plan, run.pre_move
    assert plan is not None and pre is not None and run.execution is not None and not run.violations
    segs = plan.segments
    moves = [k for k, s in enumerate(segs) if s.kind == "move" and s.trajectory.duration > 0.0]
    assert len(moves) >= 12  # home -> first seam, between seams, last seam -> home
    worst = ptp_line_deviation(_executed(run, 0.0, pre.duration, pre.q))  # scan pose -> home is a PTP too
    blended = 0
    for k in moves:
        # A move blended into the next motion is left inside its zone, one joined from the previous motion starts
        # with the link: between the two it is the straight line from its programmed start to its programmed end.
        s = segs[k]
        start = segs[k - 1].q_end if k else plan.q_home
        blended += s.zone_m > 0.0 or s.link_s > 0.0
        t0, t1 = pre.duration + s.t0 + s.link_s, pre.duration + s.t1
        q = _executed(run, t0, t1, np.array([start, s.q_end]))
        # the programmed ends and the executed samples between (recorded every 10 ms); a move joined at its half and
        # left right there (each blend takes up to half of each motion) may have no record in its straight part
        assert len(q) >= 3 or t1 - t0 < 0.01
        worst = max(worst, ptp_line_deviation(q))
        # synchronised axes: every moving axis moves one way all along the straight part (none at rest inside it)
        dq = s.q_end - start
        moving = np.abs(dq) > 1e-6
        straight = s.trajectory.times >= s.link_s
        inner = s.trajectory.qd[straight][1:-1][:, moving]
        assert np.all(inner * np.sign(dq[moving]) > 0.0)
    assert worst <= MAX_PTP_DEVIATION, np.degrees(worst)
    assert blended >= len(moves) // 2  # most moves join or leave another without stopping
    # The gate checks the same path: its 1 kHz re-sampling of the plan lies on the same lines.
    assert run.arm is not None
    gate = GateInput(run.arm.model, plan, pre.q[-1], None, GateOptions())
    r = gate.resampled
    for k in moves:
        s = segs[k]
        start = segs[k - 1].q_end if k else plan.q_home
        inside = (r.t >= s.t0 + s.link_s) & (r.t <= s.t1)
        path = np.vstack([start, r.q[inside], s.q_end])
        assert inside.sum() > 0 and ptp_line_deviation(path) <= MAX_PTP_DEVIATION


def test_a6_stays_in_the_hose_window_without_wrist_flips(fence1_run: pipeline.WeldRun) -> None:
    run = fence1_run
    assert run.plan is not None and run.execution is not None
    opt = run.detection.scenario.motion.plan
    a6 = run.execution.q[:, 5]
    assert np.all(np.abs(a6 - opt.a6_center) <= opt.a6_window)  # default: 0 +- 185 deg
    assert np.ptp(a6) <= np.radians(285.0)  # measured 267 deg (387 deg before the window and the wrist choice)
    lo, hi = run.plan.joint_ranges()["joint_a6"]  # what the report gives as joint_range_deg
    assert lo <= a6.min() + 1e-6 and a6.max() - 1e-6 <= hi and hi - lo <= np.radians(285.0)
    # no flip between seams: A5 keeps home's sign (KUKA's status bit 2) at every weld, and A4 at consecutive weld
    # starts never swings near half a turn
    starts = np.array([s.trajectory.q[0] for s in run.plan.segments if s.kind == "weld"])
    assert np.all(np.sign(starts[:, 4]) == np.sign(run.plan.q_home[4]))
    assert np.max(np.abs(np.diff(starts[:, 3]))) <= np.radians(85.0)  # measured 66 deg (185 deg before)
