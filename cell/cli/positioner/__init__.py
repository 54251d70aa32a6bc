"""``cell positioner weld SCENARIO``: a part on a tilt-rotate positioner welded with no operator turn
(docs/positioner.md): the report (each seam's pose and ISO 6947 position) and the programs, one per pose."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Annotated

import numpy as np
import typer

from cell.cli.common import CONTEXT, app, cell_errors, load_scenario, progress, say
from cell.scenario import Scenario
from cell.types import Kinematics

positioner_app = typer.Typer(no_args_is_help=True, context_settings=CONTEXT, help="A tilt-rotate positioner.")
app.add_typer(positioner_app, name="positioner")


@positioner_app.command("weld")
def weld(
    scenario: Annotated[str, typer.Argument(help="A scenario with robot.positioner (name in scenarios/ or a file).")],
    out_dir: Annotated[Path, typer.Option("--out", help="Folder for report.json and the programs.")] = Path(
        "out-positioner"
    ),
    controller: Annotated[str, typer.Option(help="The programs' language: krl or rapid.")] = "krl",
    execute: Annotated[bool, typer.Option(help="Weld (default), or --no-execute: choose the poses only.")] = True,
) -> None:
    """Scan the part at the positioner's home, choose the poses that put every located seam in PA/PB (ISO 6947),
    weld each pose's seams with the part turned there, write report.json and a program per pose."""
    from cell.export.positioner_program import write_positioner_programs
    from cell.export.positioner_report import positioner_report
    from cell.export.program import ProgramJob
    from cell.outputs import make_folder, write_atomic
    from cell.pipeline.job import WeldJob
    from cell.pipeline.positioned import weld_on_positioner
    from cell.types.positioner import external_axes

    with cell_errors():
        sc = load_scenario(scenario)
        run = weld_on_positioner(sc, WeldJob(execute=execute), progress=progress())
        make_folder(out_dir)
        report = positioner_report(run)
        write_atomic(out_dir / "report.json", (json.dumps(report, indent=1) + "\n").encode())
        assert sc.robot.positioner is not None
        pos = sc.robot.positioner.positioner(sc.X_WR)
        robot = _robot(sc)
        jobs = []
        for k, g in enumerate(run.groups):
            if g.plan is None or not g.plan.segments or g.execution is None:
                continue
            X_RB = pos.X_R_F(g.pose.tilt, g.pose.rotate)
            ext = external_axes(pos, g.pose.tilt, g.pose.rotate)
            jobs.append(ProgramJob(g.plan, robot, f"{sc.name.replace('-', '_')}_p{k + 1}"[:24], X_RB=X_RB,
                                   X_WR=np.asarray(sc.X_WR), external=ext))  # fmt: skip
        if jobs:
            write_positioner_programs(controller, jobs, f"{sc.name.replace('-', '_')}"[:24], out_dir)
        t = report["totals"]
        say(
            f"{t['welded']}/{t['seams']} seams welded on {len(run.groups)} positioner poses, no operator turn; "
            f"cycle {t['cycle_time_s']:.1f} s (positioner {t['positioner_s']:.1f} s); TCP max "
            f"{t['tcp_max_mm'] if t['tcp_max_mm'] is not None else math.nan} mm -> {out_dir}"
        )


def _robot(sc: Scenario) -> Kinematics:
    """The arm's kinematics for the programs."""
    from cell.motion.robot import RobotModel
    from cell.station.arm import robot_urdf

    return RobotModel.from_urdf(robot_urdf(sc))
