"""The station: one builder that turns a scenario into a running cell (cf. Drake's ``MakeHardwareStation``).

Today the station is the simulator (as-built parts, table, cameras, the arm); the pipeline only talks to it through
``capture`` (depth images) and ``execute`` (a timed joint trajectory), the same ports real hardware would offer.
The robot model (Pinocchio) is loaded from the same URDF as the simulated arm, so both agree on the kinematics.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from types import TracebackType
from typing import TYPE_CHECKING

import numpy as np

from cell.errors import ScenarioError
from cell.geometry import FloatArray, invert
from cell.scenario import REPO_ROOT, Scenario
from cell.types import DepthImage, Part, WeldMap

if TYPE_CHECKING:
    from cell.motion.robot import RobotModel
    from cell.sim.cell import SimCell

ROBOT_DIR = REPO_ROOT / "robots"


@dataclass(frozen=True)
class Arm:
    """The robot of the station: its model, home and scan configurations [rad]."""

    model: RobotModel
    q_home: FloatArray
    q_scan: FloatArray


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
    from cell.motion.plan import scan_configuration
    from cell.motion.robot import RobotModel

    model = RobotModel.from_urdf(robot_urdf(scenario))
    home_deg = scenario.robot.home_deg
    if home_deg is None or len(home_deg) != model.dof:
        raise ScenarioError(f"robot.home_deg must list {model.dof} joint values in degrees, got {home_deg}")
    q_home = np.radians(np.asarray(home_deg, dtype=float))
    q_scan = q_home
    eye = [name for name, cam in scenario.cameras.items() if cam.mount == "eye_in_hand"]
    if eye:
        X_RC = invert(scenario.X_WR) @ scenario.cameras[eye[0]].X_WC
        q_scan = scan_configuration(model, X_RC, q_home, rng=scenario.rng("scan"))
    return Arm(model, q_home, np.asarray(q_scan, dtype=float))


class Station:
    """A running cell built from a scenario: the simulator, the as-built part, and the arm when there is one.

    Use as a context manager; the simulator's client is released on exit.
    """

    def __init__(self, scenario: Scenario, *, gui: bool = False, with_robot: bool = True) -> None:
        from cell.asbuilt import as_built_parts
        from cell.sim.cell import SimCell
        from cell.weldmap import read_map

        self.scenario = scenario
        self.weldmap: WeldMap = read_map(scenario.map_path, units=scenario.map.units)
        self.parts_W: tuple[Part, ...] = as_built_parts(self.weldmap, scenario)
        self.sim: SimCell = SimCell(scenario, self.parts_W, gui=gui)
        self.arm: Arm | None = None
        try:
            if with_robot and scenario.robot.urdf is not None:
                self.arm = load_arm(scenario)
                self.sim.load_robot(
                    robot_urdf(scenario), scenario.X_WR, self.arm.q_scan, joint_names=self.arm.model.joint_names
                )
        except BaseException:
            self.sim.close()
            raise

    def capture(self) -> dict[str, DepthImage]:
        """One image from every camera; the arm (if any) holds the eye-in-hand camera at its scan pose."""
        if self.arm is not None:
            self.sim.set_q(self.arm.q_scan)
        return self.sim.capture_all()

    def close(self) -> None:
        self.sim.close()

    def __enter__(self) -> Station:
        return self

    def __exit__(
        self, exc_type: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None
    ) -> None:
        self.close()
