"""``cell locate CLOUD --map MAP.dxf``: the map's seams located in a point cloud someone brings, in the cloud's own
frame (docs/locate.md). Everything that can be checked is checked before any work (exit 2); nothing here imports
the simulator."""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import numpy as np
import typer
from rich.markup import escape

from cell.cli.common import (
    FormatOpt,
    app,
    cell_errors,
    check_method,
    detail,
    err,
    fail_line,
    log,
    out,
    parse_format,
    say,
    was_interrupted,
)
from cell.cli.outputs import Stage, Writer, check_file, finish, on_interrupt, stopped_report
from cell.cli.placement import PlaceOpt, PlaceRpyOpt, placement
from cell.cli.printout.explain import detection_exit
from cell.errors import EXIT_INTERRUPTED, UsageError
from cell.geometry import FloatArray

if TYPE_CHECKING:
    from cell.pipeline.records import Detection
    from cell.types import Cloud

TRUTH_UNITS = "mm"  # a truth file's coordinates (docs/locate.md)


@app.command()
def locate(
    cloud: Annotated[Path, typer.Argument(metavar="CLOUD", help="A point cloud: PLY or PCD, ascii or binary.")],
    map_path: Annotated[Path, typer.Option("--map", help="The welding map (DXF) of the part in the cloud.")],
    place: PlaceOpt = None,
    place_rpy: PlaceRpyOpt = None,
    units: Annotated[str, typer.Option(help="Units of the cloud file's numbers: m, cm, mm, in.")] = "m",
    map_units: Annotated[
        str | None, typer.Option(help="Units the DXF is drawn in (mm, cm, m, in); wins over its $INSUNITS.")
    ] = None,
    frame: Annotated[str, typer.Option(help="The name of the cloud's own frame (the report's frame).")] = "F",
    viewpoint: Annotated[
        str | None, typer.Option(help="Where the sensor was, X,Y,Z in mm in the cloud's frame (orients normals).")
    ] = None,
    method: Annotated[str | None, typer.Option(help="Seam locator: paper, ransac or ours (default: ours).")] = None,
    json_path: Annotated[
        Path | None, typer.Option("--json", help="Write the JSON report here ('-': stdout, the table to stderr).")
    ] = None,
    save_cloud: Annotated[
        Path | None, typer.Option(help="Write the cloud as read (metres, finite points, its frame) as PLY.")
    ] = None,
    truth: Annotated[
        Path | None, typer.Option(help="True seams (JSON: seam id -> start, end in mm in the cloud's frame).")
    ] = None,
    table_z: Annotated[
        float | None,
        typer.Option(help="The table's height in mm in the cloud's frame (its z up), when no table is in the cloud."),
    ] = None,
    no_table: Annotated[
        bool, typer.Option("--no-table", help="There is no table in the cloud: align on the parts' own faces.")
    ] = False,
    fmt: FormatOpt = "table",
) -> None:
    """Locate the welding map's seams in a point cloud you bring (a laser scan, any sensor's cloud).

    --place is the nominal pose of the drawing's origin in the cloud's frame; without it the map is found by a
    global registration. A cloud with no table in it (cropped above it, a part on a fixture) is recognised, or
    said so with --no-table or --table-z. Exit 3 when a seam that can be seen was not found (the report says why).
    """
    from cell.export.reports.report import detection_report
    from cell.perception.cloud_files import check_frame, check_units, read_cloud
    from cell.pipeline.cloud import locate_cloud
    from cell.provenance import provenance
    from cell.weldmap import METRES_PER_UNIT, read_map

    with cell_errors():
        table = parse_format(fmt)
        check_file(json_path, "--json")
        check_file(save_cloud, "--save-cloud", stdout_ok=False)
        check_units(units)
        check_frame(frame)
        if map_units is not None and map_units not in METRES_PER_UNIT:
            raise UsageError(f"--map-units {map_units!r}; valid: {', '.join(METRES_PER_UNIT)}")
        X_FM = placement(place, place_rpy)
        viewpoint_F = parse_viewpoint(viewpoint)
        table_z_m = parse_table(table_z, no_table)
        check_method(method)
        for path, option in ((map_path, "--map"), (truth, "--truth")):
            if path is not None and not path.is_file():
                raise UsageError(f"{option} {str(path)!r} does not exist; valid: an existing file")
        cloud_F = read_cloud(cloud, units=units, frame=frame, warn=_warn)
        weldmap = read_map(map_path, units=map_units)
        truth_F = read_truth(truth, [s.id for s in weldmap.seams], frame) if truth is not None else None
        inputs: dict[str, Path] = {"cloud": cloud, "map": map_path} | ({"truth": truth} if truth else {})
        prov = provenance(None, inputs=inputs)
        detail(f"cloud {prov['cloud_file']} (sha256 {prov['cloud_sha256']}), map {prov['map_file']}")
        say(f"{len(cloud_F)} points in frame {frame} read from {cloud}")
        stage, writer = Stage(), Writer()
        det: Detection | None = None
        try:
            det = locate_cloud(
                cloud_F, weldmap, X_FM, name=cloud.stem, method=method, viewpoint_F=viewpoint_F,
                truth_F=truth_F, table_z_m=table_z_m, no_table=no_table, progress=stage,
            )  # fmt: skip
            rep = detection_report(det, provenance=prov)
            writer.report(json_path, rep)
            if save_cloud is not None and writer.attempt(lambda: _save_cloud(cloud_F, save_cloud)) is not None:
                say(f"cloud written to {save_cloud}")
            print_located(rep, table)
        except (KeyboardInterrupt, ImportError) as e:
            if not was_interrupted(e):
                raise
            done = detection_report(det, provenance=prov) if det is not None else None
            rep = done or interrupted_report(cloud.stem, method, frame, stage.last, prov)
            on_interrupt(writer, json_path, rep, stage.last)
            raise typer.Exit(EXIT_INTERRUPTED) from None
    if det.error is not None:  # the report says which seams and why: partial, with the cause in report.error
        fail_line(f"error: {det.error.message}")
    finish(writer, None if det.complete and det.error is None else detection_exit(rep))


def _warn(msg: str) -> None:
    """A warning line: stderr (also with --quiet) and the log file."""
    log.warning(msg)
    err.print(f"[yellow]warning[/]: {escape(msg)}", soft_wrap=True, highlight=False)


def parse_table(table_z_mm: float | None, no_table: bool) -> float | None:
    """``--table-z`` [mm] as metres (None: not given); UsageError when it is not finite or comes with
    ``--no-table``."""
    if table_z_mm is None:
        return None
    if no_table:
        raise UsageError("--table-z and --no-table together; valid: one of them (a table's height, or none)")
    if not math.isfinite(table_z_mm):
        raise UsageError(f"--table-z {table_z_mm}; valid: a finite height in mm in the cloud's frame")
    return table_z_mm * 1e-3


def parse_viewpoint(text: str | None) -> FloatArray | None:
    """``--viewpoint X,Y,Z`` [mm] as (3,) [m], or None; UsageError when it is not three finite numbers."""
    if text is None:
        return None
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        values = []
    if len(values) != 3 or not all(math.isfinite(v) for v in values):
        raise UsageError(f"--viewpoint {text!r}; valid: X,Y,Z in mm in the cloud's frame (three numbers)")
    return np.array(values) * 1e-3


def _point_mm(value: Any) -> list[float] | None:
    if not isinstance(value, list) or len(value) != 3:
        return None
    if not all(isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v) for v in value):
        return None
    return [float(v) for v in value]


def read_truth(path: Path, seam_ids: list[str], frame: str) -> dict[str, tuple[FloatArray, FloatArray]]:
    """A truth file (docs/locate.md): ``{"units": "mm", "frame": F, "seams": {id: {"start": [x, y, z], "end":
    [x, y, z]}}}`` with every seam of the map, in millimetres in the cloud's frame; returns id -> ends (3,) [m].
    UsageError (one line) for anything else."""
    shown = str(path)
    form = (
        'valid: JSON {"units": "mm", "frame": ..., "seams": {"<seam id>": {"start": <3 numbers>, "end": <3 numbers>}}}'
    )
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as e:
        raise UsageError(f"--truth {shown!r} is not readable JSON ({e}); {form}") from None
    if not isinstance(data, dict) or not isinstance(data.get("seams"), dict):
        raise UsageError(f"--truth {shown!r} has no 'seams' object; {form}")
    if data.get("units", TRUTH_UNITS) != TRUTH_UNITS:
        raise UsageError(f"--truth {shown!r}: units {data.get('units')!r}; valid: {TRUTH_UNITS!r}")
    if data.get("frame", frame) != frame:
        raise UsageError(f"--truth {shown!r} is in frame {data.get('frame')!r}, the cloud in {frame!r}; valid: {frame}")
    seams: Mapping[str, Any] = data["seams"]
    unknown = [k for k in seams if k not in seam_ids]
    missing = [k for k in seam_ids if k not in seams]
    if unknown or missing:
        what = f"seams not in the map: {', '.join(unknown)}" if unknown else f"no truth for {', '.join(missing)}"
        raise UsageError(f"--truth {shown!r}: {what}; valid: every seam of the map: {', '.join(seam_ids)}")
    out_F: dict[str, tuple[FloatArray, FloatArray]] = {}
    for seam_id, entry in seams.items():
        ends = [_point_mm(entry.get(k)) if isinstance(entry, dict) else None for k in ("start", "end")]
        if ends[0] is None or ends[1] is None:
            raise UsageError(f"--truth {shown!r}: seam {seam_id!r} needs start and end of three numbers; {form}")
        out_F[seam_id] = (np.array(ends[0]) * 1e-3, np.array(ends[1]) * 1e-3)
    return out_F


def _save_cloud(cloud: Cloud, path: Path) -> Path:
    from cell.outputs import replacing
    from cell.perception import save_ply

    with replacing(path, what="cloud") as tmp:  # whole: save_ply writes the file, then rewrites its header
        save_ply(cloud, tmp)
    return path


def interrupted_report(
    name: str, method: str | None, frame: str, stage: str, prov: Mapping[str, Any] | None
) -> dict[str, Any]:
    """The report of a ``cell locate`` stopped by Ctrl-C before it returned: what ran, where it stopped, no seams
    (the keys of ``cell detect``'s interrupted report; no scenario, so ``config`` and ``noise`` are null)."""
    return stopped_report(name, method or "ours", stage, prov, frame=frame)


def print_located(rep: dict[str, Any], fmt: str) -> None:
    """``cell detect``'s table (and its json/csv rows); in table form also the located ends and sigma in the
    report's frame [mm]."""
    from rich.table import Table

    from cell.cli.printout.tables import print_detection

    table_fmt = parse_format(fmt)
    print_detection(rep, table_fmt)
    found = [s for s in rep["seams"] if s["status"] == "found" and not s.get("curved")]  # a curve: its own line
    if table_fmt != "table" or not found:
        return
    t = Table(title=f"located seams · frame {rep['frame']} · mm", title_justify="left")
    for col in ("seam", "start x y z", "end x y z", "sigma"):
        t.add_column(col, justify="left" if col == "seam" else "right")
    for s in found:
        ends = [" ".join(f"{v * 1e3:.1f}" for v in s["detected"][k]) for k in ("start", "end")]
        t.add_row(s["id"], *ends, f"{s['sigma_mm']:.2f}" if s.get("sigma_mm") is not None else "-")
    out.print(t)
