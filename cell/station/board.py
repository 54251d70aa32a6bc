"""The simulated cell as ``cell calibrate`` finds it: the table, the arm and the cameras, no part, and the printed
calibration board, bolted on the flange's bracket or lying on the table. What only the simulation knows stays here:
where the board really sits (its mount's error), the robot's repeatability on every pose it reports, and each
camera's true pose to judge a calibration by."""

from __future__ import annotations

from typing import Literal

import numpy as np
import numpy.typing as npt

from cell.calibrate.solve import WRIST_LEVER_M
from cell.geometry import FloatArray, axis_angle_to_matrix, invert, make_pose
from cell.scenario import ExtrinsicErrorSpec, Scenario
from cell.station.arm import robot_urdf
from cell.station.ports import Arm
from cell.types import CameraIntrinsics, DepthImage

BoardPlace = Literal["flange", "table"]
BOARD = "calibration_board"
FLANGE = "tool0"
CAMERA_LINK = "camera_optical"
# The board's true place against its drawing: a bracket machined and bolted on the flange, a board laid on the table.
_BRACKET_ERROR = ExtrinsicErrorSpec(translation_mm=2.0, rotation_deg=1.0)
_TABLE_SLIDE_M, _TABLE_TURN_RAD = 0.005, np.radians(2.0)  # the board laid on the table: slid and turned on it


class SimBoardStation:
    """A running simulated cell for calibration: ``picture`` (h, w) uint8 the printed face, ``face_m`` its size,
    ``origin_m`` its top-left corner in the board frame B; ``X_FB`` the board's drawn pose on the flange, ``X_WB``
    on the table. The poses the arm reports are exact forward kinematics; the board and the arm camera render from
    the poses the arm really reached (the scenario's ``calibration.repeatability_mm``)."""

    def __init__(
        self,
        scenario: Scenario,
        arm: Arm,
        picture: npt.ArrayLike,
        face_m: tuple[float, float],
        origin_m: tuple[float, float],
        *,
        X_FB: FloatArray,
        X_WB: FloatArray,
    ) -> None:
        from cell.sim import SimCell
        from cell.sim.noise import perturb_pose

        self.scenario = scenario
        self.arm = arm
        self.sim = SimCell(scenario, ())
        try:
            self.sim.load_robot(robot_urdf(scenario), scenario.X_WR, arm.q_home, joint_names=arm.model.joint_names)
            self.sim.add_board(BOARD, picture, face_m, origin_m)
        except BaseException:
            self.sim.close()
            raise
        self.X_FB_true = perturb_pose(X_FB, _BRACKET_ERROR, scenario.rng("calibrate/bracket"))
        self.X_WB_true = _slid(X_WB, scenario.rng("calibrate/table_board"))
        self._rng = scenario.rng("calibrate/repeatability")
        self._sigma_m = scenario.calibration.repeatability_mm * 1e-3

    def view(
        self, camera: str, q: npt.ArrayLike, board: BoardPlace
    ) -> tuple[FloatArray, DepthImage, npt.NDArray[np.uint8]]:
        """The arm moved to q (dof,) [rad], the board on the flange or the table, one image from ``camera``: the
        flange pose X_RF the robot reports, the depth image and the colour image."""
        self.sim.set_q(q)
        X_WF = self.sim.link_pose(FLANGE)
        w = self._rng.normal(0.0, self._sigma_m / WRIST_LEVER_M, 3)
        off = make_pose(_rotvec(w), self._rng.normal(0.0, self._sigma_m, 3))
        X_WF_reached = X_WF @ off  # where the flange really is: its repeatability about the commanded pose
        self.sim.place(BOARD, X_WF_reached @ self.X_FB_true if board == "flange" else self.X_WB_true)
        X_WC = None
        if self.scenario.cameras[camera].mount == "eye_in_hand":
            X_WC = X_WF_reached @ invert(X_WF) @ self.sim.link_pose(CAMERA_LINK)
        depth, rgb = self.sim.capture_rgbd(camera, X_WC)
        return np.asarray(self.arm.model.fk(q, FLANGE)), depth, rgb

    def intrinsics(self, camera: str) -> CameraIntrinsics:
        return self.sim.intrinsics(camera)

    def camera_truth(self, camera: str) -> FloatArray:
        """The camera's true pose: X_RC of a fixed camera, X_FC (on the flange) of the arm's."""
        spec = self.scenario.cameras[camera]
        if spec.mount == "eye_in_hand":
            q = self.arm.q_home
            return invert(self.arm.model.fk(q, FLANGE)) @ self.arm.model.fk(q, CAMERA_LINK)
        return invert(self.scenario.X_WR) @ spec.X_WC

    def close(self) -> None:
        self.sim.close()

    def __enter__(self) -> SimBoardStation:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _slid(X_WB: FloatArray, rng: np.random.Generator) -> FloatArray:
    """The board where it really lies: slid on the table's top and turned about its normal (world z)."""
    d = rng.normal(0.0, _TABLE_SLIDE_M, 2)
    a = rng.normal(0.0, _TABLE_TURN_RAD)
    R = np.array([[np.cos(a), -np.sin(a), 0.0], [np.sin(a), np.cos(a), 0.0], [0.0, 0.0, 1.0]])
    return make_pose(R @ X_WB[:3, :3], X_WB[:3, 3] + np.array([d[0], d[1], 0.0]))  # turned about its origin's vertical


def _rotvec(w: FloatArray) -> FloatArray:
    angle = float(np.linalg.norm(w))
    return np.eye(3) if angle == 0.0 else axis_angle_to_matrix(w / angle, angle)
