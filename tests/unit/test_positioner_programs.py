"""The programs of a part on a positioner: KRL with E2/E3 in every point and the base on the kinematic chain, RAPID
with a coordinated work object and eax_b/eax_c, and ``cell krl check`` on the positioner's axes. The tiny cell's
plan (tests/unit/test_krl.py) is written as if the faceplate stood at a tilt and a rotation."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest
from test_krl import HOME, OBSTACLES, PROCESS, SEAMS, URDF

from cell.export.checks.calls import check_all
from cell.export.checks.program import read_programs
from cell.export.positioner_program import positioner_texts
from cell.export.program import ProgramJob, write_texts
from cell.motion.robot import RobotModel
from cell.planning.plan import plan_welds
from cell.scenario.positioner_specs import PositionerSpec
from cell.types.positioner import external_axes


@pytest.fixture(scope="module")
def jobs() -> list[ProgramJob]:
    robot = RobotModel.from_urdf(URDF)
    pos = PositionerSpec(base_xyz_m=(0.6, 0.0, -0.6), tilt_height_mm=400).positioner(np.eye(4))
    out = []
    for k, seams in enumerate((SEAMS[:1], SEAMS[1:2])):
        tilt, rotate = math.radians(30.0 * (k + 1)), math.radians(-45.0 * k)
        plan = plan_welds(robot, seams, HOME, PROCESS, OBSTACLES)
        ext = external_axes(pos, tilt, rotate)
        out.append(ProgramJob(plan, robot, f"POS_P{k + 1}", X_RB=pos.X_R_F(tilt, rotate), external=ext))
    return out


def test_krl_points_carry_the_positioner_and_pass_the_check(jobs: list[ProgramJob], tmp_path: Path) -> None:
    texts = positioner_texts("krl", jobs, "pos")
    src, dat = texts["POS_P2.src"], texts["POS_P2.dat"]
    assert "$BASE = EK(MACHINE_DEF[2].ROOT, MACHINE_DEF[2].MECH_TYPE, BASE_DATA[1])" in src
    assert "BAS(#BASE" not in src
    points = re.findall(r"^DECL E6(?:POS|AXIS) XP\d+=\{.*\}$", dat, flags=re.M)
    assert points and all(", E2 60.000, E3 -45.000," in p for p in points)
    assert "PTP XPOSITIONER" in src and "E2 60.000, E3 -45.000" in dat
    write_texts(texts, tmp_path)
    programs, found = read_programs(tmp_path)
    assert not found
    assert check_all(programs, jobs[0].robot) == []  # S/T from the stated base, calls without an operator stop


def test_krl_check_finds_a_positioner_axis_beyond_its_limit(jobs: list[ProgramJob], tmp_path: Path) -> None:
    texts = positioner_texts("krl", jobs[:1], "pos")
    dat = texts["POS_P1.dat"]
    dat, n = re.subn(r"(DECL E6POS XP2=\{.*?), E2 30\.000", r"\1, E2 141.000", dat)
    assert n == 1
    dat, n = re.subn(r"(DECL E6AXIS XP1=\{.*?), E3 0\.000", r"\1", dat)
    assert n == 1
    texts["POS_P1.dat"] = dat
    write_texts(texts, tmp_path)
    programs, _ = read_programs(tmp_path)
    found = [f.message for f in check_all(programs, jobs[0].robot) if f.code == "positioner"]
    assert found == [
        "XP1 has no E3: the program runs on a positioner",
        "XP2: E2 141 deg is outside its limits -135 .. 135",
    ]


def test_a_route_round_the_arm_is_driven_as_the_move_check_cleared_it(jobs: list[ProgramJob], tmp_path: Path) -> None:
    """The positioner's via points (the route :func:`~cell.pipeline.positioned.sweep.clear_route` found when the
    straight move sweeps the part into the arm) come before the move to the pose, in both languages, and
    ``cell krl check`` holds them to the axes' limits."""
    from dataclasses import replace

    ext = jobs[1].external
    assert ext is not None
    routed = replace(jobs[1], external=replace(ext, via_deg=((0.0, -45.0), (60.0, -45.0))))
    texts = positioner_texts("krl", [routed], "pos")
    src, dat = texts["POS_P2.src"], texts["POS_P2.dat"]
    moves = re.findall(r"^PTP (XPOS\w+)", src, flags=re.M)
    assert moves == ["XPOSVIA1", "XPOSVIA2", "XPOSITIONER"]
    assert re.search(r"DECL E6AXIS XPOSVIA1=\{.*, E2 0\.000, E3 -45\.000", dat)
    write_texts(texts, tmp_path)
    programs, _ = read_programs(tmp_path)
    assert check_all(programs, jobs[0].robot) == []
    beyond = replace(jobs[1], external=replace(ext, via_deg=((150.0, -45.0),)))
    write_texts(positioner_texts("krl", [beyond], "pos"), tmp_path / "beyond")
    programs, _ = read_programs(tmp_path / "beyond")
    found = [f.message for f in check_all(programs, jobs[0].robot) if f.code == "positioner"]
    assert found == ["XPOSVIA1: E2 150 deg is outside its limits -135 .. 135"]
    mod = positioner_texts("rapid", [routed], "pos")["POS_P2.mod"]
    body = [ln.strip() for ln in mod.splitlines() if ln.strip().startswith("MoveAbsJ")]
    assert body[:3] == [
        "MoveAbsJ jPosVia1, v1000, fine, tWeld;  ! on the way: a straight move meets the arm",
        "MoveAbsJ jPosVia2, v1000, fine, tWeld;  ! on the way: a straight move meets the arm",
        "MoveAbsJ jHome, v1000, fine, tWeld;",
    ]
    assert re.search(r"CONST jointtarget jPosVia1 := \[\[.*\],\[9E9,0\.000,-45\.000,9E9,9E9,9E9\]\];", mod)


def test_rapid_uses_a_coordinated_work_object(jobs: list[ProgramJob]) -> None:
    mod = positioner_texts("rapid", jobs[1:], "pos")["POS_P2.mod"]
    assert 'PERS wobjdata wobjPart := [FALSE,FALSE,"STN1",' in mod
    assert "    ActUnit STN1;" in mod and "    DeactUnit STN1;" in mod
    targets = re.findall(r"CONST robtarget p\d+ := \[.*\];", mod)
    assert targets and all(t.endswith(",[9E9,60.000,-45.000,9E9,9E9,9E9]];") for t in targets)


def test_cell_weld_takes_a_positioner_scenario_and_refuses_what_does_not_apply(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from typer.testing import CliRunner

    from cell.cli import app
    from cell.sim.cell import SimCell

    started: list[bool] = []
    monkeypatch.setattr(SimCell, "__init__", lambda *a, **k: started.append(True))
    result = CliRunner().invoke(app, ["weld", "fence1-positioner", "--sides", "first", "--json", str(tmp_path / "r")])
    assert result.exit_code == 2, result.stderr
    assert "--sides first" in result.stderr and "robot.positioner" in result.stderr and "--program" in result.stderr
    assert not started and not (tmp_path / "r").exists()  # refused before any work


def test_a_partial_positioner_job_names_each_unwelded_seams_reason() -> None:
    from cell.cli.positioner import partial_line

    codes = (None, "not_planned", "low_confidence", "not_planned")
    seams = [{"welded": c is None, "reason_code": c} for c in codes]
    rep = {"seams": seams, "error": None, "totals": {"welded": 1, "seams": 4}}
    assert partial_line(rep) == "exit 3: 3 seams not welded (low_confidence: 1, not_planned: 2); 1/4 welded"
    assert partial_line({**rep, "seams": seams[:1], "totals": {"welded": 1, "seams": 1}}) is None


def test_the_main_program_calls_the_coordinated_welds_after_the_poses_as_they_were_played(
    jobs: list[ProgramJob],
) -> None:
    """The coordinated welds' programs are called by the main program after the poses' (the order the simulation
    played them), each named with what it welds; with no pose's plan the main program still calls them, its home
    the one given."""
    after = [("pos_c1", "seam RUN>END_L:circle from 356 to 578 mm along it"), ("pos_c2", "seam BRANCH>RUN:saddle")]
    src = positioner_texts("krl", jobs, "pos", after)["POS.src"]
    calls = re.findall(r"^(\w+)\( \)$", src, flags=re.M)
    assert calls == [*(j.name.upper() for j in jobs), "POS_C1", "POS_C2"]
    assert ";- coordinated weld 2 of 2: POS_C2, seam BRANCH>RUN:saddle" in src
    q_home = np.radians([-90.0, -100.0, 100.0, 0.0, 45.0, 0.0])
    alone = positioner_texts("krl", [], "pos", after, q_home)
    assert set(alone) == {"POS.src", "POS.dat"}  # the coordinated programs are written beside it by their own post
    assert re.findall(r"^(\w+)\( \)$", alone["POS.src"], flags=re.M) == ["POS_C1", "POS_C2"]
    assert "XHOME_PLAN={A1 -90.000, A2 -100.000, A3 100.000," in alone["POS.dat"]
    with pytest.raises(ValueError, match="nothing to export"):
        positioner_texts("krl", [], "pos")
