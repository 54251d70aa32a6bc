"""Commands that move the arm (or plan to): ``cell weld``, ``cell preview``, ``cell rescan``.

Each checks its output paths before any work, writes the report first (it survives any later failure), then
every other output on its own, and on Ctrl-C writes the report of the stage it reached (exit 130); ``cell weld``
keeps the job's journal and stops on SIGINT, SIGTERM or SIGHUP with a report built from it (docs/journal.md).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from cell.cli.common import (
    CalibrationOpt,
    FormatOpt,
    NoiseOpt,
    app,
    cell_errors,
    check_display,
    check_method,
    detail,
    load_scenario,
    parse_format,
    parse_noise,
    parse_rescan_mode,
    program_folder,
    say,
    was_interrupted,
)
from cell.cli.outputs import (
    Stage,
    Writer,
    check_file,
    check_folder,
    finish,
    interrupted_report,
    on_interrupt,
)
from cell.cli.printout.rescan_table import print_rescan
from cell.errors import EXIT_INTERRUPTED, EXIT_PARTIAL, EXIT_USAGE, UsageError

if TYPE_CHECKING:
    from cell.pipeline import WeldRun
    from cell.scenario import Scenario

ScenarioArg = Annotated[str, typer.Argument(help="A scenario name (see `cell scenarios`) or a YAML path.")]
MethodOpt = Annotated[str | None, typer.Option(help="Seam locator (default: the scenario's).")]
JsonOpt = Annotated[
    Path | None, typer.Option("--json", help="Write the JSON report here ('-': stdout, the table to stderr).")
]
RerunOpt = Annotated[
    Path | None,
    typer.Option(
        "--rerun",
        metavar="FILE.rrd",
        help="Write a Rerun recording (cloud, map, cameras, robot and tool path on a timeline) here; needs the"
        " optional extra: uv sync --extra rerun, or pip install 'weld-cell\\[rerun]'.",  # help is rich markup
    ),
]
SidesOpt = Annotated[
    str, typer.Option(help="first: weld what the part shows as it lies | all: then turn it over for the rest.")
]


def _load(
    scenario: str, method: str | None, noise: str | None, calibration: Path | None = None
) -> tuple[Scenario, dict[str, Any]]:
    """The scenario as given, with ``--calibration`` applied (other overrides are the pipeline's to apply), and the
    provenance of the run (which records the calibration file)."""
    from cell import scenario as sc
    from cell.provenance import provenance

    scn = load_scenario(scenario, calibration)
    check_method(method)
    n = parse_noise(noise)
    prov = provenance(scn.with_noise(n) if n else scn, scenario_file=sc.resolve(scenario))
    if calibration is not None:
        prov["calibration"] = str(calibration.resolve())
    detail(f"scenario {prov['scenario_file']} (sha256 {prov['scenario_sha256']}), map {prov['map_file']}")
    return scn, prov


@app.command()
def weld(
    scenario: ScenarioArg,
    method: MethodOpt = None,
    noise: NoiseOpt = None,
    calibration: CalibrationOpt = None,
    json_path: JsonOpt = None,
    program: Annotated[
        Path | None,
        typer.Option(
            "--program",
            metavar="DIR",
            help="Write the robot program (in --controller's language) and the trajectory (JSON, CSV) here.",
        ),
    ] = None,
    controller: Annotated[
        str, typer.Option(help="The --program's language: krl (KUKA .src/.dat) | rapid (ABB RAPID .mod).")
    ] = "krl",
    krl: Annotated[
        Path | None, typer.Option("--krl", metavar="DIR", hidden=True, help="Deprecated: --program DIR.")
    ] = None,
    rescan: Annotated[
        str | None, typer.Option(help="Re-scan before welding: none | low (below the confidence threshold) | all.")
    ] = None,
    gui: Annotated[bool, typer.Option(help="Open the PyBullet window (needs a display).")] = False,
    fmt: FormatOpt = "table",
    html: Annotated[
        Path | None, typer.Option("--html", help="Write one page to look at (results, 3D cell, joints) here.")
    ] = None,
    rerun_path: RerunOpt = None,
    sides: SidesOpt = "all",
    journal: Annotated[
        Path | None,
        typer.Option(help="Write the job's journal here (default: beside --json, else in --program's folder)."),
    ] = None,
    resume: Annotated[
        Path | None,
        typer.Option(metavar="JOURNAL", help="Continue the job this journal (or the one in this folder) stopped."),
    ] = None,
) -> None:
    """The whole cell: capture, locate every seam, re-scan doubtful ones up close, plan, check, weld in simulation;
    then turn the part over for the seams against the table and weld its other side (``--sides all``). Every step
    goes to the job's journal as it happens; ``--resume`` welds what an interrupted job left (docs/journal.md)."""
    from cell import pipeline
    from cell.cli.journal import end_job, joined, journal_path, open_job, resumed, stopped
    from cell.cli.positioner import weld_positioned
    from cell.cli.turnover import check_rerun, finish_turnover, parse_sides, write_page, write_rerun
    from cell.journal import SideLog, stop_on_signals
    from cell.journal.signals import received
    from cell.pipeline.job import WeldJob
    from cell.pipeline.turnover import weld_part
    from cell.pipeline.turnover_run import TurnoverRun

    with cell_errors():
        table = parse_format(fmt)
        mode = parse_rescan_mode(rescan)
        check_display(gui)
        check_file(json_path, "--json")
        program = program_folder(program, krl)
        check_folder(program, "--program")
        if controller not in ("krl", "rapid"):
            raise UsageError(f"--controller {controller!r} is unknown; valid: krl, rapid")
        check_file(html, "--html", stdout_ok=False)
        check_rerun(rerun_path)
        side_opt = parse_sides(sides)
        scn, prov = _load(scenario, method, noise, calibration)
        if scn.robot.positioner is not None:  # the positioner, not an operator, turns the part (docs/positioner.md)
            unused = {"--rerun": rerun_path, "--journal": journal, "--resume": resume}
            asked = WeldJob(method, noise=parse_noise(noise), rescan=mode, gui=gui, sides=side_opt)
            return weld_positioned(scn, prov, asked, (json_path, program, controller), table, unused, html)
        state = resumed(resume, prov) if resume is not None else None
        if state is not None:  # the job's own options, unless given again
            was = state.start.get("options", {})
            method, noise = method or was.get("method"), noise or was.get("noise")
            mode, side_opt = mode or was.get("rescan"), parse_sides(was.get("sides") or sides)
        opts = {"scenario": scn.name, "method": method, "noise": noise, "rescan": mode, "sides": side_opt,
                "controller": controller, "json": json_path, "program": program,
                "calibration": calibration}  # fmt: skip
        stage, writer = Stage(), Writer()
        log = open_job(
            journal_path(journal, json_path, program), state, prov, {k: v and str(v) for k, v in opts.items()}
        )
        writer.journal = log.writer if log is not None else None
        done, turned = (tuple(state.welds), state.turn) if state is not None else ((), None)
        with stop_on_signals():
            try:
                asked = WeldJob(method, noise=parse_noise(noise), rescan=mode, gui=gui, sides=side_opt)
                side_log = SideLog(writer.journal)
                if side_opt == "first":  # side A alone, as the part lies
                    run = pipeline.weld(scn, asked, progress=stage, log=side_log, done=done)
                    job = TurnoverRun(run)
                else:
                    job = weld_part(scn, asked, progress=stage, log=side_log, done=done, turned=turned)
                    run = job.side_a  # the page and the recording show side A
                amend = joined(log, on_b=turned is not None)
                partial = finish_turnover(job, json_path, program, title="weld", provenance=prov, writer=writer,
                                          fmt=table, controller=controller, amend=amend)  # fmt: skip
                if html is not None and writer.attempt(lambda: write_page(run, html)) is not None:
                    say(f"page: {html}")
                write_rerun(run, rerun_path, writer)
                errs = [e for e in (job.side_a.error, job.side_b and job.side_b.error, job.error) if e is not None]
                code = EXIT_USAGE if writer.failures else EXIT_PARTIAL if partial else 0
                end_job(log, "failed" if errs else "partial" if partial else "complete", code, partial or "")
            except (KeyboardInterrupt, Exception) as e:  # a signal, a bug: the report from the journal, then exit
                signal_in_import = isinstance(e, ImportError) and (was_interrupted(e) or received() is not None)
                stop = KeyboardInterrupt() if signal_in_import else e
                code = stopped(log, stop, stage.last, interrupted_report(scn, method, stage.last, prov), writer,
                               json_path)  # fmt: skip
                if not isinstance(stop, KeyboardInterrupt):
                    raise
                raise typer.Exit(code) from None
    finish(writer, partial)


@app.command("rescan")
def rescan_cmd(
    scenario: ScenarioArg,
    seams: Annotated[
        str | None, typer.Option(help="Comma-separated seam ids, curved ones too (default: rescan.mode's choice).")
    ] = None,
    all_seams: Annotated[bool, typer.Option("--all", help="Re-scan every visible seam and located curve.")] = False,
    method: MethodOpt = None,
    noise: NoiseOpt = None,
    calibration: CalibrationOpt = None,
    json_path: JsonOpt = None,
) -> None:
    """Only the close-up re-scan: detect, look again at seams with the eye-in-hand camera, compare before/after.

    The same re-scan as ``cell weld`` (its selection and its escalation when a close-up disagrees), curves too.
    """
    from cell import pipeline
    from cell.export.reports.report import detection_report, rescan_report
    from cell.pipeline.curved.rescan_all import rescan_all
    from cell.pipeline.geometry import open_cell

    with cell_errors():
        check_file(json_path, "--json")
        scn, prov = _load(scenario, method, noise, calibration)
        scn = scn.with_noise(n) if (n := parse_noise(noise)) else scn
        ids = [s.strip() for s in seams.split(",") if s.strip()] if seams else None
        weldmap = pipeline.read_weldmap(scn)
        valid = [s.id for s in weldmap.seams] + [c.id for c in weldmap.curved]
        if unknown := sorted(set(ids or ()) - set(valid)):  # before any capture
            raise UsageError(f"--seams: no seam {', '.join(unknown)} in the map; seams: {', '.join(valid)}")
        stage, writer = Stage(), Writer()
        det: pipeline.Detection | None = None
        try:
            with open_cell(scn, weldmap) as station:
                det = pipeline.detect(scn, method, progress=stage, station=station, weldmap=weldmap)
                if det.error is not None:
                    writer.report(json_path, detection_report(det, provenance=prov))
                    raise det.error
                rmode: pipeline.RescanMode = "all" if all_seams else "low"
                rs, after = rescan_all(station, det, rmode, seam_ids=ids, progress=stage)
            rep = rescan_report(det, after, rs, provenance=prov)
            writer.report(json_path, rep)
            print_rescan(rep)
        except (KeyboardInterrupt, ImportError) as e:
            if not was_interrupted(e):
                raise
            done = detection_report(det, provenance=prov) if det is not None else None
            on_interrupt(writer, json_path, done or interrupted_report(scn, method, stage.last, prov), stage.last)
            raise typer.Exit(EXIT_INTERRUPTED) from None
    finish(writer, None)


@app.command()
def preview(
    scenario: ScenarioArg,
    out_dir: Annotated[Path, typer.Option("--out", help="Folder for the pictures and the report.")] = Path("preview"),
    method: MethodOpt = None,
    noise: NoiseOpt = None,
    calibration: CalibrationOpt = None,
    fmt: FormatOpt = "table",
    rerun_path: RerunOpt = None,
    sides: SidesOpt = "all",
) -> None:
    """Dry run: detect and plan, move nothing; pictures of cloud, map, seams, torch poses and joint plots, and of
    the planned turn with side B's seams at their nominal turned place (``--sides all``)."""
    from cell import pipeline
    from cell.cli.positioner import weld_positioned
    from cell.cli.turnover import check_rerun, finish_turnover, interrupted, parse_sides, write_rerun
    from cell.pipeline.job import WeldJob
    from cell.pipeline.turnover import weld_part
    from cell.pipeline.turnover_run import TurnoverRun
    from cell.preview import write_run
    from cell.preview.turnover import write_turnover

    with cell_errors():
        table = parse_format(fmt)
        check_folder(out_dir, "--out")
        check_rerun(rerun_path)
        side_opt = parse_sides(sides)
        scn, prov = _load(scenario, method, noise, calibration)
        json_path = out_dir / "report.json"
        if scn.robot.positioner is not None:  # the poses chosen and the report, nothing moves
            asked = WeldJob(method, noise=parse_noise(noise), execute=False, sides=side_opt)
            page = out_dir / "cell.html"  # the page as a fixed arm's preview writes it (no robot: docs/positioner.md)
            return weld_positioned(scn, prov, asked, (json_path, None, "krl"), table, {"--rerun": rerun_path}, page)
        stage, writer = Stage(), Writer()
        run: WeldRun | None = None
        try:
            asked = WeldJob(method, noise=parse_noise(noise), execute=False, sides=side_opt)
            if side_opt == "first":
                run = pipeline.weld(scn, asked, progress=stage)
                job = TurnoverRun(run)
            else:
                job = weld_part(scn, asked, progress=stage)
                run = job.side_a
            partial = finish_turnover(job, json_path, None, title="preview", provenance=prov, writer=writer, fmt=table)
            write_rerun(run, rerun_path, writer)  # before the pictures: it needs no cloud, they do
            stage(f"drawing pictures into {out_dir}/")
            done = run
            paths = writer.attempt(lambda: write_run(done, out_dir)) or []
            paths += writer.attempt(lambda: write_turnover(job, out_dir)) or []
            for p in paths:
                say(str(p))
        except (KeyboardInterrupt, ImportError) as e:
            if not was_interrupted(e):
                raise
            interrupted(run, scn, method, stage, prov, writer, json_path)
    finish(writer, partial)
