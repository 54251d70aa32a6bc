"""Geometry a run computes once and hands on: the arm (its model, home and the scan configuration solved by IK,
handed to the station), the obstacles the arm must miss and their collision checker.

The joints of the map are found once per run too (:func:`cell.pipeline.detect.capture`): they are topological
(which face of which part), so the same joints hold for the map as drawn, as aligned and as built.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from cell.errors import IKError, ScenarioError
from cell.geometry import invert
from cell.pipeline.records import Detection
from cell.scenario import Scenario
from cell.station import Arm, SimStation, open_station, robot_urdf
from cell.types import Part, WeldMap

if TYPE_CHECKING:
    from cell.motion.collision import CollisionChecker


@dataclass(frozen=True)
class MotionScene:
    """What the arm must miss, in R: the aligned map's parts and the table, and the checker built on them (it
    loads the arm's collision model once for the whole run: planning, the gate and every re-scan view)."""

    obstacles: tuple[Part, ...]
    checker: CollisionChecker


def motion_scene(arm: Arm, det: Detection) -> MotionScene:
    """The obstacles of a detection's aligned map (its nominal placement when alignment failed) and the table."""
    from cell.motion.collision import CollisionChecker
    from cell.motion.collision.scene import cell_obstacles

    sc = det.scenario
    obstacles = cell_obstacles(det.weldmap_R, sc.X_WR, sc.table.center_m, sc.table.size_m)
    obstacles = (*obstacles, *det.weldmap_R.fixtures)  # clamps and stops (map.layers): obstacles, never parts
    return MotionScene(obstacles, CollisionChecker(arm.model, obstacles, sc.motion.plan.collision))


def robot_arm(scenario: Scenario) -> Arm | None:
    """The scenario's robot (None without ``robot.urdf``): its model, its home (``robot.home_deg``) and the scan
    configuration that holds the eye-in-hand camera at its scenario viewpoint (IK on the camera's optical frame,
    rotation about the optical axis free). ScenarioError for a home of the wrong size, IKError for a viewpoint
    out of reach."""
    from cell.motion.robot import RobotModel
    from cell.motion.scan import scan_configuration

    if scenario.robot.urdf is None:
        return None
    model = RobotModel.from_urdf(robot_urdf(scenario))
    home_deg = scenario.robot.home_deg
    if home_deg is None or len(home_deg) != model.dof:
        raise ScenarioError(f"robot.home_deg must list {model.dof} joint values in degrees, got {home_deg}")
    q_home = np.radians(np.asarray(home_deg, dtype=float))
    lim = model.limits
    for j in np.flatnonzero((q_home < lim.q_min - 1e-9) | (q_home > lim.q_max + 1e-9)):
        lo, hi = np.degrees(lim.q_min[j]), np.degrees(lim.q_max[j])
        raise ScenarioError(
            f"robot.home_deg A{j + 1} {home_deg[j]:g} deg is outside the joint's limits ({lo:.0f} to {hi:.0f} deg)"
        )
    q_scan = q_home
    eye = [name for name, cam in scenario.cameras.items() if cam.mount == "eye_in_hand"]
    if eye:
        X_RC = invert(scenario.X_WR) @ scenario.cameras[eye[0]].X_WC
        try:
            q_scan = scan_configuration(model, X_RC, q_home, rng=scenario.rng("scan"), ik=scenario.motion.plan.ik)
        except IKError as e:
            centre, reach = model.reach_bound("camera_optical")
            far = float(np.linalg.norm(X_RC[:3, 3] - centre))
            raise IKError(
                f"cameras.{eye[0]}: the arm cannot hold the camera at its scan pose (eye_m "
                f"{list(scenario.cameras[eye[0]].eye_m)}, {far:.2f} m from the arm's shoulder, which reaches "
                f"{reach:.2f} m at most): {e.message}"
            ) from None
    return Arm(model, q_home, np.asarray(q_scan, dtype=float))


def open_cell(scenario: Scenario, weldmap: WeldMap, *, gui: bool = False) -> SimStation:
    """The running cell of ``scenario`` (:func:`cell.station.open_station`) with its arm (:func:`robot_arm`)."""
    return open_station(scenario, weldmap, arm=robot_arm(scenario), gui=gui)
