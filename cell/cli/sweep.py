"""``cell sweep``: a tolerance study on Ray (docs/sweep.md): N varied builds, one task each, streamed into ``--out`` as
they finish and resumable; everything it can check is checked before Ray starts."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from cell.cli.bar import Bar
from cell.cli.common import (
    CalibrationOpt,
    app,
    cell_errors,
    check_method,
    fail_line,
    load_scenario,
    say,
    was_interrupted,
)
from cell.cli.outputs import check_folder
from cell.errors import EXIT_INTERRUPTED, UsageError


def _stage(value: str) -> str:
    from cell.sweep import STAGES

    if value not in STAGES:
        raise UsageError(f"--stage {value!r}; valid: {', '.join(STAGES)}")
    return value


@app.command()
def sweep(
    scenario: Annotated[str, typer.Argument(help="A scenario name (see `cell scenarios`) or a YAML path.")],
    out: Annotated[Path, typer.Option("--out", help="Folder for runs.jsonl, summary.json and the pictures.")],
    n: Annotated[int, typer.Option("--n", min=1, help="Number of varied builds (runs 0 .. N-1).")] = 200,
    vary: Annotated[
        str, typer.Option(help="What varies, comma-separated: tolerances, placement, extrinsics, seed.")
    ] = "tolerances,placement,extrinsics,seed",
    stage: Annotated[
        str,
        typer.Option(help="How far each run goes: detect | plan (plan + safety gate, nothing moves) | weld (all)."),
    ] = "plan",
    address: Annotated[
        str | None, typer.Option(help="A running Ray cluster's head (host:port); default: a local Ray.")
    ] = None,
    workers: Annotated[
        int | None, typer.Option(min=1, help="CPUs of the local Ray (default: the machine's); tasks in flight.")
    ] = None,
    method: Annotated[str | None, typer.Option(help="Seam locator (default: the scenario's).")] = None,
    fresh: Annotated[bool, typer.Option(help="Replace what --out holds instead of resuming it.")] = False,
    calibration: CalibrationOpt = None,
) -> None:
    """Tolerance study: which seams are at risk under part tolerances, placement and calibration errors. With
    --calibration the file's measured poses are the cell's belief and the drawn extrinsic errors move the true
    cameras off them (docs/calibration.md section 6)."""
    from cell import pipeline
    from cell import scenario as sc
    from cell.provenance import sha256_file
    from cell.sweep import parse_vary
    from cell.sweep.study import Study, SweepSpec

    with cell_errors():
        words = parse_vary(vary)
        st = _stage(stage)
        check_method(method)
        check_folder(out, "--out")
        scn = load_scenario(scenario, calibration)
        weldmap = pipeline.read_weldmap(scn)
        # With a calibration the scenario is not its file's alone: the study is keyed on its values instead.
        digests = sha256_file(scn.map_path), sha256_file(sc.resolve(scenario)) if calibration is None else None
        spec = SweepSpec(scn, weldmap, n, words, st, method, *digests)  # type: ignore[arg-type]
        bar = Bar()
        study = Study(
            spec,
            out,
            count=lambda done, total: bar("runs", done, total),
            say=say,
            warn=lambda msg: fail_line(f"warning: {msg}"),
            address=address,
            workers=workers,
        )
        try:
            summary = study.run(fresh=fresh)
        except (KeyboardInterrupt, ImportError) as e:
            if not was_interrupted(e):
                raise
            bar.close()
            kept = len(study.store.lines) if study.store is not None else 0
            fail_line(
                f"exit {EXIT_INTERRUPTED}: interrupted; {kept} runs kept in {out}/runs.jsonl: run again to resume"
            )
            raise typer.Exit(EXIT_INTERRUPTED) from None
        bar.close()
    say(f"{summary['done']} runs ({summary['failed']} failed): {out}/summary.json, {out}/risk.png, {out}/errors.png")
    _print(summary)


def _print(summary: dict[str, Any]) -> None:
    """Per seam, one line: probabilities found / within tolerance / planned or welded, lateral error p90."""
    from cell.cli.common import out

    key = {"plan": "probability_planned", "weld": "probability_welded"}.get(summary["stage"])
    head = f"{'seam':<26} {'found':>6} {'in tol':>6} {(key or '').split('_')[-1]:>8} {'lat p90 mm':>10}"
    out.print(head, markup=False)
    for sid, s in summary["seams"].items():
        lat = (s.get("lateral_mm") or {}).get("p90")
        third = f"{s[key]:.2f}" if key and s.get(key) is not None else ""
        found = s["probability_found"]
        within = s["probability_within_tolerance"]
        out.print(
            f"{sid:<26} {found if found is not None else float('nan'):>6.2f} "
            f"{within if within is not None else float('nan'):>6.2f} {third:>8} "
            f"{lat if lat is not None else float('nan'):>10.3f}",
            markup=False,
        )
