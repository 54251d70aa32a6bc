"""The cell a capture was taken in: ``cell.yaml`` written from a scenario (without ``simulation:``, the map copied
beside it), and the scenario a replay runs (that file, or a cell synthesised around the map for a capture with
none). Frames: W the capture's world, R its robot base, M the map."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from cell.errors import CaptureError, UsageError
from cell.geometry import FloatArray, matrix_to_rpy
from cell.recorded.layout import CELL, RecordedCapture
from cell.scenario import Scenario, from_dict

TABLE_THICKNESS_M = 0.10  # the synthesised table under the part [m]
TABLE_MARGIN_M = 0.2  # table beyond the part on each side [m]
WORKSPACE_MARGIN_M = 0.15  # the crop beyond the part in x and y [m] (as cell init lays it out)
WORKSPACE_ABOVE_TABLE_M = 0.005  # the crop's floor above the table top: the table is cropped away [m]
WORKSPACE_ABOVE_PART_M = 0.2  # the crop's ceiling above the part's top [m]
TARGET_AHEAD_M = 1.0  # a synthesised camera's target: this far along its optical axis [m]


class _FlowDumper(yaml.SafeDumper):
    """YAML with lists of numbers on one line (``[0.15, -1.05, 0.9]``) and keys in the model's order."""


def _list(dumper: yaml.SafeDumper, data: list[Any]) -> yaml.Node:
    flow = all(isinstance(v, int | float) and not isinstance(v, bool) for v in data)
    return dumper.represent_sequence("tag:yaml.org,2002:seq", data, flow_style=flow)


_FlowDumper.add_representer(list, _list)


def cell_yaml(scenario: Scenario, *, source: str = "") -> str:
    """``scenario`` as the text of a capture's ``cell.yaml``: no ``simulation:``, ``map.file`` the map's file name
    (copy :attr:`Scenario.map_path` beside it). Floats are written as Python's repr, so they read back exactly."""
    data = scenario.model_dump(mode="json", exclude={"simulation", "base_dir"}, exclude_defaults=True)
    data["map"]["file"] = scenario.map_path.name
    head = (
        f"# The cell this capture was taken in{f' (scenario {source})' if source else ''}: what the cell is told,\n"
        "# without the scenario's simulation: section (docs/capture.md). Its map lies beside this file.\n"
    )
    return head + yaml.dump(data, Dumper=_FlowDumper, sort_keys=False, allow_unicode=True)


def _pose_spec(X: FloatArray) -> dict[str, list[float]]:
    return {"xyz_m": [float(v) for v in X[:3, 3]], "rpy_deg": [math.degrees(a) for a in matrix_to_rpy(X[:3, :3])]}


def replay_scenario(rec: RecordedCapture, *, map_path: Path | None = None, X_RM: FloatArray | None = None) -> Scenario:
    """The scenario ``cell detect --capture`` runs on ``rec``.

    map_path : a welding map (DXF) instead of the one ``cell.yaml`` names. X_RM : (4, 4) the map's nominal pose in
    the capture's robot frame R instead of ``cell.yaml``'s (the scenario's X_WM is then X_WR @ X_RM). Without a
    ``cell.yaml`` both are needed (UsageError otherwise) and the cell is synthesised (:func:`synthesised`).
    """
    if rec.cell_yaml is None:
        if map_path is None or X_RM is None:
            raise UsageError(
                f"capture {rec.folder} has no {CELL} (a capture from a bag): --map and --place (or --place-rpy) "
                "are needed; valid: --map MAP.dxf --place X,Y,Z,YAW"
            )
        return synthesised(rec, map_path, X_RM)
    source = str(rec.folder / CELL)
    try:
        data = yaml.safe_load(rec.cell_yaml)
    except yaml.YAMLError as e:
        raise CaptureError(
            f"{source} is not valid YAML ({e}); valid: a scenario (docs/scenarios.md)", path=source
        ) from None
    if not isinstance(data, dict) or not isinstance(data.get("map"), dict):
        raise CaptureError(f"{source} is not a scenario with a map: section; valid: docs/scenarios.md", path=source)
    data.pop("simulation", None)  # a replay simulates nothing (a hand-edited cell.yaml may still hold one)
    if map_path is not None:
        data["map"]["file"] = str(map_path.resolve())
    if X_RM is not None:
        data["map"]["X_WM"] = _pose_spec(rec.X_WR @ X_RM)
    scenario = from_dict(data, rec.folder, source)
    if not np.allclose(scenario.X_WR, rec.X_WR, rtol=0.0, atol=1e-9):
        raise CaptureError(
            f"{source}: robot.X_WR disagrees with the capture's X_WR; valid: the pose capture.json records",
            path=source,
        )
    unknown = [name for name in rec.images if name not in scenario.cameras]
    if unknown:  # its calibration and mount would be unknown: refuse rather than guess
        raise CaptureError(
            f"{source}: camera(s) {', '.join(unknown)} of the capture are not in its cameras; valid: "
            f"{', '.join(scenario.cameras)}",
            path=source,
        )
    return scenario


def synthesised(rec: RecordedCapture, map_path: Path, X_RM: FloatArray) -> Scenario:
    """A cell around the map placed at X_RM (frame R) for a capture without ``cell.yaml``: the table under the
    part (its top at the part's lowest point, the footprint grown by 0.2 m a side), the crop the part's bounds
    grown by 0.15 m in x and y, from 5 mm above the table to 0.2 m above the part, the capture's cameras (each
    image carries its own pose and intrinsics), no robot model (a capture cannot move one), seed 1."""
    from cell.weldmap import read_map

    weldmap = read_map(map_path)
    X_WM = rec.X_WR @ X_RM
    v_W = np.vstack([p.transformed(X_WM).vertices() for p in weldmap.parts])
    lo, hi = v_W.min(axis=0), v_W.max(axis=0)
    centre = (lo + hi) / 2.0
    size = hi[:2] - lo[:2] + 2.0 * TABLE_MARGIN_M
    cameras = {}
    for name, image in rec.images.items():
        X_WC = np.asarray(image.X_WC)
        intr = image.intrinsics
        cameras[name] = {
            "mount": image.mount,
            "eye_m": [float(v) for v in X_WC[:3, 3]],
            "target_m": [float(v) for v in X_WC[:3, 3] + TARGET_AHEAD_M * X_WC[:3, 2]],
            "up": [float(v) for v in -X_WC[:3, 1]],  # the image's up is the optical frame's -y
            "resolution": [intr.width, intr.height],
            "hfov_deg": math.degrees(2.0 * math.atan(intr.width / (2.0 * intr.fx))),
        }
    data = {
        "name": f"capture {rec.folder.name}",
        "description": f"synthesised around {map_path.name} for the capture {rec.folder}",
        "seed": 1,
        "map": {"file": str(map_path.resolve()), "X_WM": _pose_spec(X_WM)},
        "table": {
            "center_m": [float(centre[0]), float(centre[1]), float(lo[2] - TABLE_THICKNESS_M / 2.0)],
            "size_m": [float(size[0]), float(size[1]), TABLE_THICKNESS_M],
        },
        "robot": {"X_WR": _pose_spec(rec.X_WR)},
        "cameras": cameras,
        "perception": {
            "workspace": {
                "min_m": [*(float(v) for v in lo[:2] - WORKSPACE_MARGIN_M), float(lo[2] + WORKSPACE_ABOVE_TABLE_M)],
                "max_m": [*(float(v) for v in hi[:2] + WORKSPACE_MARGIN_M), float(hi[2] + WORKSPACE_ABOVE_PART_M)],
            }
        },
    }
    return from_dict(data, rec.folder, f"the cell synthesised for {rec.folder}")
