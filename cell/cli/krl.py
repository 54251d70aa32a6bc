"""``cell krl check FOLDER_OR_FILE``: re-read KRL programs (a folder's, or one program and those it calls) and list
what is wrong with them, one ``FILE:LINE: code: detail`` line per finding (docs/programs.md); exit
:data:`EXIT_CHECK_FAILED` when there is any."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from cell.cli.common import CONTEXT, app, cell_errors, out, say
from cell.errors import UsageError

EXIT_CHECK_FAILED = 4  # the program check found something wrong

krl_app = typer.Typer(no_args_is_help=True, context_settings=CONTEXT, help="KUKA KRL programs (.src/.dat).")
app.add_typer(krl_app, name="krl")


@krl_app.command("check")
def check(
    target: Annotated[
        Path,
        typer.Argument(
            metavar="FOLDER_OR_FILE",
            help="A folder with NAME.src and NAME.dat (as `cell weld --program` writes), or one program's NAME.src:"
            " a main program is checked with every program it calls.",
        ),
    ],
    robot: Annotated[
        str, typer.Option(help="The arm's URDF in the repository's robots/ folder (S, T and reach are checked on it).")
    ] = "kr5_arc.urdf",
    e1_limits: Annotated[
        tuple[float, float] | None,
        typer.Option(
            metavar="MIN MAX",
            help="The linear track's E1 limits in mm: every point's E1 must lie within them (default: the limits"
            " the program states in its header, if any).",
        ),
    ] = None,
) -> None:
    """Re-read every program: names, structure, the INI fold, points declared, arc on ... off with declared weld
    data sets, S and T of every E6POS against the arm's kinematics; a main program's calls (each called program
    exists and is checked), the operator's stop between two sides, home at its start and end; TOOL_DATA and
    BASE_DATA the programs agree on; E1 of every point on a linear track. Exit 4 with one line per finding."""
    from cell.export.checks.calls import check_all, read_target

    with cell_errors():
        if target.is_file() and target.suffix.lower() not in (".src", ".dat"):
            raise UsageError(f"{str(target)!r} is not a KRL program: give NAME.src (or its folder)")
        if not target.exists():
            raise UsageError(f"{str(target)!r} does not exist: give a folder with KRL programs or a NAME.src")
        programs, findings = read_target(target)
        if not programs and not findings:
            raise UsageError(f"{str(target)!r} holds no KRL program (NAME.src with NAME.dat)")
        from cell.motion.robot import RobotModel
        from cell.station.arm import ROBOT_DIR

        urdf = ROBOT_DIR / robot
        if not urdf.is_file():
            known = ", ".join(sorted(p.name for p in ROBOT_DIR.glob("*.urdf")))
            raise UsageError(f"--robot {robot!r} is not in robots/; available: {known}")
        if e1_limits is not None and not e1_limits[0] <= 0.0 <= e1_limits[1]:
            raise UsageError(f"--e1-limits {e1_limits[0]:g} {e1_limits[1]:g}: MIN <= 0 <= MAX [mm] (0: the base at R)")
        findings += check_all(programs, RobotModel.from_urdf(urdf), e1_limits)
        for f in findings:
            out.print(str(f), soft_wrap=True, highlight=False, markup=False)
        names = ", ".join(p.name for p in programs)
        if findings:
            say(f"{len(findings)} finding(s) in {target}: {names}")
            raise typer.Exit(EXIT_CHECK_FAILED)
        say(
            f"{names}: passed (structure, INI, points, arc statements and weld data, S and T on {robot}, calls and"
            " operator stops)"
        )
