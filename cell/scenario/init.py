"""A scenario for any welding map (``cell init``): the cell laid out around the part's bounds as the shipped fence
scenarios are around theirs, as YAML with a comment on every key; an exact build, no faults (the layout rules:
docs/cell.md, "Your own part")."""

from __future__ import annotations

import json
import math
import os
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from cell.geometry import FloatArray
from cell.scenario.camera_layout import (
    CAMERA_SECTION_M,
    CAMERA_UP,
    FaceSight,
    camera_candidates,
    choose_cameras,
)
from cell.scenario.model import MAP_DIR, Scenario
from cell.types import WeldMap
from cell.weldmap import read_map

PART_CENTRE_XY_M = (0.15, 0.0)  # where the part's centre goes in the world [m]
TABLE_TOP_M = 0.90  # table-top height [m]
TABLE_THICKNESS_M = 0.10
TABLE_MIN_SIZE_M = (2.0, 1.2)  # the shipped scenarios' table [m]
TABLE_MARGIN_M = 0.2  # table beyond the part on each side [m]
ROBOT_BEHIND_EDGE_M = 0.45  # robot base in front of the table's near edge [m]
ROBOT_URDF = "kr5_arc.urdf"  # in the repository's robots/ folder
ROBOT_HOME_DEG = (-90.0, -100.0, 100.0, 0.0, 45.0, 0.0)  # arm over the table, torch well above the parts
REACH_M = 1.45  # horizontal base-to-seam distance the shipped fences still weld at [m]
_CALIBRATION = "    calibration: {translation_mm: 0.0, rotation_deg: 0.0}"
_CALIBRATION_NOTE = "RMS residual from your calibration report: seams seen by it alone carry it in sigma"
EYE_IN_HAND_ABOVE_TOP_M = 1.05
EYE_IN_HAND_FRONT_M = 0.45
WORKSPACE_MARGIN_M = 0.15
WORKSPACE_ROUND_M = 0.05
WORKSPACE_ABOVE_TABLE_M = 0.005
WORKSPACE_ABOVE_PART_M = 0.2


@dataclass(frozen=True)
class Layout:
    """Where everything goes for one map, in the world [m]: the numbers the scenario file is written from.

    lo_W, hi_W : (3,) the part's nominal bounds in the world. X_WM_xyz : the drawing's origin in the world.
    cameras : name -> (eye, target); the eye-in-hand camera separately. far_seam_m : the horizontal distance
    of the farthest seam end from the robot base. closeup_only : the seams whose faces no camera of the first scan
    could see from where this layout may put one (only the close-up will); None: the cameras were not chosen by
    what they see (the shipped pair per section).
    """

    X_WM_xyz: FloatArray
    lo_W: FloatArray
    hi_W: FloatArray
    table_center: FloatArray
    table_size: FloatArray
    X_WR_xyz: FloatArray
    cameras: dict[str, tuple[FloatArray, FloatArray]]
    eye_in_hand: tuple[FloatArray, FloatArray]
    workspace: tuple[FloatArray, FloatArray]
    far_seam_m: float
    closeup_only: tuple[str, ...] | None = None

    @property
    def unreachable_risk(self) -> bool:
        """Some seam is farther from the base than the shipped cells weld at."""
        return self.far_seam_m > REACH_M


def _round_out(lo: FloatArray, hi: FloatArray, step: float) -> tuple[FloatArray, FloatArray]:
    return np.floor(lo / step + 1e-9) * step, np.ceil(hi / step - 1e-9) * step


def layout(weldmap: WeldMap, sight: FaceSight | None = None) -> Layout:
    """The cell laid out around ``weldmap``'s parts (frame M, metres) as the module docstring says; the fixed
    cameras chosen by the seams' faces they see when ``sight`` is given, else the shipped pair per section."""
    v_M = np.vstack([p.vertices() for p in weldmap.parts])
    lo_M, hi_M = v_M.min(axis=0), v_M.max(axis=0)
    centre_M = (lo_M + hi_M) / 2.0
    X_WM_xyz = np.array([PART_CENTRE_XY_M[0] - centre_M[0], PART_CENTRE_XY_M[1] - centre_M[1], TABLE_TOP_M - lo_M[2]])
    lo_W, hi_W = lo_M + X_WM_xyz, hi_M + X_WM_xyz
    cx, cy = PART_CENTRE_XY_M
    extent = hi_W - lo_W
    size_xy = np.maximum(np.array(TABLE_MIN_SIZE_M), extent[:2] + 2.0 * TABLE_MARGIN_M)
    table_center = np.array([cx, cy, TABLE_TOP_M - TABLE_THICKNESS_M / 2.0])
    table_size = np.array([size_xy[0], size_xy[1], TABLE_THICKNESS_M])
    X_WR_xyz = np.array([cx, cy - size_xy[1] / 2.0 - ROBOT_BEHIND_EDGE_M, TABLE_TOP_M])

    mid_z = (lo_W[2] + hi_W[2]) / 2.0
    n = max(1, math.ceil(extent[0] / CAMERA_SECTION_M - 1e-9))
    sections = [np.array([lo_W[0] + (i + 0.5) * extent[0] / n, cy, mid_z]) for i in range(n)]
    eye_in_hand = (
        np.array([cx, cy - EYE_IN_HAND_FRONT_M, hi_W[2] + EYE_IN_HAND_ABOVE_TOP_M]),
        np.array([cx, cy, lo_W[2] + 0.4 * extent[2]]),  # a little below mid-height, as in the shipped fences
    )
    closeup_only: tuple[str, ...] | None = None
    if sight is None:
        cameras: dict[str, tuple[FloatArray, FloatArray]] = {}
        for i, target in enumerate(sections):
            for name, eye, t in camera_candidates(target, hi_W[2], "" if n == 1 else f"_{i + 1}")[1::-1]:
                cameras[name] = (eye, t)
    else:
        X_WM = np.eye(4)
        X_WM[:3, 3] = X_WM_xyz
        map_W = weldmap.transformed(X_WM, "W")
        cameras, eye_in_hand, closeup_only = choose_cameras(map_W, TABLE_TOP_M, sections, hi_W[2], eye_in_hand, sight)
    ws_lo, ws_hi = _round_out(lo_W[:2] - WORKSPACE_MARGIN_M, hi_W[:2] + WORKSPACE_MARGIN_M, WORKSPACE_ROUND_M)
    workspace = (
        np.array([*ws_lo, TABLE_TOP_M + WORKSPACE_ABOVE_TABLE_M]),
        np.array([*ws_hi, hi_W[2] + WORKSPACE_ABOVE_PART_M]),
    )
    ends_W = np.array([p for s in weldmap.seams for p in (s.p_start, s.p_end)]) + X_WM_xyz
    far = float(np.linalg.norm(ends_W[:, :2] - X_WR_xyz[:2], axis=1).max()) if len(ends_W) else 0.0
    return Layout(
        X_WM_xyz, lo_W, hi_W, table_center, table_size, X_WR_xyz, cameras, eye_in_hand, workspace, far, closeup_only
    )


def _str(s: str) -> str:
    """A YAML scalar for ``s``: plain when that is safe, else double-quoted (JSON's quoting is YAML's)."""
    return s if re.fullmatch(r"[A-Za-z0-9_][A-Za-z0-9_./-]*", s) else json.dumps(s)


def _num(x: float) -> str:
    return repr(float(round(float(x), 4)) + 0.0)


def _vec(v: FloatArray | tuple[float, ...]) -> str:
    return "[" + ", ".join(_num(x) for x in v) + "]"


def map_reference(map_path: Path, scenario_dir: Path) -> str:
    """What to write as ``map.file``: relative to the scenario when the map lies in its folder (or below), the
    bare name when it is the repository's ``maps/`` copy (found there by name), else the absolute path."""
    map_path, scenario_dir = map_path.resolve(), scenario_dir.resolve()
    if map_path.is_relative_to(scenario_dir):
        return map_path.relative_to(scenario_dir).as_posix()
    if map_path == (MAP_DIR / map_path.name).resolve():
        return map_path.name
    return os.fspath(map_path)


def _side(d: FloatArray) -> str:
    """Where a camera stands from the point it looks at, in words: ``+x``, ``-x +y`` ... (the robot is at -y)."""
    words = [f"{'+' if d[k] > 0 else '-'}{'xy'[k]}" for k in (0, 1) if abs(d[k]) > 0.1 * float(np.hypot(d[0], d[1]))]
    return " ".join(words) + (" (the robot's side)" if d[1] < -0.1 * float(np.hypot(d[0], d[1])) else "")


def _lines(name: str, map_file: str, units: str | None, weldmap: WeldMap, lay: Layout) -> list[tuple[str, str]]:
    """(YAML line, its comment) pairs, in file order."""
    parts = ", ".join(p.name for p in weldmap.parts)
    lo, hi = lay.workspace
    rows: list[tuple[str, str]] = [
        (f"name: {_str(name)}", "shown in reports"),
        (f"description: {_str(f'Written by cell init for {Path(map_file).name}')}", "one line for `cell scenarios`"),
        ("seed: 1", "every random draw (sensor noise, RANSAC) derives from it"),
        ("map:", "the welding map and where the cell is told it lies"),
        (f"  file: {_str(map_file)}", "looked for beside this file, then by name in the repository's maps/"),
    ]
    if units is not None:
        rows.append((f"  units: {units}", "the drawing declares no $INSUNITS: its units"))
    rows += [
        ("  X_WM:", "nominal pose of the drawing's origin in the world"),
        (f"    xyz_m: {_vec(lay.X_WM_xyz)}", "part centred at (0.15, 0.0), its underside on the table top [m]"),
        ("    rpy_deg: [0.0, 0.0, 0.0]", "roll, pitch, yaw [deg]: as drawn"),
        ("table:", "the welding table, a box"),
        (f"  center_m: {_vec(lay.table_center)}", "its centre in the world [m]"),
        (f"  size_m: {_vec(lay.table_size)}", "the part's footprint + 0.2 m a side, at least 2.0 x 1.2 [m]"),
        ("robot:", "a KUKA KR 5 arc on a pedestal in front of the table, facing +y"),
        (f"  urdf: {ROBOT_URDF}", "in the repository's robots/ folder"),
        ("  X_WR:", "pose of the robot base in the world"),
        (f"    xyz_m: {_vec(lay.X_WR_xyz)}", "0.45 m before the table's near edge, at table-top height [m]"),
        (f"  home_deg: {_vec(ROBOT_HOME_DEG)}", "joints A1-A6 [deg]: arm over the table, torch well above"),
        ("cameras:", "depth cameras (1280 x 720, 65 deg field unless given)"),
    ]
    for cam, (eye, target) in lay.cameras.items():
        rows += [
            (f"  {cam}:", f"a fixed camera looking down at the part from {_side(eye - target)}"),
            (f"    eye_m: {_vec(eye)}", "where it is [m]"),
            (f"    target_m: {_vec(target)}", "the point it looks at [m]"),
            (f"    up: {_vec(CAMERA_UP)}", "portrait: the image's up is +y, its long side along x"),
            (_CALIBRATION, _CALIBRATION_NOTE),
        ]
    eye, target = lay.eye_in_hand
    rows += [
        ("  eye_in_hand:", "the camera on the arm: close-up re-scans and this scan pose"),
        ("    mount: eye_in_hand", "rides on the arm; the arm is solved for the pose below"),
        (f"    eye_m: {_vec(eye)}", "scan pose: above and in front of the part's centre [m]"),
        (f"    target_m: {_vec(target)}", "the point it looks at [m]"),
        (_CALIBRATION, _CALIBRATION_NOTE),
        ("perception:", "how the clouds are cropped and processed"),
        ("  workspace:", "only points inside this box are kept"),
        (f"    min_m: {_vec(lo)}", "the part's bounds - 0.15 m; 5 mm above the table top [m]"),
        (f"    max_m: {_vec(hi)}", "the part's bounds + 0.15 m; 0.2 m above its top [m]"),
        ("simulation:", "what only a simulation knows (a real cell is told none of it)"),
        ("  noise: realistic", "simulated depth noise: realistic (RealSense D4xx model) | none"),
        ("  placement_error:", "where the part really lies relative to map.X_WM"),
        ("    xyz_m: [0.0, 0.0, 0.0]", "[m]: e.g. [0.005, -0.003, 0.0]"),
        ("    rpy_deg: [0.0, 0.0, 0.0]", "[deg]: e.g. [0.0, 0.0, 0.3]"),
        (
            "  deviations: {}",
            f"part -> as built minus drawn, e.g. {weldmap.parts[0].name}: {{size_mm: [2.0, 0.0, 0.0]}}"
            f" (parts: {parts})",
        ),
    ]
    return rows


def scenario_text(
    map_path: Path, scenario_path: Path, units: str | None = None, sight: FaceSight | None = None
) -> tuple[str, Layout]:
    """The YAML text of a scenario for ``map_path`` to be saved at ``scenario_path``, and its layout (its fixed
    cameras chosen by ``sight``: :func:`layout`).

    Raises MapError / MapUnitsError when the map cannot be read (``units`` is used when the DXF declares none).
    """
    weldmap = read_map(map_path, units=units)
    lay = layout(weldmap, sight)
    map_file = map_reference(map_path, scenario_path.parent)
    rows = _lines(scenario_path.stem, map_file, units if weldmap.units == units else None, weldmap, lay)
    width = max(len(line) for line, _ in rows) + 2
    head = [
        f"# A scenario for {map_path.name}, written by `cell init`: the cell laid out around the part's bounds",
        "# (cell/scenario/init.py says how). Every key is in docs/scenarios.md; check it with `cell scenario check`.",
    ]
    if lay.unreachable_risk:
        head.append(
            f"# Note: a seam lies {lay.far_seam_m:.2f} m from the robot base (the shipped cells weld up to "
            f"{REACH_M} m): it may be unreachable; move robot.X_WR or turn the part."
        )
    if lay.closeup_only:
        head.append(
            f"# Note: no fixed camera can see both faces of {', '.join(lay.closeup_only)} from around the part: only "
            "the close-up re-scan will (rescan.mode low re-scans a seam not found)."
        )
    body = [f"{line:<{width}}# {comment}" for line, comment in rows]
    return "\n".join([*head, *body]) + "\n", lay


def check_layout(scenario: Scenario, weldmap: WeldMap) -> list[str]:
    """What in a valid scenario would still spoil a run (one line each; empty when nothing does): the part at its
    nominal place (``map.X_WM``, frame M -> world) not on the table or not inside the workspace, seams beyond
    the reach the shipped cells weld at."""
    problems: list[str] = []
    map_W = weldmap.transformed(scenario.X_WM, "W")
    v_W = np.vstack([p.vertices() for p in map_W.parts])
    lo_W, hi_W = v_W.min(axis=0), v_W.max(axis=0)
    ws = scenario.perception.workspace
    tol = 1e-6
    if np.any(lo_W[:2] < np.array(ws.min_m[:2]) - tol) or np.any(hi_W[:2] > np.array(ws.max_m[:2]) + tol):
        problems.append(
            f"the part ({_vec(lo_W[:2])} to {_vec(hi_W[:2])} m in x, y) is not inside perception.workspace "
            f"({_vec(ws.min_m[:2])} to {_vec(ws.max_m[:2])}): the crop cuts it"
        )
    if hi_W[2] > ws.max_m[2] + tol or hi_W[2] < ws.min_m[2]:
        problems.append(f"the part's top (z {_num(hi_W[2])} m) is outside the workspace's z range")
    t = scenario.table
    t_lo = np.array(t.center_m[:2]) - np.array(t.size_m[:2]) / 2.0
    t_hi = np.array(t.center_m[:2]) + np.array(t.size_m[:2]) / 2.0
    if np.any(lo_W[:2] < t_lo - tol) or np.any(hi_W[:2] > t_hi + tol):
        problems.append("the part overhangs the table")
    if scenario.robot.urdf is not None and map_W.seams:
        ends_W = np.array([p for s in map_W.seams for p in (s.p_start, s.p_end)])
        far = float(np.linalg.norm(ends_W[:, :2] - np.array(scenario.robot.X_WR.xyz_m[:2]), axis=1).max())
        if far > REACH_M:
            problems.append(
                f"a seam lies {far:.2f} m from the robot base (the shipped cells weld up to {REACH_M} m): it may be "
                "unreachable"
            )
    return problems
