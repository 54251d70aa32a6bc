"""A part partly out of the fixed arm's reach, welded on a linear track through the whole pipeline: fence1 with the
robot's base 0.7 m to the left on a track (docs/track.md). One run (module fixture): capture at a reduced camera
resolution without noise and no close-up re-scan (the track is what is tested, not perception), plan, gate and
execution in the simulator, whose base rides the track."""

from __future__ import annotations

import numpy as np
import pytest

from cell import pipeline
from cell import scenario as sc
from cell.export.krl import krl_program
from cell.planning.plan import reach_model
from cell.planning.tasks import seam_tasks
from cell.planning.track import reach_curves
from cell.process.torch import WeldProcess

BASE_X = -0.55  # [m] the base's x in W (fence1's is 0.15): the fence's right post is beyond the fixed reach


def _scenario() -> sc.Scenario:
    text = (sc.SCENARIO_DIR / "fence1.yaml").read_text()
    swaps = {
        "X_WR: {xyz_m: [0.15, -1.05, 0.90]}": f"X_WR: {{xyz_m: [{BASE_X}, -1.05, 0.90]}}\n"
        "  track: {axis_W: [1.0, 0.0, 0.0], min_mm: -200.0, max_mm: 1000.0, speed_mm_s: 800.0}",
        "eye_m: [0.15, -0.45, 2.05]": f"eye_m: [{BASE_X}, -0.45, 2.05]",  # the scan pose moves with the base
        "target_m: [0.15, 0.0, 0.94]": f"target_m: [{BASE_X}, 0.0, 0.94]",
        "    up: [0.0, 1.0, 0.0]": "    up: [0.0, 1.0, 0.0]\n    resolution: [640, 360]",
        "noise: realistic": "noise: none",
    }
    for old, new in swaps.items():
        assert old in text, old
        text = text.replace(old, new)
    return sc.from_yaml(text, sc.SCENARIO_DIR, "fence1-track.yaml")


@pytest.fixture(scope="module")
def run() -> pipeline.WeldRun:
    return pipeline.weld(_scenario(), pipeline.WeldJob(rescan="none"))


def test_seams_beyond_the_fixed_reach_are_welded_from_the_track(run: pipeline.WeldRun) -> None:
    plan, det = run.plan, run.detection
    assert plan is not None and plan.track is not None and run.error is None and run.execution is not None
    by_id = {w.id: w for w in run.seams}
    at = {s.seam_id: s.e1_end for s in plan.segments if s.arc_on}
    far = [sid for sid, e in at.items() if e > 0.3]
    assert far and all(by_id[sid].welded for sid in far)
    # measured in the simulator, whose base the track carried: on the true seam, not E1 off it
    assert max(by_id[sid].quality.tcp_max_mm for sid in far) < 1.0  # type: ignore[union-attr]
    # some of them no torch could reach from E1 = 0 (the pre-check's bound, every torch the process allows)
    ss = det.scene.seam_scene  # type: ignore[union-attr]
    tasks = [t for t in seam_tasks(det.estimates, ss.weldmap, ss.joints, ss.table_z) if t.id in far]
    assert run.arm is not None
    reach = reach_model(run.arm.model)
    process = WeldProcess.from_spec(det.scenario.process, det.scenario.robot.stickout_mm)
    assert reach is not None and plan.track is not None
    sure = reach_curves(reach, tasks, [process] * len(tasks), plan.track, np.array([0.0]), cone=True)
    assert np.any(sure[:, 0] > 0.0)
    # the carriage goes out and back, the arm at home; every visible seam welded or refused with its reason
    e1 = plan.joint_trajectory()[0].e1
    assert e1 is not None and e1[0] == 0.0 and e1[-1] == 0.0 and e1.max() > 0.3
    visible = [w for w in run.seams if w.code is None or w.code.value != "not_visible"]
    assert all(w.welded or w.reason for w in visible)


def test_the_program_carries_the_track(run: pipeline.WeldRun) -> None:
    plan = run.plan
    assert plan is not None and run.arm is not None
    src, dat = krl_program(plan, run.arm.model, "FENCE_TRACK")
    assert "Linear track E1" in src and "software limits -200.0 .. 1000.0 mm" in src
    e1 = {round(s.e1_end * 1000.0, 3) for s in plan.segments if s.arc_on}
    assert any(f"E1 {v:.3f}" in dat for v in e1 if v)


def test_the_pictures_draw_the_arm_where_the_carriage_has_it(run: pipeline.WeldRun) -> None:
    """The preview's robot poses follow the track: during a weld planned from E1 > 0.3 m every link stands that far
    along the axis from where the arm's own kinematics would put it at the same joints."""
    plan, view, arm = run.plan, run.view, run.arm
    assert plan is not None and plan.track is not None and view is not None and arm is not None
    far = [s for s in plan.segments if s.arc_on and s.e1_end > 0.3]
    assert far
    seg = far[0]
    t = (seg.t0 + seg.t1) / 2.0
    pose = min(view.poses[1:], key=lambda p: abs(p.t_s - t))
    assert seg.t0 <= pose.t_s <= seg.t1
    q, _, _ = plan.sample(pose.t_s)
    links = tuple(pose.X_RL)
    X0 = arm.model.fk_frames(q, links)
    d_R = plan.track.offset_R(seg.e1_end)
    for link in links:
        np.testing.assert_allclose(np.asarray(pose.X_RL[link])[:3, 3] - X0[link][:3, 3], d_R, atol=1e-9)
