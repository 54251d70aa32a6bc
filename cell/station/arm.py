"""The station's robot: the URDF the scenario names (the simulator loads the same file as the planner's model, so
both agree on the kinematics). Where the arm stands is handed to the station (:class:`~cell.station.ports.Arm`,
planned by :func:`cell.pipeline.geometry.robot_arm`): the station moves it there, it does not plan."""

from __future__ import annotations

from pathlib import Path

from cell.errors import ScenarioError
from cell.scenario import REPO_ROOT, Scenario

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
