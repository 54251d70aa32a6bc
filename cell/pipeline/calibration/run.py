"""``cell calibrate``'s runs: the simulated cell's cameras calibrated from the images :mod:`.images` takes, or a
capture folder's; each camera's checks, OpenCV's start and the joint refinement (:mod:`cell.calibrate`)."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from cell.calibrate import HandEyeMethod
from cell.calibrate.board import Board
from cell.calibrate.checks import check_board_size, check_diversity, depth_scale, rotation_spread_deg
from cell.calibrate.intrinsics import check_intrinsics
from cell.calibrate.result import CameraCalibration
from cell.calibrate.solve import hand_eye_start, held_out, refine
from cell.calibrate.views import Mount, View, undistorted
from cell.errors import CalibrationError, CalibrationFault, CaptureError, ScenarioError, UsageError
from cell.geometry import FloatArray, make_pose, pose_from_xyz_rpy, rot_x
from cell.pipeline.calibration.images import SEEN_FRACTION, PoseScreen, depth_at, take_views
from cell.pipeline.geometry import robot_arm
from cell.recorded.board_capture import BoardCapture, BoardShot, read_board_capture
from cell.scenario import Scenario
from cell.scenario.calibration_specs import BoardSpec, CalibrationRunSpec
from cell.station.board import SimBoardStation
from cell.types import CameraIntrinsics

Progress = Callable[[str], None]
OPENCV_METHODS: tuple[HandEyeMethod, ...] = ("park", "tsai", "daniilidis")  # OpenCV's hand-eye methods alone


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
    out: list[CameraCalibration] = []
    shots: list[BoardShot] = []
    intrinsics: dict[str, CameraIntrinsics] = {}
    screen = PoseScreen(scn, arm, board, X_FB)
    with SimBoardStation(scn, arm, picture, face_m, origin_m, X_FB=X_FB, X_WB=X_WB) as station:
        for name in names:
            mount = Mount.EYE_IN_HAND if scn.cameras[name].mount == "eye_in_hand" else Mount.EYE_TO_HAND
            say(f"{name}: taking {spec.poses + spec.held_out} board images ({mount})")
            got = take_views(scn, station, arm, board, name, mount, spec.poses + spec.held_out, X_FB, X_WB, screen)
            cal = solve_camera(spec, name, mount, got.views, board, got.intrinsics, spec.held_out)
            out.append(replace(cal, X_AC_true=station.camera_truth(name), dropped=got.dropped))
            say(f"{name}: {_summary(out[-1])}; poses dropped: {_dropped(got.dropped)}")
            if keep:
                shots += got.shots
                intrinsics[name] = got.intrinsics
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
    run_spec: CalibrationRunSpec | None = None,
) -> CalibrationRun:
    """Calibrate from a capture folder (:mod:`cell.recorded.board_capture`) or a ROS 2 bag
    (:mod:`cell.recorded.board_bag`), no simulator: the board found in each colour image, the last ``held_out``
    images of each camera kept out of the fit. ``run_spec`` (a scenario's ``calibration``) states the board a bag
    does not hold, and the tolerances; default: the scenario defaults (a folder's own board)."""
    from cell.recorded.board_bag import is_bag, read_board_bag

    say = progress or (lambda _m: None)
    base = run_spec or CalibrationRunSpec()
    if is_bag(folder):
        cap = read_board_bag(folder, base.board.model_dump(), cameras, progress=say)
    else:
        probe = read_board_capture(folder, ())
        unknown = [c for c in cameras or () if c not in probe.mounts]
        if unknown:
            raise UsageError(f"--cameras {', '.join(unknown)}: not in the capture; cameras: {', '.join(probe.mounts)}")
        cap = read_board_capture(folder, cameras)
    try:
        spec = base.model_copy(update={"board": BoardSpec(**cap.board), "held_out": held_out})
    except ValueError as e:
        raise CaptureError(f"{folder}: its board is not valid ({' '.join(str(e).split())})", path=str(folder)) from None
    board = Board(spec.board)
    out = []
    for name, mount_name in cap.mounts.items():
        mount = Mount.EYE_IN_HAND if mount_name == "eye_in_hand" else Mount.EYE_TO_HAND
        views = []
        for shot in (s for s in cap.shots if s.camera == name):
            corners = board.detect(shot.rgb)
            if len(corners) >= SEEN_FRACTION * len(board.p_B):
                views.append(View(shot.X_RF, corners, depth_at(shot.depth_m, corners.px)))
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
    """The checks, OpenCV's start and methods alone, the joint refinement and its held-out residuals of one camera.
    The corners are solved where a pinhole puts them, through the stated lens (``intr.distortion``) or, where the
    images show that one wrong (flagged), through the lens they measure."""
    K = intr.K
    check_diversity(views[: len(views) - n_held], mount, camera)
    ideal = undistorted(views, K, intr.distortion)
    scale = depth_scale(ideal, board.p_B, K)
    check_board_size(scale, camera, spec.board_scale_tolerance)
    lens = check_intrinsics(views, board.p_B, intr, scale, spec)
    if lens.flagged_lens:
        ideal = undistorted(views, K, lens.lens)
    fit, rest = ideal[: len(views) - n_held], ideal[len(views) - n_held :]
    starts = {m: hand_eye_start(fit, board.p_B, K, mount, m) for m in OPENCV_METHODS}
    X0, B0 = starts["park"]
    sol = refine(fit, board.p_B, K, mount, X0, B0, spec.repeatability_mm * 1e-3)
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
        intrinsics=lens,
        opencv={m: X for m, (X, _) in starts.items()},
    )


def _dropped(dropped: dict[str, int]) -> str:
    return ", ".join(f"{n} {why.replace('_', ' ')}" for why, n in dropped.items() if n) or "none"


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
