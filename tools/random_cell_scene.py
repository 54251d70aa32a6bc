"""The cell around a generated weldment (used by ``tools/random_cells.py``): where the part lies on the table, the
robot, the fixed cameras and the arm camera's scan pose, the sensors' noise and calibration, written as a scenario.

The table, the robot's base and home, and the workspace follow ``cell init`` (``cell/scenario/init.py``: the
shipped fences' cell, laid out around the part). World frame W [m], z up, the table top at ``TABLE_TOP_M``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from cell.geometry import rot_z
from cell.scenario.camera_layout import CAMERA_ABOVE_TOP_M, CAMERA_SIDE_M
from cell.scenario.init import (
    EYE_IN_HAND_ABOVE_TOP_M,
    EYE_IN_HAND_FRONT_M,
    PART_CENTRE_XY_M,
    ROBOT_BEHIND_EDGE_M,
    ROBOT_HOME_DEG,
    TABLE_MARGIN_M,
    TABLE_MIN_SIZE_M,
    TABLE_THICKNESS_M,
    TABLE_TOP_M,
    WORKSPACE_ABOVE_PART_M,
    WORKSPACE_ABOVE_TABLE_M,
    WORKSPACE_MARGIN_M,
    WORKSPACE_ROUND_M,
)
from cell.types import WeldMap

CAMERA_DISTANCE_M = (0.8, 2.2)  # fixed camera to the part's centre [m]
CAMERA_ELEVATION_DEG = (25.0, 75.0)  # above the table's plane, seen from the part's centre [deg]
REACH_M = (0.45, 1.25)  # horizontal distance from the robot base a seam end may lie at [m]
TABLE_EDGE_M = 0.05  # the part stays this far inside the table's edge [m]
# Calibration residuals of a real cell (docs/reference.md section 2: 0.3-1 mm, 0.03-0.1 deg).
EXTRINSIC_MM = (0.3, 1.0)
EXTRINSIC_DEG = (0.03, 0.1)


@dataclass(frozen=True)
class Camera:
    """One camera of the cell: where it is and looks [m, W], its sensor model, its drawn extrinsic error and the
    calibration the cell is told (both translation [mm], rotation [deg]); distance and angles from the target."""

    name: str
    mount: str
    eye_m: tuple[float, float, float]
    target_m: tuple[float, float, float]
    up: tuple[float, float, float]
    model: str
    error: tuple[float, float]
    calibration: tuple[float, float]

    @property
    def distance_m(self) -> float:
        return math.dist(self.eye_m, self.target_m)

    @property
    def elevation_deg(self) -> float:
        d = np.subtract(self.eye_m, self.target_m)
        return math.degrees(math.atan2(d[2], math.hypot(d[0], d[1])))

    @property
    def azimuth_deg(self) -> float:
        d = np.subtract(self.eye_m, self.target_m)
        return math.degrees(math.atan2(d[1], d[0])) % 360.0


@dataclass(frozen=True)
class Placement:
    """The part on the table: the drawing's origin at ``xyz_m`` turned ``yaw_deg`` about z; the part's bounds in W,
    the table (centre, size) and the robot base, all [m]."""

    xyz_m: tuple[float, float, float]
    yaw_deg: float
    lo_W: np.ndarray
    hi_W: np.ndarray
    table_center: tuple[float, float, float]
    table_size: tuple[float, float, float]
    robot_xyz: tuple[float, float, float]

    @property
    def centre_W(self) -> np.ndarray:
        return (self.lo_W + self.hi_W) / 2.0

    @property
    def X_WM(self) -> np.ndarray:
        X = np.eye(4)
        X[:3, :3], X[:3, 3] = rot_z(math.radians(self.yaw_deg)), self.xyz_m
        return X


def r6(x: float) -> float:
    """A number as written to the scenario and the truth: rounded to 6 decimals, no negative zero."""
    return round(float(x), 6) + 0.0


def t3(v: Any) -> tuple[float, float, float]:
    a = np.asarray(v, dtype=float).reshape(3)
    return (r6(a[0]), r6(a[1]), r6(a[2]))


def place(weldmap: WeldMap, yaw_deg: float, rng: np.random.Generator | None) -> Placement | None:
    """The part turned ``yaw_deg`` and set on the table: at cell init's place (centre at (0.15, 0)) when ``rng`` is
    None, else at a random place on the table whose seam ends all lie within :data:`REACH_M` of the robot base
    (None when 50 draws find none). The table and robot are cell init's for the turned part's footprint."""
    R = rot_z(math.radians(yaw_deg))
    v = np.vstack([p.vertices() for p in weldmap.parts]) @ R.T
    lo, hi = v.min(axis=0), v.max(axis=0)
    half = (hi - lo) / 2.0
    size_xy = np.maximum(np.array(TABLE_MIN_SIZE_M), 2.0 * half[:2] + 2.0 * TABLE_MARGIN_M)
    cx, cy = PART_CENTRE_XY_M
    table_center = (cx, cy, TABLE_TOP_M - TABLE_THICKNESS_M / 2.0)
    table_size = (r6(size_xy[0]), r6(size_xy[1]), TABLE_THICKNESS_M)
    robot = np.array([cx, cy - size_xy[1] / 2.0 - ROBOT_BEHIND_EDGE_M, TABLE_TOP_M])
    ends = np.array([p for s in weldmap.seams for p in (s.p_start, s.p_end)]) @ R.T
    for _ in range(50 if rng is not None else 1):
        if rng is None:
            centre = np.array([cx, cy])
        else:
            room = size_xy / 2.0 - half[:2] - TABLE_EDGE_M
            if np.any(room < 0.0):
                return None
            centre = np.array([cx, cy]) + rng.uniform(-room, room)
        xyz = np.array([*(centre - (lo[:2] + hi[:2]) / 2.0), TABLE_TOP_M - lo[2]])
        reach = np.linalg.norm(ends[:, :2] + xyz[:2] - robot[:2], axis=1)
        if rng is None or (reach.min() >= REACH_M[0] and reach.max() <= REACH_M[1]):
            return Placement(t3(xyz), yaw_deg, lo + xyz, hi + xyz, table_center, table_size, t3(robot))
    return None


def fixed_cameras(
    placement: Placement, rng: np.random.Generator, count: int, azimuth0: float | None = None
) -> list[tuple[np.ndarray, np.ndarray]]:
    """``count`` (eye, target) pairs [m, W] looking at the part's centre from random distances and elevations in
    their ranges; any azimuth, or evenly around from ``azimuth0`` [deg]."""
    target = placement.centre_W
    out = []
    for k in range(count):
        d = rng.uniform(*CAMERA_DISTANCE_M)
        el = math.radians(rng.uniform(*CAMERA_ELEVATION_DEG))
        az = math.radians(rng.uniform(0.0, 360.0) if azimuth0 is None else azimuth0 + 360.0 * k / count)
        eye = target + d * np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])
        out.append((eye, target.copy()))
    return out


def init_cameras(placement: Placement) -> list[tuple[np.ndarray, np.ndarray]]:
    """cell init's pair of portrait cameras (one each side of the part along x, 1 m above its top)."""
    c, top = placement.centre_W, placement.hi_W[2]
    target = np.array([c[0], c[1], c[2]])
    return [(np.array([c[0] + s * CAMERA_SIDE_M, c[1], top + CAMERA_ABOVE_TOP_M]), target) for s in (-1.0, 1.0)]


def scan_pose(placement: Placement, rng: np.random.Generator | None) -> tuple[np.ndarray, np.ndarray]:
    """The arm camera's scan pose (eye, target) [m, W]: above the part, towards the robot from its centre (cell
    init's 0.45 m and 1.05 m above its top; random 0.3-0.5 m and 0.85-1.1 m with an rng)."""
    c, lo, hi = placement.centre_W, placement.lo_W, placement.hi_W
    toward = np.asarray(placement.robot_xyz[:2]) - c[:2]
    toward /= max(float(np.linalg.norm(toward)), 1e-9)
    if rng is None:
        front, above, toward = EYE_IN_HAND_FRONT_M, EYE_IN_HAND_ABOVE_TOP_M, np.array([0.0, -1.0])
    else:
        front, above = rng.uniform(0.3, 0.5), rng.uniform(0.85, 1.1)
    eye = np.array([*(c[:2] + front * toward), hi[2] + above])
    return eye, np.array([c[0], c[1], lo[2] + 0.4 * (hi[2] - lo[2])])


def workspace(placement: Placement) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    """cell init's crop: the part's bounds grown by 0.15 m in x, y (rounded out to 5 cm), from 5 mm above the table
    to 0.2 m above the part [m, W]."""
    step = WORKSPACE_ROUND_M
    lo = np.floor((placement.lo_W[:2] - WORKSPACE_MARGIN_M) / step + 1e-9) * step
    hi = np.ceil((placement.hi_W[:2] + WORKSPACE_MARGIN_M) / step - 1e-9) * step
    return t3([*lo, TABLE_TOP_M + WORKSPACE_ABOVE_TABLE_M]), t3([*hi, placement.hi_W[2] + WORKSPACE_ABOVE_PART_M])


def camera_entry(cam: Camera) -> dict[str, Any]:
    """A camera's scenario keys."""
    entry: dict[str, Any] = {"mount": cam.mount, "eye_m": list(cam.eye_m), "target_m": list(cam.target_m)}
    if cam.up != (0.0, 0.0, 1.0):
        entry["up"] = list(cam.up)
    entry["noise"] = {"model": cam.model}
    entry["extrinsic_error"] = {"translation_mm": cam.error[0], "rotation_deg": cam.error[1]}
    entry["calibration"] = {"translation_mm": cam.calibration[0], "rotation_deg": cam.calibration[1]}
    return entry


def scenario_dict(
    name: str,
    seed: int,
    map_file: str,
    placement: Placement,
    cameras: list[Camera],
    simulation: dict[str, Any],
    description: str,
) -> dict[str, Any]:
    """The scenario as a mapping (written as YAML next to its map)."""
    lo, hi = workspace(placement)
    return {
        "name": name,
        "description": description,
        "seed": seed,
        "map": {
            "file": map_file,
            "X_WM": {"xyz_m": list(placement.xyz_m), "rpy_deg": [0.0, 0.0, r6(placement.yaw_deg)]},
        },
        "table": {"center_m": list(t3(placement.table_center)), "size_m": list(placement.table_size)},
        "robot": {
            "urdf": "kr5_arc.urdf",
            "X_WR": {"xyz_m": list(placement.robot_xyz)},
            "home_deg": list(ROBOT_HOME_DEG),
        },
        "cameras": {c.name: camera_entry(c) for c in cameras},
        "perception": {"workspace": {"min_m": list(lo), "max_m": list(hi)}},
        "simulation": simulation,
    }
