"""The station's robot: the URDF the scenario names, its Pinocchio model, home and scan configurations.

The same URDF drives the simulated arm and the planner's model, so both agree on the kinematics.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from cell.errors import ScenarioError
from cell.geometry import invert
from cell.scenario import REPO_ROOT, Scenario
from cell.station.ports import Arm

ROBOT_DIR = REPO_ROOT / "robots"


def robot_urdf(scenario: Scenario) -> Path:
    """The scenario's robot URDF (``robot.urdf``, relative to robots/); ScenarioError if missing."""
    if scenario.robot.urdf is None:
        raise ScenarioError(f"scenario {scenario.name!r} has no robot: set robot.urdf (e.g. kr5_arc.urdf)")
    path = ROBOT_DIR / scenario.robot.urdf
    if not path.is_file():
        known = ", ".join(sorted(p.name for p in ROBOT_DIR.glob("*.urdf")))
        raise ScenarioError(f"robot.urdf {scenario.robot.urdf!r} does not exist in robots/; available: {known}")
    return path


def load_arm(scenario: Scenario) -> Arm:
    """The robot model, its home (``robot.home_deg``) and the scan configuration that holds the eye-in-hand camera
    at its scenario viewpoint (IK on the camera's optical frame, rotation about the optical axis free)."""
    from cell.motion.robot import RobotModel
    from cell.motion.scan import scan_configuration

    model = RobotModel.from_urdf(robot_urdf(scenario))
    home_deg = scenario.robot.home_deg
    if home_deg is None or len(home_deg) != model.dof:
        raise ScenarioError(f"robot.home_deg must list {model.dof} joint values in degrees, got {home_deg}")
    q_home = np.radians(np.asarray(home_deg, dtype=float))
    q_scan = q_home
    eye = [name for name, cam in scenario.cameras.items() if cam.mount == "eye_in_hand"]
    if eye:
        X_RC = invert(scenario.X_WR) @ scenario.cameras[eye[0]].X_WC
        q_scan = scan_configuration(model, X_RC, q_home, rng=scenario.rng("scan"), ik=scenario.motion.plan.ik)
    return Arm(model, q_home, np.asarray(q_scan, dtype=float))
