"""Commands that look and measure: ``cell scenarios``, ``cell map info``, ``cell detect``, ``cell bench``."""

from __future__ import annotations

import datetime as dt
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from cell.cli.common import (
    CalibrationOpt,
    FormatOpt,
    NoiseOpt,
    app,
    cell_errors,
    check_method,
    detail,
    fail_line,
    load_scenario,
    map_app,
    out,
    parse_format,
    parse_noise,
    progress,
    say,
    warn,
    was_interrupted,
)
from cell.cli.outputs import Stage, Writer, check_file, check_folder, finish, interrupted_report, on_interrupt
from cell.cli.placement import PlaceOpt, PlaceRpyOpt
from cell.cli.printout.explain import detection_exit
from cell.cli.printout.tables import print_detection
from cell.errors import EXIT_INTERRUPTED, UsageError

if TYPE_CHECKING:
    from cell.station import Station

BENCH_SAVED = Path("benchmarks/results/latest.json")  # what --save writes (Table 1 of docs/results.md is made from it)


@app.command()
def scenarios() -> None:
    """List the scenarios shipped in scenarios/."""
    from cell import scenario as sc

    with cell_errors():
        for name in sc.available():
            s = sc.load(name)
            out.print(f"{name:28s} {s.description}", soft_wrap=True)


@map_app.command("info")
def map_info(
    path: Annotated[Path, typer.Argument(help="A DXF welding map.")],
    units: Annotated[
        str | None, typer.Option(help="Units the DXF is drawn in (mm, cm, m, in); wins over its $INSUNITS.")
    ] = None,
    scenario: Annotated[
        str | None, typer.Option(help="Read the map as this scenario does: its map.layers and map.units.")
    ] = None,
) -> None:
    """Print the units, parts, fixtures and seams (with their joints) of a DXF welding map, and what it skipped."""
    from cell.seams.joint import joint_notes
    from cell.weldmap import METRES_PER_UNIT, describe, read_map

    with cell_errors():
        if units is not None and units not in METRES_PER_UNIT:
            raise UsageError(f"--units {units!r}; valid: {', '.join(METRES_PER_UNIT)}")
        layers = None
        if scenario is not None:
            from cell import scenario as sc

            spec = sc.load(scenario).map
            layers, units = spec.layers, units if units is not None else spec.units
        weldmap = read_map(path, units=units, layers=layers)  # its warnings print through cli.common's handler
        out.print(describe(weldmap, joint_notes(weldmap)), soft_wrap=True, markup=False, highlight=False)


@app.command()
def detect(
    scenario: Annotated[
        str | None, typer.Argument(help="A scenario name (see `cell scenarios`) or a YAML path (not with --capture).")
    ] = None,
    method: Annotated[
        str | None, typer.Option(help="Seam locator: paper, ransac or ours (default: the scenario's).")
    ] = None,
    noise: NoiseOpt = None,
    json_path: Annotated[
        Path | None, typer.Option("--json", help="Write the JSON report here ('-': stdout, the table to stderr).")
    ] = None,
    save_cloud: Annotated[Path | None, typer.Option(help="Write the spliced cloud (robot frame) as PLY.")] = None,
    fmt: FormatOpt = "table",
    capture_dir: Annotated[
        Path | None,
        typer.Option("--capture", help="A capture folder (`cell capture`, docs/capture.md) instead of SCENARIO."),
    ] = None,
    map_path: Annotated[
        Path | None, typer.Option("--map", help="With --capture: this DXF map instead of the capture's.")
    ] = None,
    place: PlaceOpt = None,
    place_rpy: PlaceRpyOpt = None,
    calibration: CalibrationOpt = None,
) -> None:
    """Capture the cell, splice the clouds, align the map and locate every seam; report errors against truth.

    With --capture DIR the images are the recorded ones (no simulator); --map and --place (the map's nominal pose
    in the capture's robot frame) override the capture's cell, and are needed when it has no cell.yaml.
    """
    from cell import pipeline
    from cell import scenario as sc
    from cell.export.reports.report import detection_report
    from cell.provenance import provenance

    with cell_errors():
        table = parse_format(fmt)
        check_file(json_path, "--json")
        check_file(save_cloud, "--save-cloud", stdout_ok=False)
        station: Station | None = None
        if capture_dir is not None:
            from cell.cli.capture import replay

            scn, station, scenario_file = replay(scenario, capture_dir, map_path, place, place_rpy, noise)
        elif scenario is None or map_path is not None or place is not None or place_rpy is not None:
            raise UsageError("give SCENARIO, or --capture DIR (which --map and --place go with)")
        else:
            scn, scenario_file = load_scenario(scenario, calibration), sc.resolve(scenario)
        if calibration is not None and capture_dir is not None:
            raise UsageError("--calibration goes with SCENARIO; a capture folder records the poses it was taken with")
        check_method(method)
        scn = scn.with_noise(n) if (n := parse_noise(noise)) else scn
        prov = provenance(scn, scenario_file=scenario_file)
        if capture_dir is not None:
            prov["capture"] = str(capture_dir.resolve())
        detail(f"scenario {prov['scenario_file']} (sha256 {prov['scenario_sha256']}), map {prov['map_file']}")
        stage, writer = Stage(), Writer()
        det: pipeline.Detection | None = None
        try:
            det = pipeline.detect(scn, method, progress=stage, station=station)
            rep = detection_report(det, provenance=prov)
            writer.report(json_path, rep)
            if save_cloud is not None:
                save_spliced(det, save_cloud, writer)
            print_detection(rep, table)
        except (KeyboardInterrupt, ImportError) as e:
            if not was_interrupted(e):
                raise
            done = detection_report(det, provenance=prov) if det is not None else None
            on_interrupt(writer, json_path, done or interrupted_report(scn, method, stage.last, prov), stage.last)
            raise typer.Exit(EXIT_INTERRUPTED) from None
    if det.error is not None:  # the report says which seams and why: partial, with the cause in report.error
        fail_line(f"error: {det.error.message}")
    finish(writer, None if det.complete and det.error is None else detection_exit(rep))


def save_spliced(det: Any, path: Path, writer: Writer) -> None:
    """``--save-cloud``: every camera's registered points in R (unfiltered, the splice's result: what ``cell
    locate`` aligns best), also when the alignment failed; when perception itself failed, a warning line says why
    nothing was written. The line after a write gives the ``cell locate`` command that reads it back."""
    from cell.pipeline import table_z_R

    perceived = det.scene.perceived if det.scene is not None else det.perceived
    if perceived is None:
        why = det.error.message if det.error is not None else "no cloud was perceived"
        warn(f"--save-cloud: nothing written to {path}: no cloud was spliced ({why})")
        return
    cloud = perceived.spliced.registered
    if writer.attempt(lambda: _save_cloud(cloud, path)) is not None:
        z_mm = table_z_R(det.scenario) * 1e3  # the workspace crop leaves the table out: its height says where it is
        say(
            f"spliced cloud ({len(cloud)} points, frame R) written to {path}; read it back with: cell locate {path}"
            f" --map MAP --frame R --table-z {z_mm:.1f}"
        )


def _save_cloud(cloud: Any, path: Path) -> Path:
    from cell.outputs import replacing
    from cell.perception import save_ply

    with replacing(path, what="cloud") as tmp:  # whole: save_ply writes the file, then rewrites its header
        save_ply(cloud, tmp)
    return path


def bench_folder(out_dir: Path | None, now: dt.datetime | None = None) -> Path:
    """Where ``cell bench`` writes: ``--out DIR``, else ``runs/bench-<UTC time>/`` (untracked: .gitignore)."""
    if out_dir is not None:
        return out_dir
    stamp = (now or dt.datetime.now(dt.UTC)).astimezone(dt.UTC).strftime("%Y%m%dT%H%M%SZ")
    return Path("runs") / f"bench-{stamp}"


@app.command()
def bench(
    scenarios: Annotated[
        list[str] | None, typer.Argument(help="Scenarios to run (default: fence1-exact fence1 fence2).")
    ] = None,
    methods: Annotated[
        str | None, typer.Option(help="Comma-separated locators (default: every registered one).")
    ] = None,
    noise: NoiseOpt = None,
    extrinsics: Annotated[
        str, typer.Option(help="Comma-separated calibration errors of the fixed cameras: exact or MM/DEG.")
    ] = "exact",
    repeat: Annotated[int, typer.Option(min=1, help="Runs per locator (each seam's fastest).")] = 1,
    out_dir: Annotated[
        Path | None, typer.Option("--out", help="Run folder for the rows (default: runs/bench-<UTC time>/).")
    ] = None,
    json_path: Annotated[
        Path | None, typer.Option("--json", help="Also write the rows (and their .md table) to this file.")
    ] = None,
    save: Annotated[
        bool, typer.Option("--save", help=f"Also write the rows to {BENCH_SAVED} (Table 1 of docs/results.md).")
    ] = False,
    calibration: CalibrationOpt = None,
) -> None:
    """Table 1 of the paper, reproduced and extended: every locator on the same clouds in one run.

    Writes bench.json, bench.md and provenance.json into a run folder; tracked files only with --save or --json.
    With --calibration every scenario's cameras are told the file's measured poses; an --extrinsics error then
    moves the true fixed cameras off them (docs/calibration.md section 6).
    """
    from cell import bench as b
    from cell import scenario as sc
    from cell.export import write_json
    from cell.outputs import write_atomic
    from cell.provenance import provenance
    from cell.seams.registry import METHODS

    with cell_errors():
        names = scenarios or ["fence1-exact", "fence1", "fence2"]
        wanted = [m.strip() for m in methods.split(",") if m.strip()] if methods else list(METHODS)
        bad = [m for m in wanted if m not in METHODS]
        if bad:
            raise typer.BadParameter(f"{', '.join(bad)}; valid: {', '.join(METHODS)}", param_hint="--methods")
        try:
            exts = [b.Extrinsics.parse(e.strip()) for e in extrinsics.split(",")]
        except ValueError as e:
            raise typer.BadParameter(str(e), param_hint="--extrinsics") from None
        folder = bench_folder(out_dir)
        if out_dir is None:
            folder.parent.mkdir(exist_ok=True)  # runs/, the cell's own (untracked) folder of run folders
        check_folder(folder, "--out")
        check_file(json_path, "--json", stdout_ok=False)
        loaded = [load_scenario(n, calibration) for n in names]
        prov: dict[str, Any] = provenance(None)
        prov["scenarios"] = [
            {k: v for k, v in provenance(s, scenario_file=sc.resolve(n)).items() if k in _PER_SCENARIO} | {"name": n}
            for n, s in zip(names, loaded, strict=True)
        ]
        rows = b.run(loaded, wanted, noise=parse_noise(noise), extrinsics=exts, repeat=repeat, progress=progress())
        md = b.markdown_table(rows)
        made_by = f"<!-- made by cell {prov['version']}, commit {prov['commit']}, {prov['timestamp_utc']}: "
        made_by += f"{prov['command']} -->\n"
        writer = Writer()
        targets = [folder / "bench.json"] + [p for p in (json_path, BENCH_SAVED if save else None) if p is not None]
        for target in targets:
            if writer.attempt(partial(write_json, target, rows)) is not None:
                md_path = target.with_suffix(".md")
                text = (made_by + md) if target.parent == folder else md
                writer.attempt(partial(write_atomic, md_path, text.encode("utf-8"), what="table"))
                say(f"rows written to {target} and {md_path}")
        writer.attempt(lambda: write_json(folder / "provenance.json", prov))
        out.print(md, soft_wrap=True)
    finish(writer, None)


_PER_SCENARIO = ("seed", "scenario_file", "scenario_sha256", "map_file", "map_sha256")
