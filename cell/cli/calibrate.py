"""``cell calibrate``: the cameras' poses measured with a ChArUco board (docs/calibration.md), written as a
calibration file every run command applies with ``--calibration CAL.yaml``."""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import numpy as np
import typer
import yaml

from cell.cli.common import NoiseOpt, app, cell_errors, out, parse_noise, say
from cell.cli.outputs import check_file, check_folder
from cell.errors import UsageError

if TYPE_CHECKING:
    from cell.pipeline.calibration import CalibrationRun


@app.command()
def calibrate(
    scenario: Annotated[
        str | None,
        typer.Argument(help="A scenario name (see `cell scenarios`) or a YAML path (with --capture: a bag's board)."),
    ] = None,
    out_path: Annotated[
        Path | None, typer.Option("--out", "-o", metavar="CAL.yaml", help="The calibration file to write.")
    ] = None,
    cameras: Annotated[
        str | None, typer.Option(help="The cameras to calibrate, comma-separated (default: every camera).")
    ] = None,
    poses: Annotated[
        int | None, typer.Option(min=4, max=60, help="Board images fitted per camera (default: calibration.poses).")
    ] = None,
    noise: NoiseOpt = None,
    json_path: Annotated[
        Path | None, typer.Option("--json", help="Also write the file's content as JSON here ('-': stdout).")
    ] = None,
    held_out: Annotated[
        int, typer.Option(min=0, max=20, help="With --capture: each camera's last images kept out of the fit.")
    ] = 4,
    capture_dir: Annotated[
        Path | None,
        typer.Option(
            "--capture",
            metavar="DIR",
            help="Solve from a calibration capture folder or a ROS 2 bag (its board: SCENARIO's, else the default).",
        ),
    ] = None,
    save_capture: Annotated[
        Path | None,
        typer.Option("--save-capture", metavar="DIR", help="Also write the images and flange poses taken here."),
    ] = None,
) -> None:
    """Measure the cameras' poses: the fixed cameras against the robot (the arm carries the board through poses
    chosen for good conditioning), the arm's camera against the flange (the board on the table); each with its
    covariance, held-out residuals, its intrinsics and depth scale checked. Refuses a degenerate pose set, a board
    of the wrong size or a camera that cannot see the board (exit 17, with the reason). With --capture DIR the images
    and flange poses are a capture folder's (--save-capture writes one) or a ROS 2 bag's (colour images, CameraInfo,
    depth, the flange from tf), solved without the simulator."""
    from cell import scenario as sc
    from cell.calibrate.file import document
    from cell.outputs import write_atomic
    from cell.pipeline.calibration import calibrate as run_calibration
    from cell.pipeline.calibration import calibrate_capture
    from cell.recorded.board_bag import is_bag

    with cell_errors():
        if out_path is None:
            raise UsageError("--out CAL.yaml is missing; valid: cell calibrate fence1 --out cal.yaml")
        if out_path.suffix not in (".yaml", ".yml"):
            raise UsageError(f"--out {str(out_path)!r} must end in .yaml or .yml")
        bag = capture_dir is not None and is_bag(capture_dir)
        if (scenario is None) == (capture_dir is None) and not (bag and scenario is not None):
            raise UsageError(
                "give SCENARIO or --capture DIR (one of them; with a bag, SCENARIO may state the board); "
                "valid: cell calibrate fence1 --out cal.yaml"
            )
        if capture_dir is not None and (poses is not None or noise is not None or save_capture is not None):
            raise UsageError("--poses, --noise and --save-capture simulate; a capture holds what was taken")
        check_file(out_path, "--out", stdout_ok=False)
        check_file(json_path, "--json")
        if save_capture is not None:
            check_folder(save_capture, "--save-capture")
        names = [c.strip() for c in cameras.split(",") if c.strip()] if cameras else None
        if capture_dir is not None:
            spec = sc.load(scenario).calibration if scenario is not None else None  # a bag's board
            run = calibrate_capture(capture_dir, names, held_out=held_out, progress=say, run_spec=spec)
            source = str(capture_dir)
        else:
            assert scenario is not None
            scn = sc.load(scenario)
            scn = scn.with_noise(n) if (n := parse_noise(noise)) else scn
            run = run_calibration(scn, names, poses=poses, progress=say, keep=save_capture is not None)
            source = scenario
            if save_capture is not None and run.capture is not None:
                from cell.recorded.board_capture import write_board_capture

                write_board_capture(save_capture, run.capture)
                say(f"capture: {save_capture} ({len(run.capture.shots)} images)")
        doc = document(run.cameras, scenario=source, board=run.board.model_dump())
        text = f"# cell calibrate {source}: camera poses measured (docs/calibration.md)\n"
        text += yaml.safe_dump(doc, sort_keys=False, default_flow_style=None, width=120)
        write_atomic(out_path, text.encode("utf-8"), what="calibration")
        if json_path is not None:
            data = json.dumps(doc, indent=2) + "\n"
            if str(json_path) == "-":
                typer.echo(data, nl=False)
            else:
                write_atomic(json_path, data.encode("utf-8"), what="JSON")
        _print(run)
        say(f"calibration: {out_path}; apply it with --calibration {out_path}")


def _print(run: CalibrationRun) -> None:
    from rich.table import Table

    table = Table(title="cameras calibrated", title_justify="left")
    for col in ("camera", "frame", "poses", "fit px", "held out px / mm", "1-sigma mm / deg", "truth error mm / deg"):
        table.add_column(col)
    for cal in run.cameras:
        s = cal.solution
        err = cal.truth_error()
        table.add_row(
            cal.camera,
            cal.frame,
            str(cal.poses),
            f"{s.rms_px:.2f}",
            f"{cal.held_out_px:.2f} / {cal.held_out_3d_m * 1e3:.2f}",
            f"{s.sigma_translation_m * 1e3:.3f} / {np.degrees(s.sigma_rotation_rad):.4f}",
            "-" if err is None else f"{err[0] * 1e3:.3f} / {np.degrees(err[1]):.4f}",
        )
    out.print(table)
    for cal in run.cameras:
        if cal.intrinsics.flags:
            from cell.cli.common import warn

            warn(f"{cal.camera}: its images disagree with its stated {', '.join(cal.intrinsics.flags)}")
