"""The two-sided robot program: each side's own program and a main program that runs them in order with
the operator's stop to turn the part between them (KRL and RAPID), its errors, and ``cell krl check`` on a main
program (its calls, the stop, home, the sides' bases). One small plan of the tiny cell serves both sides: side B is
the same motion with the part's base elsewhere."""

from __future__ import annotations

import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from test_krl import HOME, OBSTACLES, PROCESS, SEAMS, URDF
from typer.testing import CliRunner

from cell.cli import app
from cell.export.checks.calls import check_all, read_target
from cell.export.krl import KrlPost
from cell.export.post import write_program
from cell.export.program import ProgramJob
from cell.export.rapid import RapidPost
from cell.export.turnover_program import turnover_program, write_turnover_program
from cell.geometry import make_pose, rot_x
from cell.motion.robot import RobotModel
from cell.planning.plan import plan_welds
from cell.types.plan import WeldPlan

MESSAGE = "Turn the part over about its x axis, set it against the stops, then confirm"
X_RB_B = make_pose(rot_x(np.pi), [0.0, 0.0, 0.12])  # side B: the part turned about x (a base only, same motion)


@pytest.fixture(scope="module")
def robot() -> RobotModel:
    return RobotModel.from_urdf(URDF)


@pytest.fixture(scope="module")
def plan(robot: RobotModel) -> WeldPlan:
    return plan_welds(robot, SEAMS[:1], HOME, PROCESS, OBSTACLES)


@pytest.fixture(scope="module")
def sides(robot: RobotModel, plan: WeldPlan) -> list[ProgramJob]:
    return [ProgramJob(plan, robot, "weld_t_a"), ProgramJob(plan, robot, "WELD_T_B", X_RB=X_RB_B)]


def _lines(text: str) -> list[str]:
    return [ln.strip() for ln in text.splitlines()]


def _index(lines: list[str], pattern: str, start: int = 0) -> int:
    return next(i for i in range(start, len(lines)) if re.search(pattern, lines[i]))


def _check(target: Path, robot: RobotModel) -> list[tuple[str, str]]:
    programs, found = read_target(target)
    return [(f.code, f.message) for f in found + check_all(programs, robot)]


def test_krl_main_runs_side_a_stops_for_the_operator_then_runs_side_b(sides: list[ProgramJob]) -> None:
    texts = turnover_program("krl", sides, main_name="weld_t", turnover_message=MESSAGE)
    assert list(texts) == [f"{n}.{e}" for n in ("WELD_T", "WELD_T_A", "WELD_T_B") for e in ("src", "dat")]
    src, dat = _lines(texts["WELD_T.src"]), texts["WELD_T.dat"]
    assert src[2] == "DEF WELD_T( )" and dat.startswith("DEFDAT WELD_T PUBLIC")
    home = _index(src, r"^PTP XHOME\b")
    a = _index(src, r"^WELD_T_A\( \)$")
    msg = _index(src, r"^FLIP_HANDLE = Set_KrlMsg\(#QUIT, FLIP_MSG, FLIP_PAR\[ \], FLIP_OPT\)$", a)
    wait = _index(src, r"^WHILE Exists_KrlMsg\(FLIP_HANDLE\)$", msg)
    b = _index(src, r"^WELD_T_B\( \)$", wait)
    back = _index(src, r"^PTP XHOME\b", b)
    assert _index(src, r"^BAS\(#INITMOV, 0\)$") < home < a < msg < wait < b < back and src[back + 1] == "END"
    assert _index(src, r"^BAS\(#TOOL, 1\) ;") < home  # the torch's load for the moves home
    assert [ln for ln in src if re.fullmatch(r"\w+\( \)", ln)] == ["WELD_T_A( )", "WELD_T_B( )"]
    assert f'Msg_Txt[] "{MESSAGE}"' in dat and "VL_Stop TRUE" in dat and "Clear_P_Reset TRUE" in dat
    # side A is the post's own program; side B has its own base index, since its base (the turned part) differs
    assert {k: v for k, v in texts.items() if k.startswith("WELD_T_A")} == KrlPost().texts(sides[0])
    assert "BAS(#BASE, 1)" in texts["WELD_T_A.src"] and "BAS(#BASE, 2)" in texts["WELD_T_B.src"]
    assert re.search(r";- BASE_DATA\[2\] = \{X 0.000, Y 0.000, Z 120.000, A 0.000, B 0.000, C 180.000\}",
                     texts["WELD_T_B.src"])  # fmt: skip


def test_krl_halt_stop_and_one_side_only(sides: list[ProgramJob]) -> None:
    texts = turnover_program("krl", sides, main_name="WELD_T", turnover_message="Turn the part", stop="halt")
    src = _lines(texts["WELD_T.src"])
    a, b = _index(src, r"^WELD_T_A\( \)$"), _index(src, r"^WELD_T_B\( \)$")
    assert [ln for ln in src[a:b] if ln.startswith("HALT")] == ["HALT ; Turn the part"]
    assert "Set_KrlMsg" not in texts["WELD_T.src"] and "FLIP_MSG" not in texts["WELD_T.dat"]
    assert turnover_program("krl", sides[:1], main_name="WELD_T", turnover_message=MESSAGE) == KrlPost().texts(sides[0])


def test_rapid_main_module_calls_both_sides_and_waits_for_the_operator(sides: list[ProgramJob]) -> None:
    texts = turnover_program("rapid", sides, main_name="WELD_T", turnover_message=MESSAGE)
    assert list(texts) == ["WELD_T.mod", "WELD_T_A.mod", "WELD_T_B.mod"]
    main = _lines(texts["WELD_T.mod"])
    a, b = _index(main, r"^WELD_T_A_RUN;$"), _index(main, r"^WELD_T_B_RUN;$")
    ask = _index(main, rf'^TPReadFK nKey, "{MESSAGE}", "Turned", stEmpty, stEmpty, stEmpty, "Abort";$')
    assert _index(main, r"^PROC main\(\)$") < _index(main, r"^MoveAbsJ jHome") < a < ask < b
    assert main[ask + 1 : ask + 5][1:] == ['TPWrite "Aborted by the operator: WELD_T_B not welded";', "EXIT;",
                                            "ENDIF"]  # fmt: skip
    assert main[b + 1].startswith("MoveAbsJ jHome") and main[b + 2] == "ENDPROC"
    assert all(len(t) <= 80 for t in re.findall(r'"([^"]*)"', texts["WELD_T.mod"]))  # TPWrite's and TPReadFK's limit
    for name, job in zip(("WELD_T_A", "WELD_T_B"), sides, strict=True):
        side = texts[f"{name}.mod"]
        assert "PROC main()" not in side and f"  PROC {name}_RUN()" in side
        declared = [ln for ln in side.splitlines() if re.match(r"^  (LOCAL )?(PERS|CONST|VAR) ", ln)]
        assert declared and all(ln.startswith("  LOCAL ") for ln in declared)
        # nothing else changed from the post's own module
        own = side.replace("  LOCAL ", "  ").replace(f"PROC {name}_RUN()", "PROC main()")
        assert own == RapidPost().texts(job)[f"{name}.mod"]
    halt = _lines(
        turnover_program("rapid", sides, main_name="WELD_T", turnover_message="Turn", stop="halt")["WELD_T.mod"]
    )
    s = _index(halt, r'^TPWrite "Turn";$')
    assert halt[s + 1] == "Stop;" and "TPReadFK" not in " ".join(halt)


@pytest.mark.parametrize(
    ("controller", "main", "names", "message", "needle"),
    [
        ("krl", "1WELD", ("A", "B"), MESSAGE, "main program name '1WELD' is invalid"),
        ("krl", "W" * 25, ("A", "B"), MESSAGE, "is invalid: 1-24 characters"),
        ("krl", "weld_t_a", ("WELD_T_A", "B"), MESSAGE, "side program WELD_T_A has the main program's name"),
        ("rapid", "WELD_T", ("A", "a"), MESSAGE, "two sides are both called A"),
        ("krl", "WELD_T", ("A", "B"), "x" * 81, "at most 80 printable ASCII"),
        ("krl", "WELD_T", ("A", "B"), 'say "turned"', "without a double quote or backslash"),
        ("rapid", "WELD_T", ("A", "B"), "C:\\part", "without a double quote or backslash"),
        ("krl", "WELD_T", ("A", "B"), "  ", "the turnover message is empty"),
        ("fanuc", "WELD_T", ("A", "B"), MESSAGE, "controller 'fanuc' is unknown; valid: krl, rapid"),
    ],
)
def test_bad_names_and_messages_are_one_line_value_errors(
    sides: list[ProgramJob], controller: str, main: str, names: tuple[str, str], message: str, needle: str
) -> None:
    jobs = [replace(j, name=n.upper()) for j, n in zip(sides, names, strict=True)]
    with pytest.raises(ValueError, match=re.escape(needle)) as e:
        turnover_program(controller, jobs, main_name=main, turnover_message=message)
    assert "\n" not in str(e.value)


def test_sides_that_plan_different_homes_or_no_side_are_refused(sides: list[ProgramJob]) -> None:
    other = replace(sides[1].plan, q_home=sides[1].plan.q_home + np.radians([0, 0, 0, 0, 0, 1.0]))
    with pytest.raises(ValueError, match=r"WELD_T_B's home differs from WELD_T_A's by 1.00 deg"):
        turnover_program("krl", [sides[0], replace(sides[1], plan=other)], main_name="W", turnover_message=MESSAGE)
    with pytest.raises(ValueError, match="at least one job"):
        turnover_program("krl", [], main_name="W", turnover_message=MESSAGE)


def test_checker_passes_the_written_folder_and_the_main_file(
    sides: list[ProgramJob], robot: RobotModel, tmp_path: Path
) -> None:
    paths = write_turnover_program("krl", sides, "weld_t", MESSAGE, tmp_path)
    assert [p.name for p in paths][:2] == ["WELD_T.src", "WELD_T.dat"]
    assert b"\r\n" in paths[0].read_bytes()
    assert _check(tmp_path, robot) == []
    programs, _ = read_target(tmp_path / "WELD_T.src")
    assert [p.name for p in programs] == ["WELD_T", "WELD_T_A", "WELD_T_B"]  # the file and what it calls
    assert not any(p.src.problems or p.dat.problems for p in programs)
    assert _check(tmp_path / "WELD_T.src", robot) == []
    halt = tmp_path / "halt"
    write_turnover_program("krl", sides, "WELD_T", MESSAGE, halt, stop="halt")
    assert _check(halt, robot) == []


def _edit(path: Path, old: str, new: str) -> None:
    text = path.read_text()
    assert old in text
    path.write_text(text.replace(old, new))


def test_checker_finds_a_missing_side_an_unknown_call_a_missing_stop_and_a_shared_base(
    sides: list[ProgramJob], robot: RobotModel, tmp_path: Path
) -> None:
    write_turnover_program("krl", sides, "WELD_T", MESSAGE, tmp_path)
    main = tmp_path / "WELD_T.src"
    (tmp_path / "WELD_T_B.src").unlink()
    (tmp_path / "WELD_T_B.dat").unlink()
    found = _check(main, robot)
    assert found == [("call", "WELD_T_B( ) is neither a program in the folder nor a KSS routine this checker knows")]
    write_turnover_program("krl", sides, "WELD_T", MESSAGE, tmp_path)
    text = main.read_text()
    start, end = text.index(";FOLD OPERATOR STOP"), text.index(";ENDFOLD", text.index("ENDWHILE"))
    main.write_text(text[:start] + "CLEAN_TORCH( )" + text[end + len(";ENDFOLD") :])
    found = _check(tmp_path, robot)
    assert ("operator_stop", "WELD_T_B runs after WELD_T_A with no operator stop between them (HALT, a message or"
            " dialog waited for, or WAIT FOR an input)") in found  # fmt: skip
    assert ("call", "CLEAN_TORCH( ) is neither a program in the folder nor a KSS routine this checker knows") in found
    assert len(found) == 2
    # a stop only inside the error branch is no stop; without the last PTP XHOME, side B still ends at home
    _edit(main, "CLEAN_TORCH( )", "IF $IN[5] THEN\nHALT\nENDIF")
    _edit(main, "PTP XHOME ; back home", "")
    assert [c for c, _ in _check(main, robot)] == ["operator_stop"]
    # the message shown must be declared, with a text that fits Msg_Txt[] (CHAR[80])
    write_turnover_program("krl", sides, "WELD_T", MESSAGE, tmp_path)
    dat = tmp_path / "WELD_T.dat"
    _edit(dat, f'"{MESSAGE}"', f'"{MESSAGE}{"!" * (81 - len(MESSAGE))}"')
    assert _check(main, robot) == [("operator_stop", "FLIP_MSG's text has 81 characters, over the 80 of Msg_Txt[]")]
    _edit(dat, "DECL KrlMsg_T FLIP_MSG=", "DECL KrlMsg_T OTHER_MSG=")
    assert _check(main, robot) == [("operator_stop", "the message FLIP_MSG is not declared (KrlMsg_T)")]
    # two sides on one base index with different poses: the controller holds one BASE_DATA[1]
    shared = tmp_path / "shared"
    for job in sides:
        write_program("krl", job, shared)
    found = _check(shared, robot)
    assert found == [("setup", "BASE_DATA[1] differs from WELD_T_A's: the controller holds one value per index (give"
                      " each base of the part its own index)")]  # fmt: skip


def test_cli_checks_a_main_file_and_its_sides(sides: list[ProgramJob], tmp_path: Path) -> None:
    write_turnover_program("krl", sides, "WELD_T", MESSAGE, tmp_path)
    runner = CliRunner()
    ok = runner.invoke(app, ["krl", "check", str(tmp_path / "WELD_T.src")])
    assert ok.exit_code == 0 and "WELD_T, WELD_T_A, WELD_T_B: passed" in ok.stderr
    ok = runner.invoke(app, ["krl", "check", str(tmp_path / "WELD_T.dat")])  # its .dat does too
    assert ok.exit_code == 0 and "WELD_T, WELD_T_A, WELD_T_B: passed" in ok.stderr, ok.stdout + ok.stderr
    _edit(tmp_path / "WELD_T.src", "WELD_T_B( )", "WELD_T_C( )")
    bad = runner.invoke(app, ["krl", "check", str(tmp_path / "WELD_T.src")])
    assert bad.exit_code == 4 and "WELD_T.src:" in bad.stdout and ": call: WELD_T_C( ) is neither" in bad.stdout
    (tmp_path / "notes.txt").write_text("not a program")
    for path in ("notes.txt", "MISSING.src"):
        wrong = runner.invoke(app, ["krl", "check", str(tmp_path / path)])
        assert wrong.exit_code == 2 and "Traceback" not in wrong.stderr, wrong.stderr
