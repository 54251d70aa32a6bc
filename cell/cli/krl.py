"""``cell krl check DIR``: re-read the KRL programs in a folder and list what is wrong with them.

Exit codes: 0 when every program passes; :data:`EXIT_CHECK_FAILED` (4) with one line per finding
(``FILE:LINE: code: detail``, on stdout) when not; 2 when DIR holds no program (or is no folder).
"""

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
    directory: Annotated[
        Path, typer.Argument(help="A folder with NAME.src and NAME.dat (as `cell weld --krl` writes).")
    ],
    robot: Annotated[
        str, typer.Option(help="The arm's URDF in the repository's robots/ folder (S, T and reach are checked on it).")
    ] = "kr5_arc.urdf",
) -> None:
    """Re-read every program of DIR: names, structure, the INI fold, points declared, arc on ... off with declared
    weld data sets, S and T of every E6POS against the arm's kinematics. Exit 4 with one line per finding."""
    from cell.export.krl_check import check_program, read_programs
    from cell.export.krl_kin import check_kinematics

    with cell_errors():
        if not directory.is_dir():
            raise UsageError(f"{str(directory)!r} is not a folder with KRL programs")
        programs, findings = read_programs(directory)
        if not programs and not findings:
            raise UsageError(f"{str(directory)!r} holds no KRL program (NAME.src with NAME.dat)")
        from cell.motion.robot import RobotModel
        from cell.station.arm import ROBOT_DIR

        urdf = ROBOT_DIR / robot
        if not urdf.is_file():
            known = ", ".join(sorted(p.name for p in ROBOT_DIR.glob("*.urdf")))
            raise UsageError(f"--robot {robot!r} is not in robots/; available: {known}")
        model = RobotModel.from_urdf(urdf)
        for p in programs:
            findings += check_program(p)
            findings += check_kinematics(p, model)
        for f in findings:
            out.print(str(f), soft_wrap=True, highlight=False, markup=False)
        names = ", ".join(p.name for p in programs)
        if findings:
            say(f"{len(findings)} finding(s) in {directory}: {names}")
            raise typer.Exit(EXIT_CHECK_FAILED)
        say(f"{names}: passed (structure, INI, points, arc statements and weld data, S and T on {robot})")
