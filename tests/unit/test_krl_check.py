"""The project's KRL reader and ``cell krl check`` on small programs: an arc switch where the procedure changes
within a burning arc, the plain-signal mode, and the findings of broken programs (on the tiny cell's plan)."""

from __future__ import annotations

import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from test_krl import HOME, OBSTACLES, PROCESS, SEAMS, URDF

from cell.export.checks.kinematics import check_kinematics
from cell.export.checks.program import check_program, read_programs
from cell.export.checks.read import parse_value, read_krl
from cell.export.krl import KrlOptions, write_krl
from cell.motion.robot import RobotModel
from cell.planning.plan import plan_welds
from cell.types import Trajectory, Weave, WeldPass, WeldProcedure
from cell.types.plan import WeldPlan


@pytest.fixture(scope="module")
def robot() -> RobotModel:
    return RobotModel.from_urdf(URDF)


@pytest.fixture(scope="module")
def two_pass_plan(robot: RobotModel) -> WeldPlan:
    """The tiny cell's plan with one seam's weld split at half its samples into a root pass (the process's
    figures) and a second, weaving procedure: one burning arc whose data change half way."""
    plan = plan_welds(robot, SEAMS[:1], HOME, PROCESS, OBSTACLES)
    k = next(i for i, s in enumerate(plan.segments) if s.kind == "weld")
    weld = plan.segments[k]
    tr, m = weld.trajectory, len(weld.trajectory.times) // 2
    first = Trajectory(tr.times[: m + 1], tr.q[: m + 1], tr.qd[: m + 1], tr.qdd[: m + 1])
    t_m = tr.times[m]
    second = Trajectory(tr.times[m:] - t_m, tr.q[m:], tr.qd[m:], tr.qdd[m:])
    cap = WeldProcedure(name="cap", current_a=170.0, weave=Weave("zigzag", 4.0, 1.5, (0.1, 0.1)),
                        passes=(WeldPass(), WeldPass(lift_mm=2.0)))  # fmt: skip
    a = replace(weld, trajectory=first, X_end=robot.fk(tr.q[m], "torch_tcp"))
    b = replace(weld, trajectory=second, t0=weld.t0 + t_m, procedure=cap, pass_index=1)
    return replace(plan, segments=(*plan.segments[:k], a, b, *plan.segments[k + 1 :]))


def _check(directory: Path, robot: RobotModel) -> list[tuple[str, str]]:
    programs, found = read_programs(directory)
    for p in programs:
        found += check_program(p) + check_kinematics(p, robot)
    return [(f.code, f.message) for f in found]


def test_the_reader_reads_nested_krl_values() -> None:
    v = parse_value('{WdatId[] "W1",Weld {Velocity 0.008,Channel1 7.0},Weave {Pattern #None},On TRUE}')
    assert v == {"WDATID": "W1", "WELD": {"VELOCITY": 0.008, "CHANNEL1": 7.0}, "WEAVE": {"PATTERN": "#None"},
                 "ON": True}  # fmt: skip
    f = read_krl("DEFDAT X PUBLIC\nDECL E6POS P1={X 1.5, Y -2, Z 3e1, A 0, B 0, C 0, S 2, T 35}\nENDDAT\n", "dat")
    assert f.module == "X" and f.closed and f.decls["P1"].value["Z"] == 30.0 and not f.problems
    bad = read_krl("DEF Y( )\nLIN {X 1, Y\nEND\n", "src")
    assert bad.closed and [p.line for p in bad.problems] == [2]


def test_arc_switch_where_the_procedure_changes_and_the_check_passes(
    robot: RobotModel, two_pass_plan: WeldPlan, tmp_path: Path
) -> None:
    src_path, dat_path = write_krl(two_pass_plan, robot, tmp_path, "passes")
    src, dat = src_path.read_text(), dat_path.read_text()
    kinds = re.findall(r"^;FOLD (ARCON|ARCSWI|ARCOFF) (\w+)", src, flags=re.M)
    assert [k for k, _ in kinds] == ["ARCON", "ARCSWI", "ARCOFF"]
    swi = next(ln for ln in dat.splitlines() if ln.startswith(f"DECL stArcDat_T {kinds[1][1]}="))
    # the switch carries the second part's data: the cap's current and its weave (wavelength 8 / 1.5 mm)
    assert "Channel3 170.000" in swi and "Pattern #Triangle,Length 5.333,Amplitude 2.000" in swi
    assert "procedure cap pass 2/2" in src
    assert _check(tmp_path, robot) == []


def test_plain_signal_program_passes_and_a_missing_wait_fails(
    robot: RobotModel, two_pass_plan: WeldPlan, tmp_path: Path
) -> None:
    opt = KrlOptions(arc="signals")
    write_krl(two_pass_plan, robot, tmp_path / "ok", "sig", options=opt)
    assert _check(tmp_path / "ok", robot) == []
    bad = tmp_path / "bad"
    src_path2, _ = write_krl(two_pass_plan, robot, bad, "sig", options=opt)
    text = src_path2.read_text()
    src_path2.write_text(re.sub(r"^WAIT FOR \$IN\[1\].*\n", "", text, count=1, flags=re.M))
    assert ("arc", "welding motion before WAIT FOR the arc-established input") in _check(bad, robot)


def test_findings_of_a_broken_program(robot: RobotModel, two_pass_plan: WeldPlan, tmp_path: Path) -> None:
    src_path, dat_path = write_krl(two_pass_plan, robot, tmp_path, "broken")
    text = src_path.read_text().replace("INTERRUPT ON 3\n", "").replace("DEF BROKEN( )", "DEF OTHER( )")
    src_path.write_text(text)
    wdat = re.search(r"^;FOLD ARCSWI (\w+)", text, flags=re.M).group(1)  # type: ignore[union-attr]
    dat_path.write_text(re.sub(rf"^DECL stArcDat_T {wdat}=.*\n", "", dat_path.read_text(), flags=re.M))
    found = _check(tmp_path, robot)
    assert ("init", "INTERRUPT ON 3 is missing before the first motion") in found
    assert ("files", "DEF OTHER differs from the file name BROKEN") in found
    assert ("arc", f"weld data set {wdat} is not declared (stArcDat_T)") in found
    (tmp_path / "BROKEN.dat").unlink()
    assert _check(tmp_path, robot) == [("files", "no BROKEN.dat beside BROKEN.src")]


def test_a_point_off_the_line_is_unreachable_from_the_point_before(
    robot: RobotModel, two_pass_plan: WeldPlan, tmp_path: Path
) -> None:
    _, dat_path = write_krl(two_pass_plan, robot, tmp_path, "far")
    text = dat_path.read_text()
    m = re.search(r"^DECL E6POS (\w+)=\{X (-?[\d.]+),", text, flags=re.M)
    assert m is not None
    dat_path.write_text(text.replace(m.group(0), f"DECL E6POS {m.group(1)}={{X {float(m.group(2)) + 3000.0:.3f},"))
    found = _check(tmp_path, robot)
    assert [c for c, _ in found] == ["kinematics"] and found[0][1].startswith(f"{m.group(1)}: the arm does not reach")
    assert np.isfinite(float(m.group(2)))


def test_rapid_module_structure(robot: RobotModel, two_pass_plan: WeldPlan, tmp_path: Path) -> None:
    from cell.export.post import write_program
    from cell.export.program import ProgramJob

    (path,) = write_program("rapid", ProgramJob(two_pass_plan, robot, "passes"), tmp_path)
    assert path.name == "PASSES.mod"
    lines = [ln.strip() for ln in path.read_text().splitlines()]
    opens = [ln.split()[0] for ln in lines if re.match(r"(MODULE|PROC) ", ln)]
    closes = [ln for ln in lines if ln in ("ENDMODULE", "ENDPROC")]
    assert opens == ["MODULE", "PROC"] and closes == ["ENDPROC", "ENDMODULE"]
    assert lines.index("ENDPROC") < lines.index("ENDMODULE")
    declared = {m.group(2): m.group(1) for ln in lines if (m := re.match(r"(?:CONST|PERS) (\w+) (\w+) :=", ln))}
    moves = [re.match(r"(\w+) (\w+), (\w+)", ln) for ln in lines if re.match(r"(MoveJ|MoveL|MoveAbsJ|Arc\w+) ", ln)]
    for m in moves:
        assert m is not None and declared[m.group(2)] in ("robtarget", "jointtarget")
        assert m.group(3) in declared or m.group(3) == "v1000"  # v1000: RAPID's predefined speeddata
    arc = [m.group(1) for m in moves if m is not None and m.group(1).startswith("Arc")]
    assert arc == ["ArcLStart", "ArcL", "ArcLEnd"]  # the second procedure switches the data mid-seam
    for ln in lines:
        if ln.startswith("Arc"):
            sm, wd = re.search(r", (sm\d+), (wd\d+) \\Weave:=(wv\d+)", ln).group(1, 2)  # type: ignore[union-attr]
            assert declared[sm] == "seamdata" and declared[wd] == "welddata"
    targets = [ln for ln in lines if ln.startswith("CONST robtarget")]
    assert all(re.search(r"\],\[-?\d+,-?\d+,-?\d+,[0-7]\],\[9E9", ln) for ln in targets)  # confdata on each
    assert "wd2 := [8.00,0,[0,0,21.50,7.00,0,170.0,0,0,0]" in path.read_text()


def test_inline_form_data_must_be_declared_and_the_command_line(
    robot: RobotModel, two_pass_plan: WeldPlan, tmp_path: Path
) -> None:
    from typer.testing import CliRunner

    from cell.cli import app
    from cell.cli.krl import EXIT_CHECK_FAILED

    _, dat_path = write_krl(two_pass_plan, robot, tmp_path, "forms")
    name = re.search(r"^DECL FDAT (\w+)=", dat_path.read_text(), flags=re.M).group(1)  # type: ignore[union-attr]
    dat_path.write_text(re.sub(rf"^DECL FDAT {name}=.*\n", "", dat_path.read_text(), flags=re.M))
    assert _check(tmp_path, robot) == [("undeclared", f"{name} is not declared")]
    runner = CliRunner()
    result = runner.invoke(app, ["krl", "check", str(tmp_path)])
    assert result.exit_code == EXIT_CHECK_FAILED and result.stdout.strip().endswith(f"{name} is not declared")
    assert runner.invoke(app, ["krl", "check", str(tmp_path / "none")]).exit_code == 2
    (tmp_path / "empty").mkdir()
    assert runner.invoke(app, ["krl", "check", str(tmp_path / "empty")]).exit_code == 2


def test_an_arc_statement_without_its_motion(robot: RobotModel, two_pass_plan: WeldPlan, tmp_path: Path) -> None:
    src_path, _ = write_krl(two_pass_plan, robot, tmp_path, "nomove")
    text = src_path.read_text()
    i = text.index(";FOLD ARCSWI ")
    j = text.index("\nLIN ", i)
    src_path.write_text(text[:j] + text[text.index("\n", j + 1) :])  # the switch's LIN deleted
    found = _check(tmp_path, robot)
    assert ("arc", "ARC_SWI holds 0 motions, not one") in found
