"""``cell weld`` / ``cell preview`` of a whole part (docs/flip.md): the two-sided report, its table and
the robot programs of both sides with the main program that stops for the operator's turn; the run's page and
recording, and what Ctrl-C writes."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from cell.cli.common import TableFormat, fail_line, say
from cell.cli.outputs import Stage, Writer, check_file, interrupted_report, on_interrupt
from cell.cli.printout.explain import weld_exit
from cell.cli.printout.tables import print_weld
from cell.errors import EXIT_INTERRUPTED, UsageError
from cell.pipeline.job import Sides

if TYPE_CHECKING:
    from cell.pipeline import WeldRun
    from cell.pipeline.turnover_run import TurnoverRun
    from cell.scenario import Scenario
    from cell.types.turnover import TurnoverPlan


def parse_sides(sides: str) -> Sides:
    """``--sides``: ``first`` (side A only, the part as it lies) or ``all`` (turn the part for the rest)."""
    if sides == "first":
        return "first"
    if sides == "all":
        return "all"
    raise UsageError(f"--sides {sides!r} is unknown; valid: first, all")


def turnover_message(plan: TurnoverPlan) -> str:
    """The operator's message between the sides (at most 80 characters)."""
    return f"Turn the part {math.degrees(plan.angle_rad):+.0f} deg about its {plan.axis} axis, then confirm"


def finish_turnover(
    run: TurnoverRun,
    json_path: Path | None,
    krl: Path | None,
    *,
    title: str,
    provenance: Mapping[str, Any],
    writer: Writer,
    fmt: TableFormat,
    controller: str = "krl",
    amend: Callable[[dict[str, Any]], dict[str, Any]] | None = None,
) -> str | None:
    """Write the report first, then the programs; print the table and one line per side; the exit's explanation
    when the job is partial (None when complete). amend : the report joined with the job's journal (a resume:
    the seams earlier runs welded)."""
    from cell.export.reports.curve_report import write_manual_welds
    from cell.export.reports.turnover_report import turnover_report
    from cell.preview.welder_sheet import write_welder_sheet

    rep = turnover_report(run, provenance=provenance)
    rep = amend(rep) if amend is not None else rep
    writer.report(json_path, rep)
    sides = [wr for wr in (run.side_a, run.side_b) if wr is not None]
    if krl is not None and not any(wr.plan is not None and wr.plan.segments for wr in sides):
        say(f"no robot program written to {krl}: this run has nothing to weld")  # a resume with nothing left
    elif krl is not None:
        left = not_welded(rep)
        written = writer.attempt(
            lambda: [*write_programs(run, krl, provenance, controller, left), *write_manual_welds(rep, krl)]
        )
        sheet = writer.attempt(lambda: write_welder_sheet([wr.detection for wr in sides], rep, krl))
        written = [*(written or []), *(sheet or [])]
        if written:
            say(f"robot programs: {', '.join(map(str, written))}")
            writer.written("programs", written)
    print_weld(rep, title, fmt)
    if fmt == "table":
        say(sides_line(rep))
    for err in (run.side_a.error, run.side_b.error if run.side_b is not None else None, run.error):
        if err is not None:
            fail_line(f"error: {err.message}")
    return None if run.complete else weld_exit(rep)


def sides_line(rep: Mapping[str, Any]) -> str:
    """One line: what each side welded, the turn and what the second alignment measured, the job's time."""
    parts = [f"side {k}: welded {v['welded']} in {v['cycle_time_s'] or 0:.1f} s" for k, v in rep["sides"].items()]
    f = rep.get("flip")
    if f is not None and f["made"] and f.get("placement_error_mm") is None:  # a resume: an earlier run turned it
        parts.append(f"turned {f['rotation_deg']:+.0f} deg about {f['axis']} by run {f.get('run')}")
    elif f is not None and f["made"]:
        parts.append(
            f"turned {f['rotation_deg']:+.0f} deg about {f['axis']} (lean {f['tilt_deg']:.1f} deg), placement "
            f"measured {f['placement_error_mm']:.1f} mm / {f['placement_rotation_deg']:+.2f} deg, fitness "
            f"{f['fitness']:.3f}"
        )
    elif f is not None:
        parts.append(f"no turn: {f['reason']}")
    if f is not None and f["made"] and rep.get("job_time_s") is not None:
        parts.append(f"job {rep['job_time_s']:.1f} s with the operator's turn")
        if f.get("positioner_saves_s") is not None:
            parts.append(
                f"a positioner would turn it in {f['positioner_turn_s']:.1f} s: {f['positioner_saves_s']:.1f} s less"
            )
    return " · ".join(parts)


def not_welded(rep: Mapping[str, Any]) -> tuple[tuple[str, str], ...]:
    """The report's seams no side welded, each (id, why as codes: ``not_supported: curved``, ``end_uncertain``; a
    curve welded in part: ``partial`` with what is left for a manual weld and where along it)."""
    out = []
    for s in rep["seams"]:
        if not s.get("welded"):
            code = str(s.get("weld_reason_code") or "not welded")
            code += f": {s['plan_reason_code']}" if s.get("plan_reason_code") else ""
            if s.get("remainder"):  # a curve welded in part: what is left for a manual weld, where
                left = ", ".join(f"{r['from_mm']:.0f}-{r['to_mm']:.0f} mm ({r['code']})" for r in s["remainder"])
                code += f": {s['manual_mm']:.0f} mm left for a manual weld at {left} along it"
            out.append((s["id"], f"{code}: {s['reason_code']}" if s["status"] == "not_supported" else code))
    return tuple(out)


def write_programs(
    run: TurnoverRun,
    krl: Path,
    provenance: Mapping[str, Any],
    controller: str,
    not_welded: Sequence[tuple[str, str]] = (),
) -> list[Path]:
    """The robot programs into ``krl``, each side's weld points in its own aligned map's base; each header names
    the map's seams the job does not weld (``not_welded``: id, why).

    One side welded: its program ``WELD_<SCENARIO>`` and ``trajectory.json``/``.csv``. Two:
    one program per side (``WELD_<SCENARIO>_A``, ``_B``), the main program ``WELD_<SCENARIO>`` that runs A, stops
    for the operator's turn and runs B (:func:`cell.export.turnover_program.write_turnover_program`), and each side's
    trajectory (``trajectory_A.json`` ...)."""
    import numpy as np

    from cell.export.post import write_program
    from cell.export.program import ProgramJob
    from cell.export.trajectory import write_csv, write_json
    from cell.export.turnover_program import write_turnover_program

    sc = run.side_a.detection.scenario
    base = ("WELD_" + "".join(ch if ch.isalnum() else "_" for ch in sc.name).upper())[:22]
    runs = [(k, wr) for k, wr in (("A", run.side_a), ("B", run.side_b)) if wr is not None]
    runs = [(k, wr) for k, wr in runs if wr.plan is not None and wr.plan.segments and wr.arm is not None]
    if not runs:
        raise ValueError("no plan to write")
    jobs = []
    for side, wr in runs:
        assert wr.plan is not None and wr.arm is not None
        X_RB = wr.detection.scene.X_RM if wr.detection.scene is not None else np.eye(4)
        name = base if len(runs) == 1 else f"{base}_{side}"
        jobs.append(
            ProgramJob(wr.plan, wr.arm.model, name, X_RB, sc.X_WR, sc.export.krl, provenance, tuple(not_welded))
        )
    if len(jobs) == 1:
        written = write_program(controller, jobs[0], krl)
    else:
        assert run.plan is not None
        written = write_turnover_program(controller, jobs, base, turnover_message(run.plan), krl)
    for side, wr in runs:  # after the programs: they make the folder
        assert wr.plan is not None
        stem = "trajectory" if len(runs) == 1 else f"trajectory_{side}"
        written += [write_json(wr.plan, krl / f"{stem}.json"), write_csv(wr.plan, krl / f"{stem}.csv")]
    return list(written)


def write_page(run: WeldRun | None, path: Path) -> Path:
    """The run's page (results, 3D cell, joint plots: :func:`cell.preview.write_page`)."""
    from cell.preview import write_page as page

    if run is None:
        raise ValueError("no run to draw")
    return page(run, path)


def check_rerun(path: Path | None) -> None:
    """Before the run: ``--rerun`` needs rerun-sdk installed and a file it can write (UsageError/OutputError)."""
    if path is None:
        return
    from cell.preview.rerun import require_rerun

    require_rerun()
    check_file(path, "--rerun", stdout_ok=False)


def write_rerun(run: WeldRun, path: Path | None, writer: Writer) -> None:
    """The run's Rerun recording (:func:`cell.preview.rerun.record_run`), if asked for; its failure is the writer's."""
    if path is None:
        return
    from cell.preview.rerun import record_run

    if writer.attempt(lambda: record_run(run, path)) is not None:
        say(f"rerun recording: {path}")


def interrupted(
    run: WeldRun | None,
    scn: Scenario,
    method: str | None,
    stage: Stage,
    prov: Mapping[str, Any],
    writer: Writer,
    json_path: Path | None,
) -> None:
    """Ctrl-C: the run's report if the pipeline returned, else what ran and where it stopped; exit 130."""
    from cell.export.reports.report import weld_report

    rep = weld_report(run, provenance=prov) if run is not None else interrupted_report(scn, method, stage.last, prov)
    on_interrupt(writer, json_path, rep, stage.last)
    raise typer.Exit(EXIT_INTERRUPTED) from None
