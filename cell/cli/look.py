"""Commands that look and measure: ``cell scenarios``, ``cell map info``, ``cell detect``, ``cell bench``."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from cell.cli.common import NoiseOpt, app, cell_errors, check_method, err, map_app, out, parse_noise, progress
from cell.cli.tables import print_detection
from cell.errors import EXIT_PARTIAL


@app.command()
def scenarios() -> None:
    """List the scenarios shipped in scenarios/."""
    from cell import scenario as sc

    with cell_errors():
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

    with cell_errors():
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

    with cell_errors():
        scn = sc.load(scenario)
        check_method(method)
        det = pipeline.detect(scn, method, noise=parse_noise(noise), progress=progress())
        if json_path is not None:
            write_json(json_path, detection_report(det))
            err.print(f"[dim]· report written to {json_path}[/]")
        if save_cloud is not None and det.scene is not None:
            from cell.perception import save_ply

            save_ply(det.scene.perceived.dense, save_cloud)
            err.print(f"[dim]· spliced cloud written to {save_cloud}[/]")
        print_detection(det)
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
    methods: Annotated[
        str | None, typer.Option(help="Comma-separated locators (default: every registered one).")
    ] = None,
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
        rows = b.run(
            [sc.load(n) for n in names],
            wanted,
            noise=parse_noise(noise),
            extrinsics=exts,
            repeat=repeat,
            progress=progress(),
        )
        write_json(json_path, rows)
        md = b.markdown_table(rows)
        json_path.with_suffix(".md").write_text(md, encoding="utf-8")
        out.print(md, soft_wrap=True)
        err.print(f"[dim]· rows written to {json_path} and {json_path.with_suffix('.md')}[/]")
