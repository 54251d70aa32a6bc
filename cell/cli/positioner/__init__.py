"""``cell weld`` (and ``cell preview``) of a part on a tilt-rotate positioner (docs/positioner.md): the report (each
seam's pose and ISO 6947 position, welded or why not), the programs, one per pose, and exit 3 with each unwelded
seam's reason. The options of a two-sided job that do not apply here are refused by name."""

from __future__ import annotations

from collections import Counter
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from cell.cli.common import TableFormat, progress, say
from cell.cli.outputs import Writer, finish
from cell.errors import EXIT_PARTIAL, UsageError
from cell.scenario import Scenario
from cell.types import Kinematics
from cell.types.run import partial_text

if TYPE_CHECKING:
    from cell.pipeline.job import WeldJob


def refuse_options(scenario: str, options: Mapping[str, object]) -> None:
    """A UsageError naming the first given option (not None) that a positioner job has no use for."""
    given = [k for k, v in options.items() if v is not None and v is not False]
    if given:
        raise UsageError(
            f"{given[0]} does not apply to scenario {scenario!r}: its part is on robot.positioner (no operator"
            f" turn, no sides, one report and a program per pose); valid: --json, --program, --html, --controller,"
            f" --method, --noise, --rescan, --calibration, --gui"
        )


def weld_positioned(
    sc: Scenario,
    prov: Mapping[str, Any],
    job: WeldJob,
    outputs: tuple[Path | None, Path | None, str],
    fmt: TableFormat,
    unused: Mapping[str, object],
    html: Path | None = None,
) -> None:
    """Run the job, write the report first (``outputs``: the --json path, the --program folder, the controller),
    then the programs; one line per seam, the last line; exit 3 when a seam is not welded (each one's reason code
    counted). ``unused``: the options given that a positioner job has no use for (refused, with ``--sides
    first``). ``html``: the job's page (:meth:`PositionerRun.as_weld_run`: results, the cloud and the map at home,
    the curves and their stretches left for a manual weld; no robot or joint plots: the part moves between poses)."""
    from cell.export.reports.positioner_report import positioner_report
    from cell.pipeline.positioned import weld_on_positioner

    refuse_options(sc.name, {**unused, "--sides first": job.sides == "first" or None})
    json_path, program, controller = outputs
    writer = Writer()
    run = weld_on_positioner(sc, job, progress=progress())
    rep = {**positioner_report(run), "provenance": dict(prov)}
    writer.report(json_path, rep)
    if program is not None and job.execute:
        from cell.export.reports.curve_report import write_manual_welds
        from cell.preview.welder_sheet import write_welder_sheet

        written = writer.attempt(lambda: [*_programs(sc, run, program, controller), *write_manual_welds(rep, program)])
        sheet = writer.attempt(lambda: write_welder_sheet([run.detection], rep, program))
        written = [*(written or []), *(sheet or [])]
        if written:
            say(f"robot programs: {', '.join(map(str, written))}")
            writer.written("programs", written)
    if html is not None:  # the results, the cloud and the map at home, the curves and what is left of them
        from cell.preview import write_page

        if writer.attempt(lambda: write_page(run.as_weld_run(), html)) is not None:
            say(f"page: {html}")
    if fmt == "table":
        for s in rep["seams"]:
            wp = s["weld_position"] or {}
            why = (
                s["reason"]
                if str(s["reason"]).startswith(str(s["reason_code"]))
                else f"{s['reason_code']}: {s['reason']}"
            )
            done = f"TCP max {s['tcp_max_mm']} mm" if s["welded"] else f"not welded: {why}"
            if not job.execute:  # a preview: the pose chosen, or why none
                done = "pose chosen" if s["pose"] is not None else f"no pose: {why}"
            pose = f"p{s['pose'] + 1}" if s["pose"] is not None else "--"  # the program's number
            say(f"{s['id']:>24}  {pose}  {wp.get('code', '--')} slope {wp.get('slope_deg')} deg rotation"
                f" {wp.get('rotation_deg')} deg  {done}")  # fmt: skip
    t = rep["totals"]
    verb = "welded" if job.execute else "planned (nothing moves)"
    n = t["welded"] if job.execute else sum(len(p["seams"]) for p in rep["poses"])
    say(
        f"{n}/{t['seams']} seams {verb} on {len(run.groups)} positioner poses, no operator turn; cycle"
        f" {t['cycle_time_s'] or 0:.1f} s (positioner {t['positioner_s'] or 0:.1f} s); TCP max {t['tcp_max_mm']} mm"
    )
    finish(writer, partial_line(rep) if job.execute else None)


def partial_line(rep: Mapping[str, Any]) -> str | None:
    """Why the job exits 3 (None: every seam welded): the error, the seams not welded by reason code."""
    undone = Counter(str(s["reason_code"]) for s in rep["seams"] if not s["welded"])
    if not undone and rep.get("error") is None:
        return None
    part = undone.pop("partial", 0)  # curves welded in part: said apart, with what is left for a manual weld
    n = sum(undone.values())
    parts = [str(rep["error"])] if rep.get("error") else []
    if n:
        parts.append(
            f"{n} seam{'s' * (n != 1)} not welded ({', '.join(f'{c}: {k}' for c, k in sorted(undone.items()))})"
        )
    if part:
        parts.append(partial_text(part, rep["totals"].get("manual_mm")))
    return f"exit {EXIT_PARTIAL}: {'; '.join(parts)}; {rep['totals']['welded']}/{rep['totals']['seams']} welded"


def _programs(sc: Scenario, run: Any, out_dir: Path, controller: str) -> list[Path]:
    """A program per pose that welds something, and the main program calling them (no operator stop)."""
    from cell.export.positioner_program import write_positioner_programs
    from cell.export.program import ProgramJob
    from cell.outputs import make_folder
    from cell.types import WeldReason
    from cell.types.positioner import external_axes

    assert sc.robot.positioner is not None
    pos = sc.robot.positioner.positioner(sc.X_WR)
    robot = _robot(sc)
    jobs = []
    for k, g in enumerate(run.groups):
        if g.plan is None or not g.plan.segments or g.execution is None:
            continue
        X_RB = pos.X_R_F(g.pose.tilt, g.pose.rotate)
        ext = external_axes(pos, g.pose.tilt, g.pose.rotate, via=g.via)  # the route the move check cleared
        jobs.append(ProgramJob(g.plan, robot, f"{sc.name.replace('-', '_')}_p{k + 1}"[:24], X_RB=X_RB,
                               X_WR=np.asarray(sc.X_WR), external=ext))  # fmt: skip
    coordinated = [cw for cw in run.coordinated if any(w.welded or w.code is WeldReason.PARTIAL for g in run.groups
                                                       for w in g.seams if w.id == cw.seam_id)]  # fmt: skip
    if not jobs and not coordinated:
        return []
    from cell.export.coordinated_program import coordinated_names, write_coordinated_programs

    make_folder(out_dir)
    stem = f"{sc.name.replace('-', '_')}"[:24]
    names = coordinated_names(stem[:20], len(coordinated))  # the main calls them after the poses, as they were played
    after = [(n, _welds(cw)) for n, cw in zip(names, coordinated, strict=True)]
    home = np.radians(np.asarray(sc.robot.home_deg, dtype=float))
    written = write_positioner_programs(controller, jobs, stem, out_dir, after, home)
    if coordinated:  # curved seams welded with the part turning: a program each (docs/positioner.md)
        written += write_coordinated_programs(controller, coordinated, robot, pos, stem[:20], out_dir)
    return written


def _welds(cw: Any) -> str:
    """What a coordinated weld's program welds, for the main program's comment: its seam, and the stretch of it
    when it welds one (an arc of a loop welded in part)."""
    if cw.span_m is None:
        return f"seam {cw.seam_id}"
    a, b = (v * 1000.0 for v in cw.span_m)
    return f"seam {cw.seam_id} from {a:.0f} to {b:.0f} mm along it"


def _robot(sc: Scenario) -> Kinematics:
    """The arm's kinematics for the programs."""
    from cell.motion.robot import RobotModel
    from cell.station.arm import robot_urdf

    return RobotModel.from_urdf(robot_urdf(sc))


__all__ = ["partial_line", "refuse_options", "weld_positioned"]
