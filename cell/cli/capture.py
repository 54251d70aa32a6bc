"""``cell capture``: what the cameras of a cell saw, written as a capture folder (docs/capture.md); and the replay
half of ``cell detect --capture DIR`` (:func:`replay`): the scenario and the recorded-data station of a folder.

The replay path never imports the simulator: ``cell.recorded`` and ``cell.station.recorded`` are kept free of it
(an import-linter contract), and :func:`replay` imports nothing else.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from cell.cli.common import (
    CalibrationOpt,
    NoiseOpt,
    app,
    cell_errors,
    detail,
    err,
    load_scenario,
    log,
    parse_noise,
    say,
)
from cell.cli.outputs import check_folder
from cell.cli.placement import placement
from cell.errors import CellError, OutputError, UsageError

if TYPE_CHECKING:
    from cell import pipeline
    from cell.scenario import Scenario
    from cell.station.recorded import RecordedStation


def warn(msg: str) -> None:
    """A warning line on stderr (also with --quiet: it says the output is not what was asked) and the log."""
    log.warning(msg)
    err.print(f"warning: {msg}", soft_wrap=True, markup=False, highlight=False)


@app.command("capture")
def capture(
    scenario: Annotated[
        str | None, typer.Argument(help="A scenario name (see `cell scenarios`) or a YAML path to capture.")
    ] = None,
    out_dir: Annotated[Path | None, typer.Option("--out", help="The capture folder to write (created).")] = None,
    from_bag: Annotated[
        Path | None, typer.Option("--from-bag", help="Convert this ROS 2 bag instead of simulating SCENARIO.")
    ] = None,
    noise: NoiseOpt = None,
    calibration: CalibrationOpt = None,
    depth_topic: Annotated[
        list[str] | None,
        typer.Option("--depth-topic", help="A bag's depth image topic to take (repeat; default: every one, by name)."),
    ] = None,
    base_frame: Annotated[
        str | None, typer.Option(help="The bag's robot base frame (default: base_link, else the tf tree's root).")
    ] = None,
    at_time: Annotated[
        float | None,
        typer.Option("--time", help="Take each camera's image nearest this time [s from the bag's start]."),
    ] = None,
    max_tf_gap: Annotated[
        float, typer.Option(help="Largest gap [s] between an image and the moving transform used for it.")
    ] = 0.1,
) -> None:
    """Write what the cameras saw as a capture folder: 16-bit depth PNGs, CameraInfo, poses, cell.yaml, truth.

    `cell detect --capture DIR` then runs the same pipeline on it, without the simulator.
    """
    with cell_errors():
        if out_dir is None:
            raise UsageError("--out DIR is missing; valid: cell capture SCENARIO --out DIR")
        if (scenario is None) == (from_bag is None):
            raise UsageError("give SCENARIO or --from-bag BAG (one of them); valid: cell capture fence1 --out DIR")
        if from_bag is not None and noise is not None:
            raise UsageError("--noise simulates a sensor; a bag holds what its cameras saw; valid: leave it out")
        if from_bag is not None and calibration is not None:
            raise UsageError("--calibration goes with SCENARIO; a bag's tf tree holds its cameras' poses")
        bag_only = {"--depth-topic": depth_topic, "--base-frame": base_frame, "--time": at_time}
        if from_bag is None and (given := [k for k, v in bag_only.items() if v is not None]):
            raise UsageError(f"{', '.join(given)} only apply to --from-bag BAG; valid: leave them out for SCENARIO")
        if max_tf_gap <= 0.0:
            raise UsageError(f"--max-tf-gap {max_tf_gap}; valid: a positive number of seconds")
        check_folder(out_dir, "--out")
        t0 = time.perf_counter()
        if from_bag is not None:
            options = {"depth_topics": depth_topic, "base_frame": base_frame, "time": at_time}
            folder = _from_bag(from_bag, out_dir, max_tf_gap_s=max_tf_gap, **options)
        else:
            assert scenario is not None
            folder = _simulated(scenario, out_dir, parse_noise(noise), calibration)
        say(f"capture written to {folder} ({time.perf_counter() - t0:.1f} s)")


def _from_bag(bag: Path, out_dir: Path, **options: Any) -> Path:
    from cell.recorded.bag import capture_from_bag

    return capture_from_bag(bag, out_dir, progress=say, **options)


def _simulated(name: str, out_dir: Path, noise: Any, calibration: Path | None = None) -> Path:
    from cell import scenario as sc
    from cell.provenance import provenance

    scn = load_scenario(name, calibration)
    scn = scn.with_noise(noise) if noise else scn
    prov = provenance(scn, scenario_file=sc.resolve(name))
    if calibration is not None:  # the capture records which calibration its poses came from
        prov["calibration"] = str(calibration.resolve())
    detail(f"scenario {prov['scenario_file']} (sha256 {prov['scenario_sha256']}), map {prov['map_file']}")
    return write_simulated(scn, out_dir, source=name, provenance=prov)


def write_simulated(
    scn: Scenario, out_dir: Path, *, source: str = "", provenance: dict[str, Any] | None = None
) -> Path:
    """Simulate the scenario's cell, capture with every camera (the arm at its scan pose: the eye-in-hand camera's
    flange pose is recorded) and write the capture folder with its cell.yaml, map and truth; returns the folder."""
    from cell import pipeline
    from cell.pipeline.geometry import open_cell

    weldmap = pipeline.read_weldmap(scn)
    say(f"building the cell of {scn.name}")
    with open_cell(scn, weldmap) as station:
        cap = pipeline.capture(scn, station=station, weldmap=weldmap, progress=say)
        flange = {}
        if station.arm is not None:  # the arm holds the eye-in-hand cameras where it is now (its scan pose)
            X_RF = station.arm.model.fk(station.joint_state(), "tool0")
            flange = {n: X_RF for n, im in cap.images.items() if im.mount == "eye_in_hand"}
    try:
        return _write(out_dir, cap, scn, source, provenance, flange)
    except OSError as e:  # the folder was checked before the run: a disk that filled, a folder removed meanwhile
        if isinstance(e, CellError):
            raise
        raise OutputError(f"--out {str(out_dir)!r}: cannot write ({e.strerror or e})", path=str(out_dir)) from None


def _write(
    out_dir: Path,
    cap: pipeline.Capture,
    scn: Scenario,
    source: str,
    provenance: dict[str, Any] | None,
    flange: dict[str, Any],
) -> Path:
    from cell.recorded.cell_file import cell_yaml
    from cell.recorded.layout import write_capture

    # The noise model quantises each camera's depth to its depth_unit_m: the PNG is written at that scale, so the
    # replay reads back the very floats (a depth off that grid is rounded to 0.1 mm, and write_capture warns).
    scales = {n: scn.cameras[n].noise.depth_unit_m if scn.noise == "realistic" else 0.0 for n in cap.images}
    return write_capture(
        out_dir,
        cap.images,
        scn.X_WR,
        cell_yaml=cell_yaml(scn, source=source),
        map_file=scn.map_path,
        truth_parts_W=cap.parts_W,
        provenance=provenance,
        flange=flange,
        depth_scale_m=scales,
        warn=warn,
    )


def replay(
    scenario: str | None,
    folder: Path,
    map_path: Path | None,
    place: str | None,
    place_rpy: str | None,
    noise: str | None,
) -> tuple[Scenario, RecordedStation, Path | None]:
    """``cell detect --capture``: (the scenario, the recorded station, the cell.yaml it came from or None).

    ``--map`` / ``--place`` override the map and its placement (X_RM, in the capture's robot frame R); a capture
    without cell.yaml needs both. CaptureError (exit 16) for a folder that cannot be read.
    """
    from cell.recorded.cell_file import replay_scenario
    from cell.recorded.layout import CELL
    from cell.station.recorded import RecordedStation

    if scenario is not None:
        raise UsageError(f"SCENARIO {scenario!r} and --capture both given; valid: one (the capture holds its cell)")
    if noise is not None:
        raise UsageError("--noise simulates a sensor; a capture holds what its cameras saw; valid: leave it out")
    X_RM = placement(place, place_rpy)
    if map_path is not None and not map_path.is_file():
        raise UsageError(f"--map {str(map_path)!r} is not a file; valid: a DXF welding map")
    station = RecordedStation.open(folder)
    rec = station.recorded
    truth = "with" if rec.truth_parts_W is not None else "without"
    say(f"replaying the capture {folder}: {', '.join(rec.images)}, {truth} ground truth (no simulator)")
    scn = replay_scenario(station.recorded, map_path=map_path, X_RM=X_RM)
    cell_file = folder / CELL if station.recorded.cell_yaml is not None else None
    return scn, station, cell_file
