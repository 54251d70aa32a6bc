"""What ``cell scenario check`` finds in a scenario that loads but would spoil a run, one line each: a camera looking
away from the workspace or with the part beyond its range, a robot base tilted or facing away from the part, a
part drawn in the air above the table (or into it), a weld gate loosened by ``rescan.allow_loose_gate``, a seam's
leg for a seam the map does not have. Each line
names the key and what is valid there (docs/cell.md, "What the loader refuses and what scenario check warns of")."""

from __future__ import annotations

import itertools
import math

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray, invert, transform_points
from cell.scenario.cell_specs import CameraSpec
from cell.scenario.model import Scenario
from cell.types import WeldMap

ON_TABLE_M = 0.002  # a map whose lowest point is this close to the table top rests on it (as the simulation sets it)
UPRIGHT_DEG = 1.0  # a floor-standing robot's base tilted more than this is a typing error
FACING_DEG = 90.0  # the arm at home pointing further than this from the part faces away from it


def _vec(v: FloatArray | tuple[float, ...]) -> str:
    return "[" + ", ".join(f"{float(x):.2f}" for x in v) + "]"


def _in_image(cam: CameraSpec, p_W: FloatArray) -> tuple[npt.NDArray[np.bool_], FloatArray]:
    """(in the image's field, depth along the optical axis [m]) of each world point (n, 3)."""
    p_C = transform_points(invert(cam.X_WC), p_W)
    z = p_C[:, 2]
    w, h = cam.resolution
    with np.errstate(divide="ignore", invalid="ignore"):
        u, v = cam.fx_px * p_C[:, 0] / z, cam.fx_px * p_C[:, 1] / z
    return (z > 0) & (np.abs(u) <= w / 2.0) & (np.abs(v) <= h / 2.0), z


def _grid(lo: FloatArray, hi: FloatArray, n: int = 5) -> FloatArray:
    axes = [np.linspace(lo[k], hi[k], n) for k in range(3)]
    return np.array(list(itertools.product(*axes)), dtype=float)


def camera_problems(scenario: Scenario, weldmap_M: WeldMap) -> list[str]:
    """Fixed cameras that look away from the workspace, or see the part nearer than ``near_m`` or beyond
    ``far_m``: none of their pixels would reach the splice (the eye-in-hand camera's view is checked by its scan
    pose and the seams' sight lines)."""
    ws = scenario.perception.workspace
    box_W = _grid(np.array(ws.min_m), np.array(ws.max_m))
    part_W = np.vstack([p.vertices() for p in weldmap_M.transformed(scenario.X_WM, "W").parts])
    centre = np.mean([ws.min_m, ws.max_m], axis=0)
    problems = []
    for name, cam in scenario.cameras.items():
        if cam.mount != "fixed":
            continue
        seen, _ = _in_image(cam, box_W)
        if not seen.any():
            problems.append(
                f"camera {name} looks away from the workspace (none of perception.workspace is in its image): "
                f"aim cameras.{name}.target_m at it, e.g. {_vec(centre)} m"
            )
            continue
        on, z = _in_image(cam, part_W)
        rng = np.linalg.norm(part_W - np.array(cam.eye_m), axis=1)
        if on.any() and float(rng[on].min()) > cam.far_m:
            problems.append(
                f"camera {name} sees the part from {float(rng[on].min()):.2f} m, beyond its far_m {cam.far_m:g} m: it "
                f"would see nothing of it; valid: far_m over {float(rng[on].max()):.2f} m, or the camera nearer"
            )
        elif on.any() and float(z[on].max()) < cam.near_m:
            problems.append(
                f"camera {name} sees the part nearer than its near_m {cam.near_m:g} m: it would see nothing of it"
            )
        elif not on.any():
            problems.append(f"camera {name} sees the workspace but none of the part at its nominal place (map.X_WM)")
    return problems


def part_height_problems(scenario: Scenario, weldmap_M: WeldMap) -> list[str]:
    """The map drawn (placed by ``map.X_WM``) above the table top or into it: the part lies on the table, the
    lowest part names where."""
    top = scenario.table.top_z
    lows = {p.name: float(p.vertices()[:, 2].min()) for p in weldmap_M.transformed(scenario.X_WM, "W").parts}
    name = min(lows, key=lambda n: lows[n])
    gap = lows[name] - top
    if abs(gap) <= ON_TABLE_M:
        return []
    z_fix = scenario.map.X_WM.xyz_m[2] - gap
    where = "above the table top" if gap > 0 else "into the table"
    return [
        f"part {name} (the map's lowest) is drawn {abs(gap):.3f} m {where} (its underside at z {lows[name]:.3f} m, the "
        f"top at {top:.3f} m): a part rests on the table; set map.X_WM.xyz_m z to {z_fix:.3f}"
    ]


def robot_problems(scenario: Scenario, weldmap_M: WeldMap, p_W_home: FloatArray | None) -> list[str]:
    """A robot base tilted from upright, or whose arm at home (``p_W_home``: the torch at ``robot.home_deg`` in
    the world, None without an arm) points away from the part."""
    if scenario.robot.urdf is None:
        return []
    X_WR = scenario.X_WR
    problems = []
    tilt = math.degrees(math.acos(float(np.clip(X_WR[2, 2], -1.0, 1.0))))
    if tilt > UPRIGHT_DEG:
        problems.append(
            f"robot.X_WR.rpy_deg {list(scenario.robot.X_WR.rpy_deg)} tilts the base {tilt:.0f} deg from upright"
            f"{' (upside down)' if tilt > 90.0 else ''}: the arm stands on the floor or a pedestal, roll and pitch 0"
        )
    if p_W_home is not None:
        part_W = np.vstack([p.vertices() for p in weldmap_M.transformed(scenario.X_WM, "W").parts]).mean(axis=0)
        base = X_WR[:3, 3]
        a, b = (p_W_home - base)[:2], (part_W - base)[:2]
        if np.linalg.norm(a) > 1e-3 and np.linalg.norm(b) > 1e-3:
            off = math.degrees(math.acos(float(np.clip(a @ b / np.linalg.norm(a) / np.linalg.norm(b), -1.0, 1.0))))
            if off > FACING_DEG:
                problems.append(
                    f"the arm at robot.home_deg points {off:.0f} deg away from the part: the robot faces away from "
                    "it (robot.X_WR.rpy_deg's yaw, or home_deg's A1)"
                )
    return problems


def gate_problems(scenario: Scenario) -> list[str]:
    """The weld gate's figures beyond their sane range, allowed by ``rescan.allow_loose_gate``."""
    loose = scenario.rescan.loose_gate()
    if not loose:
        return []
    return [f"the weld gate is loose (rescan.allow_loose_gate): {'; '.join(loose)}: seams that far off are welded"]


def name_problems(scenario: Scenario, weldmap_M: WeldMap) -> list[str]:
    """``process.seam_leg_mm`` keys that name no seam of the map (the run would weld those with ``leg_mm``)."""
    ids = {s.id for s in weldmap_M.seams}
    unknown = sorted(set(scenario.process.seam_leg_mm) - ids)
    if not unknown:
        return []
    return [
        f"process.seam_leg_mm names no seam {', '.join(unknown)} of the map: ignored (process.leg_mm "
        f"{scenario.process.leg_mm:g} mm applies); `cell map info` lists the seam ids"
    ]
