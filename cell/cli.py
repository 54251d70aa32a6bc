"""The ``cell`` command: a thin typer layer over :mod:`cell.pipeline`.

Heavy packages (pybullet, open3d, pinocchio) are imported inside the commands so ``cell --help`` is instant.
Progress goes to stderr, results to stdout. Every :class:`~cell.errors.CellError` becomes a one-line message and its
documented exit code (see :mod:`cell.errors`); nothing else is caught, so a bug still shows its traceback.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Literal

import typer
from rich.console import Console
from rich.table import Table

from cell.errors import EXIT_PARTIAL, CellError

if TYPE_CHECKING:  # the pipeline (and what it imports) loads inside the commands, so `cell --help` stays instant
    from cell.pipeline import Detection, WeldRun

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    help="Robotic weld cell: find weld seams with depth cameras and a DXF welding map, in simulation.",
)
map_app = typer.Typer(no_args_is_help=True, help="Welding maps (DXF).")
app.add_typer(map_app, name="map")

err = Console(stderr=True, highlight=False)
out = Console(highlight=False, width=140)

NoiseOpt = Annotated[str | None, typer.Option("--noise", help="Override the scenario's noise model: none | realistic.")]


@contextmanager
def _cell_errors() -> Iterator[None]:
    """Turn a CellError into its one-line message and exit code."""
    try:
        yield
    except CellError as e:
        err.print(f"[bold red]error[/]: {e.message}", soft_wrap=True)
        raise typer.Exit(e.exit_code) from None


def _progress() -> Callable[[str], None]:
    def say(msg: str) -> None:
        err.print(f"[dim]· {msg}[/]")

    return say


def _noise(value: str | None) -> Literal["none", "realistic"] | None:
    if value is None:
        return None
    if value not in ("none", "realistic"):
        raise typer.BadParameter(f"{value!r}; valid: none, realistic", param_hint="--noise")
    return "none" if value == "none" else "realistic"


@app.command()
def scenarios() -> None:
    """List the scenarios shipped in scenarios/."""
    from cell import scenario as sc

    with _cell_errors():
        for name in sc.available():
            s = sc.load(name)
            out.print(f"{name:28s} {s.description}")


@map_app.command("info")
def map_info(
    path: Annotated[Path, typer.Argument(help="A DXF welding map.")],
    units: Annotated[str | None, typer.Option(help="Units if the DXF declares none: mm, cm, m, in.")] = None,
) -> None:
    """Print the units, parts and seams of a DXF welding map."""
    from cell.weldmap import describe, read_map

    with _cell_errors():
        out.print(describe(read_map(path, units=units)), soft_wrap=True)


@app.command()
def detect(
    scenario: Annotated[str, typer.Argument(help="A scenario name (see `cell scenarios`) or a YAML path.")],
    method: Annotated[
        str | None, typer.Option(help="Seam locator: paper, ransac or ours (default: the scenario's).")
    ] = None,
    noise: NoiseOpt = None,
    json_path: Annotated[Path | None, typer.Option("--json", help="Write the JSON report here.")] = None,
    save_cloud: Annotated[Path | None, typer.Option(help="Write the spliced cloud (robot frame) as PLY.")] = None,
) -> None:
    """Capture the cell, splice the clouds, align the map and locate every seam; report errors against truth."""
    from cell import pipeline
    from cell import scenario as sc
    from cell.export.report import detection_report, write_json

    with _cell_errors():
        scn = sc.load(scenario)
        _check_method(method)
        det = pipeline.detect(scn, method, noise=_noise(noise), progress=_progress())
        if json_path is not None:
            write_json(json_path, detection_report(det))
            err.print(f"[dim]· report written to {json_path}[/]")
        if save_cloud is not None and det.scene is not None:
            from cell.perception import save_ply

            save_ply(det.scene.perceived.dense, save_cloud)
            err.print(f"[dim]· spliced cloud written to {save_cloud}[/]")
        _print_detection(det)
    if det.error is not None:  # the report says which seams and why: partial, with the cause in report.error
        err.print(f"[bold red]error[/]: {det.error.message}", soft_wrap=True)
        raise typer.Exit(EXIT_PARTIAL)
    if not det.complete:
        raise typer.Exit(EXIT_PARTIAL)


@app.command()
def bench(
    scenarios: Annotated[
        list[str] | None, typer.Argument(help="Scenarios to run (default: fence1-exact fence1 fence2).")
    ] = None,
    methods: Annotated[str, typer.Option(help="Comma-separated locators.")] = "paper,ransac,ours",
    noise: NoiseOpt = None,
    extrinsics: Annotated[
        str, typer.Option(help="Comma-separated calibration errors of the fixed cameras: exact or MM/DEG.")
    ] = "exact",
    repeat: Annotated[int, typer.Option(min=1, help="Runs per locator (each seam's fastest).")] = 1,
    json_path: Annotated[Path, typer.Option("--json", help="Where to write the rows.")] = Path(
        "benchmarks/results/latest.json"
    ),
) -> None:
    """Table 1 of the paper, reproduced and extended: every locator on the same clouds in one run."""
    from cell import bench as b
    from cell import scenario as sc
    from cell.export.report import write_json
    from cell.seams.registry import METHODS

    with _cell_errors():
        names = scenarios or ["fence1-exact", "fence1", "fence2"]
        wanted = [m.strip() for m in methods.split(",") if m.strip()]
        bad = [m for m in wanted if m not in METHODS]
        if bad:
            raise typer.BadParameter(f"{', '.join(bad)}; valid: {', '.join(METHODS)}", param_hint="--methods")
        try:
            exts = [b.Extrinsics.parse(e.strip()) for e in extrinsics.split(",")]
        except ValueError as e:
            raise typer.BadParameter(str(e), param_hint="--extrinsics") from None
        rows = b.run(
            [sc.load(n) for n in names],
            wanted,
            noise=_noise(noise),
            extrinsics=exts,
            repeat=repeat,
            progress=_progress(),
        )
        write_json(json_path, rows)
        md = b.markdown_table(rows)
        json_path.with_suffix(".md").write_text(md, encoding="utf-8")
        out.print(md, soft_wrap=True)
        err.print(f"[dim]· rows written to {json_path} and {json_path.with_suffix('.md')}[/]")


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
) -> None:
    """The whole cell: capture, locate every seam, re-scan doubtful ones up close, plan, check, weld in simulation."""
    from cell import pipeline
    from cell import scenario as sc

    with _cell_errors():
        scn = sc.load(scenario)
        _check_method(method)
        run = pipeline.weld(
            scn, method, noise=_noise(noise), rescan=_rescan_mode(rescan), progress=_progress(), gui=gui
        )
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

    with _cell_errors():
        scn = sc.load(scenario)
        _check_method(method)
        scn = scn.with_noise(n) if (n := _noise(noise)) else scn
        ids = [s.strip() for s in seams.split(",") if s.strip()] if seams else None
        weldmap = pipeline.read_weldmap(scn)
        unknown = sorted(set(ids or ()) - {s.id for s in weldmap.seams})
        if unknown:
            valid = ", ".join(s.id for s in weldmap.seams)
            raise typer.BadParameter(f"no seam {', '.join(unknown)} in the map; seams: {valid}", param_hint="--seams")
        with open_station(scn, weldmap) as station:
            det = pipeline.detect(scn, method, progress=_progress(), station=station, weldmap=weldmap)
            if det.error is not None:
                raise det.error
            mode: pipeline.RescanMode = "all" if all_seams else "low"
            rs, after = pipeline.rescan_detection(station, det, mode, seam_ids=ids, progress=_progress())
        rep = rescan_report(det, after, rs)
        if json_path is not None:
            write_json(json_path, rep)
            err.print(f"[dim]· report written to {json_path}[/]")
        _print_rescan(rep)


def _print_rescan(rep: dict) -> None:
    t = Table(title=f"re-scan {rep['scenario']} · method {rep['method']} · frame R", title_justify="left")
    for col in ("seam", "lateral before", "lateral after", "endpoint before", "endpoint after", "weight", "why not"):
        t.add_column(col, justify="left" if col in ("seam", "why not") else "right")
    for s in rep["seams"]:
        b, a = s.get("error_mm_before", {}), s.get("error_mm", {})
        t.add_row(
            s["id"],
            _fmt(b.get("lateral")),
            _fmt(a.get("lateral")),
            _fmt(b.get("endpoint")),
            _fmt(a.get("endpoint")),
            _fmt(s["rescan"]["weight"]),
            s["rescan"]["reason"],
        )
    out.print(t)
    b, a = rep["summary_before_rescan"], rep["summary"]
    out.print(
        f"{rep['rescan']['seams']} seams re-scanned ({rep['rescan']['used']} used) · mean lateral"
        f" {_fmt(b['lateral_mean_mm'], 3)} -> {_fmt(a['lateral_mean_mm'], 3)} mm · mean endpoint"
        f" {_fmt(b['endpoint_mean_mm'], 3)} -> {_fmt(a['endpoint_mean_mm'], 3)} mm · robot time"
        f" {_fmt(rep['rescan']['motion_s'], 1)} s"
    )


def _rescan_mode(value: str | None) -> Literal["none", "low", "all"] | None:
    if value is None:
        return None
    if value not in ("none", "low", "all"):
        raise typer.BadParameter(f"{value!r}; valid: none, low, all", param_hint="--rescan")
    return "none" if value == "none" else ("low" if value == "low" else "all")


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

    with _cell_errors():
        scn = sc.load(scenario)
        _check_method(method)
        run = pipeline.weld(scn, method, noise=_noise(noise), execute_plan=False, progress=_progress())
        _progress()(f"drawing pictures into {out_dir}/")
        paths = write_run(run, out_dir)
        _finish_run(run, out_dir / "report.json", None, title="preview")
        for p in paths:
            err.print(f"[dim]· {p}[/]")


def _check_method(method: str | None) -> None:
    from cell.seams.registry import METHODS

    if method is not None and method not in METHODS:
        raise typer.BadParameter(f"{method!r}; valid: {', '.join(METHODS)}", param_hint="--method")


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
        src, dat = write_krl(run.plan, run.arm.model, krl, name[:24], X_WR=run.detection.scenario.X_WR)
        traj_json = write_traj(run.plan, krl / "trajectory.json")
        traj_csv = write_csv(run.plan, krl / "trajectory.csv")
        err.print(f"[dim]· robot program: {src}, {dat}; trajectory: {traj_json}, {traj_csv}[/]")
    _print_weld(rep, title)
    if run.error is not None:  # the report says which seams and why: partial, with the cause in report.error
        err.print(f"[bold red]error[/]: {run.error.message}", soft_wrap=True)
        raise typer.Exit(EXIT_PARTIAL)
    if not run.complete:
        raise typer.Exit(EXIT_PARTIAL)


def _print_weld(rep: dict, title: str) -> None:
    t = Table(
        title=f"{title} {rep['scenario']} · method {rep['method']} · noise {rep['noise']} · frame R",
        title_justify="left",
    )
    for col in (
        "seam",
        "detected",
        "paper ME mm",
        "lateral mm",
        "welded",
        "TCP rms mm",
        "TCP max mm",
        "weld s",
        "why not",
    ):
        t.add_column(col, justify="left" if col in ("seam", "detected", "welded", "why not") else "right")
    for s in rep["seams"]:
        e = s.get("error_mm", {})
        tcp = s.get("tcp_error_mm", {})
        t.add_row(
            s["id"],
            s["status"],
            _fmt(e.get("paper_me")),
            _fmt(e.get("lateral")),
            "yes" if s["welded"] else ("planned" if s.get("planned") else "no"),
            _fmt(tcp.get("rms")),
            _fmt(tcp.get("max")),
            _fmt(s.get("weld_time_s"), 1),
            s.get("weld_reason", ""),
        )
    out.print(t)
    m = rep["summary"]
    cyc = rep["cycle_time_s"] if rep["cycle_time_s"] else rep["planned_cycle_time_s"]
    out.print(
        f"welded {rep['welded']}/{m['visible']} visible seams ({m['seams']} in the map) · located {m['found']} · "
        f"paper ME mean {_fmt(m['paper_me_mean_mm'])} mm · cycle time {_fmt(cyc, 1)} s"
        + ("" if rep["cycle_time_s"] else " (planned)")
    )
    _print_timings(rep)


def _print_timings(rep: dict) -> None:
    """The stage times of a report, one line."""
    tim = rep["timings_s"]
    out.print("time: " + " · ".join(f"{k.removesuffix('_s')} {v:.2f} s" for k, v in tim.items() if v is not None))


def _fmt(v: float | None, nd: int = 2) -> str:
    return "-" if v is None else f"{v:.{nd}f}"


def _print_detection(det: Detection) -> None:
    from cell.export.report import detection_report

    rep = detection_report(det)
    t = Table(
        title=f"{rep['scenario']} · method {rep['method']} · noise {rep['noise']} · frame R",
        title_justify="left",
    )
    for col in ("seam", "status", "paper ME mm", "endpoint mm", "lateral mm", "conf", "ms", "reason"):
        t.add_column(col, justify="right" if col not in ("seam", "status", "reason") else "left")
    for s in rep["seams"]:
        e = s.get("error_mm", {})
        t.add_row(
            s["id"],
            s["status"],
            _fmt(e.get("paper_me")),
            _fmt(e.get("endpoint")),
            _fmt(e.get("lateral")),
            _fmt(s.get("confidence")),
            _fmt(s["time_ms"], 1) if s["status"] == "found" else "-",
            s["reason"],
        )
    out.print(t)
    m = rep["summary"]
    out.print(
        f"found {m['found']}/{m['visible']} visible ({m['seams']} seams) · paper ME mean"
        f" {_fmt(m['paper_me_mean_mm'])} mm (p95 {_fmt(m['paper_me_p95_mm'])}) · endpoint"
        f" {_fmt(m['endpoint_mean_mm'])} mm · lateral"
        f" {_fmt(m['lateral_mean_mm'])} mm · {_fmt(m['time_ms_per_seam_median'], 1)} ms/seam (median)"
    )
    _print_timings(rep)


def main() -> None:
    """Console-script entry point."""
    try:
        app()
    except KeyboardInterrupt:
        sys.exit(130)
