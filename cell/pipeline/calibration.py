"""``cell calibrate``: the board shown to every camera asked for, the images taken, each camera's pose solved
(:mod:`cell.calibrate`). The fixed cameras see the board on the flange as the arm carries it through poses planned
for good conditioning; the arm's camera sees it lying on the table from poses the arm holds it at. Every pose is
reached by IK before it is taken; the board must be found (most of its corners) or the pose is skipped."""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import numpy.typing as npt

from cell.calibrate import HandEyeMethod
from cell.calibrate.board import Board
from cell.calibrate.checks import check_board_size, check_diversity, depth_scale, rotation_spread_deg
from cell.calibrate.intrinsics import check_intrinsics
from cell.calibrate.plan import board_poses, camera_poses
from cell.calibrate.result import CameraCalibration
from cell.calibrate.solve import hand_eye_start, held_out, refine
from cell.calibrate.views import Mount, View
from cell.errors import CalibrationError, CalibrationFault, CaptureError, IKError, ScenarioError, UsageError
from cell.geometry import FloatArray, invert, make_pose, pose_from_xyz_rpy, rot_x
from cell.motion.ik import solve_ik
from cell.pipeline.geometry import robot_arm
from cell.recorded.board_capture import BoardCapture, BoardShot, read_board_capture
from cell.scenario import Scenario
from cell.scenario.calibration_specs import BoardSpec, CalibrationRunSpec
from cell.station.board import SimBoardStation
from cell.station.ports import Arm
from cell.types import CameraIntrinsics

Progress = Callable[[str], None]
OPENCV_METHODS: tuple[HandEyeMethod, ...] = ("park", "tsai", "daniilidis")  # OpenCV's hand-eye methods alone
_SEEN_FRACTION = 0.6  # a pose counts when this much of the board's corners are found
_OFFSET = (0.25, 0.1)  # the arm camera's board this far aside and up its image: the torch hides the lower middle
_CLEARANCE_M = 0.05  # the board and the flange stay this far above the table top


@dataclass(frozen=True)
class CalibrationRun:
    """Every camera calibrated, in the order asked, with the board it used; ``capture`` what the cameras saw
    (when asked to keep it)."""

    board: BoardSpec
    cameras: tuple[CameraCalibration, ...]
    capture: BoardCapture | None = None


def calibrate(
    scn: Scenario,
    cameras: Sequence[str] | None = None,
    *,
    poses: int | None = None,
    progress: Progress | None = None,
    keep: bool = False,
) -> CalibrationRun:
    """Calibrate ``cameras`` (default: every camera) of the simulated cell; ``poses`` overrides the scenario's
    ``calibration.poses``; ``keep`` keeps the images and poses taken (a capture folder's content). CalibrationError
    (with its code) for a camera that cannot be calibrated."""
    say = progress or (lambda _m: None)
    names = list(scn.cameras) if not cameras else list(cameras)
    unknown = [n for n in names if n not in scn.cameras]
    if unknown:
        raise UsageError(f"--cameras {', '.join(unknown)}: not in the scenario; cameras: {', '.join(scn.cameras)}")
    arm = robot_arm(scn)
    if arm is None:
        raise ScenarioError(f"scenario {scn.name!r} has no robot: cell calibrate moves the board or the camera with it")
    spec = scn.calibration if poses is None else scn.calibration.model_copy(update={"poses": poses})
    board = Board(spec.board)
    picture, face_m, origin_m = Board(spec.board, scale=scn.simulation.board_scale).picture()
    X_FB = pose_from_xyz_rpy(spec.mount.X_FB_xyz_m, np.radians(spec.mount.X_FB_rpy_deg))
    X_WB = _table_board(scn, board)
    out, shots, intrinsics = [], [], {}
    with SimBoardStation(scn, arm, picture, face_m, origin_m, X_FB=X_FB, X_WB=X_WB) as station:
        for name in names:
            mount = Mount.EYE_IN_HAND if scn.cameras[name].mount == "eye_in_hand" else Mount.EYE_TO_HAND
            say(f"{name}: taking {spec.poses + spec.held_out} board images ({mount})")
            views, intr, taken = _views(scn, station, arm, board, name, mount, spec.poses + spec.held_out, X_FB, X_WB)
            cal = solve_camera(spec, name, mount, views, board, intr, spec.held_out)
            out.append(_with_truth(cal, station.camera_truth(name)))
            say(f"{name}: {_summary(out[-1])}")
            if keep:
                shots += taken
                intrinsics[name] = intr
    capture = None
    if keep:
        mounts = {n: scn.cameras[n].mount for n in names}
        capture = BoardCapture(spec.board.model_dump(), mounts, intrinsics, tuple(shots))
    return CalibrationRun(spec.board, tuple(out), capture)


def calibrate_capture(
    folder: Path,
    cameras: Sequence[str] | None = None,
    *,
    held_out: int = 4,
    progress: Progress | None = None,
) -> CalibrationRun:
    """Calibrate from a capture folder (:mod:`cell.recorded.board_capture`), no simulator: the board found in each
    colour image, the last ``held_out`` images of each camera kept out of the fit. The tolerances are the scenario
    defaults (``calibration``)."""
    say = progress or (lambda _m: None)
    probe = read_board_capture(folder, ())
    unknown = [c for c in cameras or () if c not in probe.mounts]
    if unknown:
        raise UsageError(f"--cameras {', '.join(unknown)}: not in the capture; cameras: {', '.join(probe.mounts)}")
    cap = read_board_capture(folder, cameras)
    try:
        spec = CalibrationRunSpec(board=BoardSpec(**cap.board), held_out=held_out)
    except ValueError as e:
        raise CaptureError(f"{folder}: its board is not valid ({' '.join(str(e).split())})", path=str(folder)) from None
    board = Board(spec.board)
    out = []
    for name, mount_name in cap.mounts.items():
        mount = Mount.EYE_IN_HAND if mount_name == "eye_in_hand" else Mount.EYE_TO_HAND
        views = []
        for shot in (s for s in cap.shots if s.camera == name):
            corners = board.detect(shot.rgb)
            if len(corners) >= _SEEN_FRACTION * len(board.p_B):
                views.append(View(shot.X_RF, corners, _depth_at(shot.depth_m, corners.px)))
        n = len(views) - held_out
        if n < 4:
            raise CalibrationError(
                f"{name}: the board is found in {len(views)} of the capture's images, {held_out + 4} are needed",
                code=CalibrationFault.NOT_SEEN,
                camera=name,
                value=len(views),
                needed=held_out + 4,
            )
        say(f"{name}: {len(views)} board images ({mount})")
        out.append(solve_camera(spec, name, mount, views, board, cap.intrinsics[name], held_out))
        say(f"{name}: {_summary(out[-1])}")
    return CalibrationRun(spec.board, tuple(out))


def solve_camera(
    spec: CalibrationRunSpec,
    camera: str,
    mount: Mount,
    views: Sequence[View],
    board: Board,
    intr: CameraIntrinsics,
    n_held: int,
) -> CameraCalibration:
    """The checks, OpenCV's start and methods alone, the joint refinement and its held-out residuals of one camera."""
    K = intr.K
    fit, rest = list(views[: len(views) - n_held]), list(views[len(views) - n_held :])
    check_diversity(fit, mount, camera)
    scale = depth_scale(views, board.p_B, K)
    check_board_size(scale, camera, spec.board_scale_tolerance)
    starts = {m: hand_eye_start(fit, board.p_B, K, mount, m) for m in OPENCV_METHODS}
    X0, B0 = starts["park"]
    sol = refine(fit, board.p_B, K, mount, X0, B0)
    px, d3 = held_out(sol, rest, board.p_B, K, mount)
    return CameraCalibration(
        camera=camera,
        mount=mount,
        solution=sol,
        poses=len(fit),
        held_out_images=len(rest),
        held_out_px=px,
        held_out_3d_m=d3,
        spread_deg=rotation_spread_deg(fit, mount),
        intrinsics=check_intrinsics(views, board.p_B, intr, scale, spec),
        opencv={m: X for m, (X, _) in starts.items()},
    )


def _with_truth(cal: CameraCalibration, X_AC_true: FloatArray) -> CameraCalibration:
    return replace(cal, X_AC_true=X_AC_true)


def _summary(cal: CameraCalibration) -> str:
    s = cal.solution
    text = (
        f"{cal.poses} poses, {s.rms_px:.2f} px, held out {cal.held_out_px:.2f} px / {cal.held_out_3d_m * 1e3:.2f} mm, "
        f"sigma {s.sigma_translation_m * 1e3:.3f} mm / {np.degrees(s.sigma_rotation_rad):.4f} deg"
    )
    err = cal.truth_error()
    if err is not None:
        text += f", truth error {err[0] * 1e3:.3f} mm / {np.degrees(err[1]):.4f} deg"
    return text


def _table_board(scn: Scenario, board: Board) -> FloatArray:
    """X_WB of the board lying face up on the table (its centre at ``calibration.mount.on_table_xy_m`` or the
    table's centre)."""
    xy = scn.calibration.mount.on_table_xy_m or scn.table.center_m[:2]
    R = rot_x(np.pi)  # the printed face (-z_B) looks up
    centre = np.array([xy[0], xy[1], scn.table.top_z + 1e-4])
    return make_pose(R, centre - R @ board.centre_B)


def _views(
    scn: Scenario,
    station: SimBoardStation,
    arm: Arm,
    board: Board,
    camera: str,
    mount: Mount,
    wanted: int,
    X_FB: FloatArray,
    X_WB: FloatArray,
) -> tuple[list[View], CameraIntrinsics, list[BoardShot]]:
    """``wanted`` images of the board, each pose reached by IK and the board found in it (and what was taken)."""
    spec, cam = scn.calibration, scn.cameras[camera]
    intr = station.intrinsics(camera)
    rng = scn.rng(f"calibrate/{camera}")
    X_RW = invert(scn.X_WR)
    top_R = (X_RW @ np.array([0.0, 0.0, scn.table.top_z, 1.0]))[2] + _CLEARANCE_M
    targets: Iterator[tuple[str, FloatArray]]
    if mount == Mount.EYE_TO_HAND:
        X_RC = X_RW @ cam.X_WC  # the camera where the scenario says: enough to plan by
        targets = (
            ("tool0", X_RC @ X_CB @ invert(X_FB)) for X_CB in board_poses(board, intr, spec.range_m, spec.tilt_deg, rng)
        )
    else:
        X_RB = X_RW @ X_WB
        targets = (
            ("camera_optical", X_RC)
            for X_RC in camera_poses(board, X_RB, intr, spec.hand_range_m, spec.tilt_deg, rng, offset=_OFFSET)
        )
    views: list[View] = []
    shots: list[BoardShot] = []
    q = arm.q_home
    reached = seen = 0
    for frame, X_RT in targets:
        if mount == Mount.EYE_TO_HAND and not _above(X_RT @ X_FB, board, top_R, X_RT):
            continue
        try:
            q_new = solve_ik(arm.model, X_RT, q, frame=frame, rng=rng)
        except IKError:
            continue
        reached += 1
        X_RF, depth, rgb = station.view(camera, q_new, "flange" if mount == Mount.EYE_TO_HAND else "table")
        corners = board.detect(rgb)
        if len(corners) < _SEEN_FRACTION * len(board.p_B):
            if seen == 0 and reached >= wanted:
                break  # as many poses taken as were wanted and the board found in none: no use trying the rest
            continue
        seen += 1
        q = q_new
        views.append(View(X_RF, corners, _depth_at(depth.depth, corners.px)))
        shots.append(BoardShot(camera, X_RF, rgb, depth.depth))
        if len(views) == wanted:
            return views, intr, shots
    if reached < wanted:
        raise CalibrationError(
            f"cameras.{camera}: only {reached} of the planned board poses are within the arm's reach, {wanted} "
            f"are needed (calibration.poses + held_out); move the board's range (calibration.range_m)",
            code=CalibrationFault.UNREACHABLE,
            camera=camera,
            value=reached,
            needed=wanted,
        )
    raise CalibrationError(
        f"cameras.{camera}: the board is found in {seen} of {reached} images taken, {wanted} are needed"
        + (": the camera cannot see the board at any pose (its view, near_m/far_m, or the board)" if seen == 0 else ""),
        code=CalibrationFault.NOT_SEEN,
        camera=camera,
        value=seen,
        needed=wanted,
    )


def _above(X_RB: FloatArray, board: Board, top_R: float, X_RF: FloatArray) -> bool:
    """Whether the board's corners and the flange stay above the table (robot frame z, ``top_R`` with clearance)."""
    corners = board.p_B @ X_RB[:3, :3].T + X_RB[:3, 3]
    return bool(np.all(corners[:, 2] > top_R) and X_RF[2, 3] > top_R)


def _depth_at(depth_m: npt.NDArray[np.float32], px: FloatArray) -> FloatArray:
    """The depth image (H, W) [m] at each pixel (nearest), nan where invalid."""
    h, w = depth_m.shape
    u = np.clip(np.rint(px[:, 0]).astype(int), 0, w - 1)
    v = np.clip(np.rint(px[:, 1]).astype(int), 0, h - 1)
    d = depth_m[v, u].astype(float)
    return np.where(d > 0.0, d, np.nan)
