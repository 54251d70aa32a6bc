"""A curved seam from plan to execution: the far half of a post's fillet (an arc, built from the post's true curve
as the locator will hand it over), planned with the straight seams' planner, gated, played in the simulator and
measured against the true curve; then its programs (KRL CIRC and its check, RAPID ArcC)."""

from __future__ import annotations

import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from round_post import SEAM, post_scenario
from tools_loader import load_bench

from cell.export.checks.program import Program, check_program
from cell.export.checks.read import read_krl
from cell.export.krl import krl_program
from cell.export.program import ProgramJob
from cell.export.rapid import rapid_text
from cell.gate import find_violations
from cell.geometry import invert
from cell.motion.collision import CollisionChecker
from cell.motion.collision.scene import cell_obstacles
from cell.pipeline.detect import read_weldmap
from cell.pipeline.geometry import open_cell
from cell.pipeline.outcomes import curve_welds
from cell.planning.plan import plan_welds
from cell.process.torch import WeldProcess
from cell.seams.curve_truth import true_curves
from cell.types.plan import WeldPlan


@pytest.fixture(scope="module")
def welded(tmp_path_factory: pytest.TempPathFactory) -> dict[str, object]:
    sc = post_scenario(tmp_path_factory.mktemp("post"), 0.0, 0.1)
    weldmap = read_weldmap(sc)
    with open_cell(sc, weldmap) as station:
        arm = station.arm
        assert arm is not None
        weldmap_R = weldmap.transformed(invert(sc.X_WR) @ sc.X_WM, "R")
        truth = true_curves(weldmap, station.parts_W, sc.X_WM, sc.X_WR)[SEAM]
        est = load_bench("bench_curve_weld").truth_estimate(weldmap_R.curved[0], weldmap_R, truth)
        far = np.flatnonzero(est.p_RS[:, 1] >= est.p_RS[:, 1].mean())  # the half away from the robot: an arc
        arc = replace(
            est,
            p_RS=est.p_RS[far],
            n_abutting_R=est.n_abutting_R[far],
            n_receiving_R=est.n_receiving_R[far],
            sigma_m=est.sigma_m[far],
            closed=False,
            end_sigma_m=(1e-4, 1e-4),
        )
        obstacles = cell_obstacles(weldmap_R, sc.X_WR, sc.table.center_m, sc.table.size_m)
        checker = CollisionChecker(arm.model, obstacles, sc.motion.plan.collision)
        process = WeldProcess.from_spec(sc.process, sc.robot.stickout_mm)
        plan = plan_welds(arm.model, [], arm.q_home, process, obstacles, options=sc.motion.plan, checker=checker,
                          curves=[arc])  # fmt: skip
        gate = find_violations(
            arm.model, plan, arm.q_home, checker=checker, options=sc.motion.gate, bodies=weldmap_R.parts,
            wire_m=process.stickout, joint_parts={SEAM: ("POST", "PLATE")},
        )  # fmt: skip
        traj, arc_on = plan.joint_trajectory()
        ex = station.execute(traj.times, traj.q, arc_on, record_dt=0.01)
        far_truth = truth[truth[:, 1] >= truth[:, 1].mean()]
        quality = curve_welds(plan, ex, 0.0, {SEAM: far_truth}, {SEAM: False}, sc.X_WR)
        return {"plan": plan, "gate": gate, "quality": quality, "robot": arm.model, "arc": arc}


def test_an_arc_is_planned_gated_and_welded_on_its_true_curve(welded: dict[str, object]) -> None:
    plan = welded["plan"]
    assert isinstance(plan, WeldPlan)
    assert plan.outcome(SEAM).feasible, plan.outcome(SEAM).reason
    assert list(welded["gate"]) == []  # type: ignore[call-overload]
    weld = next(s for s in plan.segments if s.kind == "weld")
    assert weld.X_path is not None and len(weld.X_path) > 40
    a6 = np.concatenate([s.trajectory.q[:, 5] for s in plan.segments])
    assert np.max(np.abs(np.diff(a6))) < 0.01  # A6 continuous at 1 kHz: no turn of the wrist on the spot
    q = welded["quality"][SEAM]  # type: ignore[index]
    assert q.tcp_max_mm < 0.1 and q.tcp_rms_mm < 0.05  # the knots on the truth, the spline between them
    assert abs(q.speed_mm_s - 8.0) < 0.2  # the procedure's travel speed along the curve
    assert q.short_start_mm + q.short_end_mm < 2.0  # the whole arc welded (the estimate samples it every 2 mm)


def test_its_programs_hold_circular_moves_that_pass_the_check(welded: dict[str, object], tmp_path: Path) -> None:
    plan, robot = welded["plan"], welded["robot"]
    assert isinstance(plan, WeldPlan)
    src, dat = krl_program(plan, robot, "CURVE")  # type: ignore[arg-type]
    circs = re.findall(r"^CIRC (XP\d+), (XP\d+), CA ([\d.]+)$", src, re.M)
    assert len(circs) == 2  # the half circle in two arcs of at most 90 deg
    assert sum(float(c[2]) for c in circs) == pytest.approx(178.0, abs=3.0)

    def findings(dat_text: str) -> list[str]:
        p = Program("CURVE", read_krl(src, "src"), read_krl(dat_text, "dat"), "CURVE.src", "CURVE.dat")
        return [f.code for f in check_program(p)]

    assert findings(dat) == []
    aux = circs[0][0]  # an auxiliary point moved 1 mm off the planned circle: the check says so
    line = next(ln for ln in dat.splitlines() if ln.startswith(f"DECL E6POS {aux}="))
    moved = re.sub(r"\{X ([-\d.]+),", lambda m: f"{{X {float(m.group(1)) + 1.0:.3f},", line, count=1)
    assert moved != line
    assert "circ" in findings(dat.replace(line, moved))
    rapid = rapid_text(ProgramJob(plan, robot, "CURVE"))  # type: ignore[arg-type]
    assert re.search(r"^\s+ArcC p\d+, p\d+, vL8,", rapid, re.M)
    assert re.search(r"^\s+ArcCEnd p\d+, p\d+, vL8,", rapid, re.M)
