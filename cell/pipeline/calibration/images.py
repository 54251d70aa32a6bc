"""The simulated cell's board images for ``cell calibrate``: each planned pose reached by IK, screened for the table's
clearance and for collisions of the arm with the cell (the table, the fixtures, the part's drawn bodies where it
would be clamped), the image taken and the board found in it (or the pose skipped), each drop counted."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from cell.calibrate.board import Board
from cell.calibrate.plan import board_poses, camera_poses
from cell.calibrate.views import Mount, View
from cell.errors import CalibrationError, CalibrationFault, IKError
from cell.geometry import FloatArray, invert
from cell.motion.ik import solve_ik
from cell.recorded.board_capture import BoardShot
from cell.scenario import Scenario
from cell.station.board import SimBoardStation
from cell.station.ports import Arm
from cell.types import CameraIntrinsics

SEEN_FRACTION = 0.6  # a pose counts when this much of the board's corners are found
_OFFSET = (0.25, 0.1)  # the arm camera's board this far aside and up its image: the torch hides the lower middle
_CLEARANCE_M = 0.05  # the board and the flange stay this far above the table top
_TRIES = 1500  # candidate poses drawn at most per camera (most of a fixed camera's may collide: the wrist bent back)
_HOPELESS = 5  # reachable poses per wanted one, none clear: the camera's poses are refused as colliding
_RESTARTS = 3  # a colliding configuration: this many IK runs from random ones besides its wrist flipped


@dataclass(frozen=True)
class Taken:
    """One camera's images: the views fitted and held out, the camera's intrinsics, what was taken (a capture's
    content), and the planned poses dropped on the way, counted by why (:data:`DROPS`)."""

    views: tuple[View, ...]
    intrinsics: CameraIntrinsics
    shots: tuple[BoardShot, ...]
    dropped: dict[str, int]


DROPS = ("table", "unreachable", "colliding", "not_seen")  # why a planned pose gave no image, in the order checked


class PoseScreen:
    """The arm's collision check for calibration poses: the arm (with its torch) against the table, the map's
    fixtures and, for the fixed cameras (the board on the flange), the part's drawn bodies at their nominal place
    and the board's plate against them; the arm's camera sees the board lying where the part would be, so its
    poses miss the table and fixtures only. Robot frame R."""

    def __init__(self, scn: Scenario, arm: Arm, board: Board, X_FB: FloatArray) -> None:
        from cell.motion.collision import CollisionChecker
        from cell.motion.collision.scene import cell_obstacles
        from cell.pipeline.detect import read_weldmap

        weldmap_R = read_weldmap(scn).transformed(invert(scn.X_WR) @ scn.X_WM, "R")
        everything = cell_obstacles(weldmap_R, scn.X_WR, scn.table.center_m, scn.table.size_m)
        table = everything[-1:]
        opt = scn.motion.plan.collision
        self._checkers = {
            Mount.EYE_TO_HAND: CollisionChecker(arm.model, (*everything, *weldmap_R.fixtures), opt),
            Mount.EYE_IN_HAND: CollisionChecker(arm.model, (*table, *weldmap_R.fixtures), opt),
        }
        bodies = [*weldmap_R.parts, *weldmap_R.fixtures]
        v = [b.vertices() for b in bodies]
        grow = opt.part_inflation
        self._lo = np.array([x.min(axis=0) for x in v]).reshape(-1, 3) - grow
        self._hi = np.array([x.max(axis=0) for x in v]).reshape(-1, 3) + grow
        (w, h), m = board.pattern_m, board.margin_m
        gx, gy = np.meshgrid(np.linspace(-m, w + m, 9), np.linspace(-m, h + m, 7))
        self._plate_B = np.column_stack([gx.ravel(), gy.ravel(), np.zeros(gx.size)])  # the plate's face, sampled
        self._X_FB = X_FB

    def collides(self, q: npt.ArrayLike, mount: Mount, X_RF: FloatArray) -> bool:
        """Whether the arm at q (dof,) [rad] touches an obstacle or itself, or (a fixed camera's pose) the board on
        the flange at X_RF (4, 4) enters a body's bounds."""
        if self._checkers[mount].check(q) is not None:
            return True
        if mount == Mount.EYE_IN_HAND or len(self._lo) == 0:
            return False
        X_RB = X_RF @ self._X_FB
        p = self._plate_B @ X_RB[:3, :3].T + X_RB[:3, 3]
        inside = np.all((p[:, None, :] >= self._lo[None]) & (p[:, None, :] <= self._hi[None]), axis=2)
        return bool(np.any(inside))


def take_views(
    scn: Scenario,
    station: SimBoardStation,
    arm: Arm,
    board: Board,
    camera: str,
    mount: Mount,
    wanted: int,
    X_FB: FloatArray,
    X_WB: FloatArray,
    screen: PoseScreen,
) -> Taken:
    """``wanted`` images of the board, each pose reached by IK, clear of the cell and the board found in it."""
    spec, cam = scn.calibration, scn.cameras[camera]
    intr = station.intrinsics(camera)
    rng = scn.rng(f"calibrate/{camera}")
    X_RW = invert(scn.X_WR)
    top_R = (X_RW @ np.array([0.0, 0.0, scn.table.top_z, 1.0]))[2] + _CLEARANCE_M
    targets: Iterator[tuple[str, FloatArray]]
    if mount == Mount.EYE_TO_HAND:
        X_RC = X_RW @ cam.X_WC  # the camera where the scenario says: enough to plan by
        targets = (
            ("tool0", X_RC @ X_CB @ invert(X_FB))
            for X_CB in board_poses(board, intr, spec.range_m, spec.tilt_deg, rng, tries=_TRIES)
        )
    else:
        X_RB = X_RW @ X_WB
        targets = (
            ("camera_optical", X_RC)
            for X_RC in camera_poses(
                board, X_RB, intr, spec.hand_range_m, spec.tilt_deg, rng, tries=_TRIES, offset=_OFFSET
            )
        )
    views: list[View] = []
    shots: list[BoardShot] = []
    dropped = dict.fromkeys(DROPS, 0)
    q = arm.q_home
    reached = clear = seen = 0
    for frame, X_RT in targets:
        if mount == Mount.EYE_TO_HAND and not _above(X_RT @ X_FB, board, top_R, X_RT):
            dropped["table"] += 1
            continue
        try:
            q_new = solve_ik(arm.model, X_RT, q, frame=frame, rng=rng)
        except IKError:
            dropped["unreachable"] += 1
            continue
        reached += 1
        q_clear = _clear_configuration(screen, arm, mount, X_RT, frame, q_new, rng)
        if q_clear is None:
            dropped["colliding"] += 1
            if clear == 0 and reached >= _HOPELESS * wanted:
                break  # this many reachable poses and not one clear of the cell: the rest will not be either
            continue
        q_new = q_clear
        clear += 1
        X_RF, depth, rgb = station.view(camera, q_new, "flange" if mount == Mount.EYE_TO_HAND else "table")
        corners = board.detect(rgb)
        if len(corners) < SEEN_FRACTION * len(board.p_B):
            dropped["not_seen"] += 1
            if seen == 0 and clear >= wanted:
                break  # as many poses taken as were wanted and the board found in none: no use trying the rest
            continue
        seen += 1
        q = q_new
        views.append(View(X_RF, corners, depth_at(depth.depth, corners.px)))
        shots.append(BoardShot(camera, X_RF, rgb, depth.depth))
        if len(views) == wanted:
            return Taken(tuple(views), intr, tuple(shots), dropped)
    if reached < wanted:
        raise CalibrationError(
            f"cameras.{camera}: only {reached} of the planned board poses are within the arm's reach, {wanted} "
            f"are needed (calibration.poses + held_out); move the board's range (calibration.range_m)",
            code=CalibrationFault.UNREACHABLE,
            camera=camera,
            value=reached,
            needed=wanted,
        )
    if clear < wanted:
        raise CalibrationError(
            f"cameras.{camera}: only {clear} of the {reached} reachable board poses keep the arm clear of the cell "
            f"({dropped['colliding']} collide with the table, the fixtures or the part), {wanted} are needed; "
            f"move the board's range (calibration.range_m) or clear the cell",
            code=CalibrationFault.COLLIDING,
            camera=camera,
            value=clear,
            needed=wanted,
        )
    raise CalibrationError(
        f"cameras.{camera}: the board is found in {seen} of {clear} images taken, {wanted} are needed"
        + (": the camera cannot see the board at any pose (its view, near_m/far_m, or the board)" if seen == 0 else ""),
        code=CalibrationFault.NOT_SEEN,
        camera=camera,
        value=seen,
        needed=wanted,
    )


def _clear_configuration(
    screen: PoseScreen,
    arm: Arm,
    mount: Mount,
    X_RT: FloatArray,
    frame: str,
    q: FloatArray,
    rng: np.random.Generator,
) -> FloatArray | None:
    """A configuration reaching X_RT clear of the cell: ``q`` itself, else the IK started from its wrist flipped
    (axis 4 turned half a turn, axis 5 mirrored, axis 6 half a turn: the same flange pose, the torch on the wrist's
    other side), else from ``_RESTARTS`` random configurations; None when every one collides."""
    X_RF = np.asarray(arm.model.fk(q, "tool0"))
    if not screen.collides(q, mount, X_RF):
        return q
    flipped = np.array(q, dtype=float)
    flipped[3] += np.pi if flipped[3] < 0.0 else -np.pi
    flipped[4] = -flipped[4]
    flipped[5] += np.pi if flipped[5] < 0.0 else -np.pi
    lim = arm.model.limits
    seeds = [flipped] + [rng.uniform(lim.q_min, lim.q_max) for _ in range(_RESTARTS)]
    for seed in seeds:
        try:
            q_alt = solve_ik(arm.model, X_RT, seed, frame=frame)
        except IKError:
            continue
        if not screen.collides(q_alt, mount, np.asarray(arm.model.fk(q_alt, "tool0"))):
            return q_alt
    return None


def _above(X_RB: FloatArray, board: Board, top_R: float, X_RF: FloatArray) -> bool:
    """Whether the board's corners and the flange stay above the table (robot frame z, ``top_R`` with clearance)."""
    corners = board.p_B @ X_RB[:3, :3].T + X_RB[:3, 3]
    return bool(np.all(corners[:, 2] > top_R) and X_RF[2, 3] > top_R)


def depth_at(depth_m: npt.NDArray[np.float32], px: FloatArray) -> FloatArray:
    """The depth image (H, W) [m] at each pixel (nearest), nan where invalid."""
    h, w = depth_m.shape
    u = np.clip(np.rint(px[:, 0]).astype(int), 0, w - 1)
    v = np.clip(np.rint(px[:, 1]).astype(int), 0, h - 1)
    d = depth_m[v, u].astype(float)
    return np.where(d > 0.0, d, np.nan)
