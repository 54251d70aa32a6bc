"""Commands that move the arm (or plan to): ``cell weld``, ``cell preview``, ``cell rescan``."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from cell.cli.common import NoiseOpt, app, cell_errors, check_method, err, parse_noise, parse_rescan_mode, progress
from cell.cli.tables import print_rescan, print_weld
from cell.errors import EXIT_PARTIAL

if TYPE_CHECKING:
    from cell.pipeline import WeldRun


@app.command()
def weld(
    scenario: Annotated[str, typer.Argument(help="A scenario name (see `cell scenarios`) or a YAML path.")],
    method: Annotated[str | None, typer.Option(help="Seam locator (default: the scenario's).")] = None,
    noise: NoiseOpt = None,
    json_path: Annotated[Path | None, typer.Option("--json", help="Write the JSON report here.")] = None,
    krl: Annotated[
        Path | None, typer.Option(help="Write the KUKA KRL program (.src/.dat) and the trajectory (JSON, CSV) here.")
    ] = None,
    rescan: Annotated[
        str | None, typer.Option(help="Re-scan before welding: none | low (below the confidence threshold) | all.")
    ] = None,
    gui: Annotated[bool, typer.Option(help="Open the PyBullet window (needs a display).")] = False,
    html: Annotated[
        Path | None, typer.Option("--html", help="Write one page to look at (results, 3D cell, joints) here.")
    ] = None,
) -> None:
    """The whole cell: capture, locate every seam, re-scan doubtful ones up close, plan, check, weld in simulation."""
    from cell import pipeline
    from cell import scenario as sc

    with cell_errors():
        scn = sc.load(scenario)
        check_method(method)
        run = pipeline.weld(
            scn, method, noise=parse_noise(noise), rescan=parse_rescan_mode(rescan), progress=progress(), gui=gui
        )
        if html is not None:
            from cell.preview import write_page

            err.print(f"[dim]· page written to {write_page(run, html)}[/]")
        _finish_run(run, json_path, krl, title="weld")


@app.command("rescan")
def rescan_cmd(
    scenario: Annotated[str, typer.Argument(help="A scenario name (see `cell scenarios`) or a YAML path.")],
    seams: Annotated[
        str | None, typer.Option(help="Comma-separated seam ids (default: the scenario's rescan.mode choice).")
    ] = None,
    all_seams: Annotated[bool, typer.Option("--all", help="Re-scan every visible seam.")] = False,
    method: Annotated[str | None, typer.Option(help="Seam locator (default: the scenario's).")] = None,
    noise: NoiseOpt = None,
    json_path: Annotated[Path | None, typer.Option("--json", help="Write the JSON report here.")] = None,
) -> None:
    """Only the close-up re-scan: detect, look again at seams with the eye-in-hand camera, compare before/after.

    The same re-scan as ``cell weld`` (its selection and its escalation when a close-up disagrees).
    """
    from cell import pipeline
    from cell import scenario as sc
    from cell.export.report import rescan_report, write_json
    from cell.station import open_station

    with cell_errors():
        scn = sc.load(scenario)
        check_method(method)
        scn = scn.with_noise(n) if (n := parse_noise(noise)) else scn
        ids = [s.strip() for s in seams.split(",") if s.strip()] if seams else None
        weldmap = pipeline.read_weldmap(scn)
        unknown = sorted(set(ids or ()) - {s.id for s in weldmap.seams})
        if unknown:
            valid = ", ".join(s.id for s in weldmap.seams)
            raise typer.BadParameter(f"no seam {', '.join(unknown)} in the map; seams: {valid}", param_hint="--seams")
        with open_station(scn, weldmap) as station:
            det = pipeline.detect(scn, method, progress=progress(), station=station, weldmap=weldmap)
            if det.error is not None:
                raise det.error
            mode: pipeline.RescanMode = "all" if all_seams else "low"
            rs, after = pipeline.rescan_detection(station, det, mode, seam_ids=ids, progress=progress())
        rep = rescan_report(det, after, rs)
        if json_path is not None:
            write_json(json_path, rep)
            err.print(f"[dim]· report written to {json_path}[/]")
        print_rescan(rep)


@app.command()
def preview(
    scenario: Annotated[str, typer.Argument(help="A scenario name (see `cell scenarios`) or a YAML path.")],
    out_dir: Annotated[Path, typer.Option("--out", help="Folder for the pictures and the report.")] = Path("preview"),
    method: Annotated[str | None, typer.Option(help="Seam locator (default: the scenario's).")] = None,
    noise: NoiseOpt = None,
) -> None:
    """Dry run: detect and plan, move nothing; pictures of cloud, map, seams, torch poses and joint plots."""
    from cell import pipeline
    from cell import scenario as sc
    from cell.preview import write_run

    with cell_errors():
        scn = sc.load(scenario)
        check_method(method)
        run = pipeline.weld(scn, method, noise=parse_noise(noise), execute_plan=False, progress=progress())
        progress()(f"drawing pictures into {out_dir}/")
        paths = write_run(run, out_dir)
        _finish_run(run, out_dir / "report.json", None, title="preview")
        for p in paths:
            err.print(f"[dim]· {p}[/]")


def _finish_run(run: WeldRun, json_path: Path | None, krl: Path | None, *, title: str) -> None:
    """Write what was asked (report first: it survives any later failure), print the table, exit with the code."""
    from cell.export.report import weld_report, write_json

    rep = weld_report(run)
    if json_path is not None:
        write_json(json_path, rep)
        err.print(f"[dim]· report written to {json_path}[/]")
    if krl is not None and run.plan is not None and run.plan.segments and run.arm is not None:
        from cell.export.krl import write_krl
        from cell.export.trajectory import write_csv
        from cell.export.trajectory import write_json as write_traj

        name = "WELD_" + "".join(ch if ch.isalnum() else "_" for ch in run.detection.scenario.name).upper()
        sc = run.detection.scenario
        src, dat = write_krl(run.plan, run.arm.model, krl, name[:24], X_WR=sc.X_WR, options=sc.export.krl)
        traj_json = write_traj(run.plan, krl / "trajectory.json")
        traj_csv = write_csv(run.plan, krl / "trajectory.csv")
        err.print(f"[dim]· robot program: {src}, {dat}; trajectory: {traj_json}, {traj_csv}[/]")
    print_weld(rep, title)
    if run.error is not None:  # the report says which seams and why: partial, with the cause in report.error
        err.print(f"[bold red]error[/]: {run.error.message}", soft_wrap=True)
        raise typer.Exit(EXIT_PARTIAL)
    if not run.complete:
        raise typer.Exit(EXIT_PARTIAL)
