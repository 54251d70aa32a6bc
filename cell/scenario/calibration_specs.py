"""The cell's calibration target and how ``cell calibrate`` moves it: a ChArUco board (OpenCV's dictionary name,
squares, printed sizes), where it rides on the flange or lies on the table, how many poses, the robot's
repeatability. Lengths in millimetres at this edge (``_mm``), metres where the key says ``_m``."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field, model_validator

from cell.scenario.base import Angles3, Model, NonNeg, Pos, Vec3

# OpenCV's predefined ArUco dictionaries that a printed ChArUco board commonly uses (cv2.aruco.DICT_*).
Dictionary = Literal[
    "DICT_4X4_50",
    "DICT_4X4_100",
    "DICT_4X4_250",
    "DICT_5X5_50",
    "DICT_5X5_100",
    "DICT_5X5_250",
    "DICT_6X6_50",
    "DICT_6X6_100",
    "DICT_6X6_250",
    "DICT_APRILTAG_36h11",
]


class BoardSpec(Model):
    """A ChArUco board as printed: squares across and down, the chessboard square and the marker inside a white
    square [mm], the ArUco dictionary. Its frame B: origin at the pattern's first corner, x along the columns,
    y along the rows, z into the board (the printed face looks along -z)."""

    dictionary: Dictionary = "DICT_5X5_100"
    squares: tuple[Annotated[int, Field(ge=3, le=30)], Annotated[int, Field(ge=3, le=30)]] = (7, 5)
    square_mm: Annotated[float, Field(gt=2.0, le=500.0)] = 40.0
    marker_mm: Annotated[float, Field(gt=1.0, le=500.0)] = 30.0
    margin_mm: NonNeg = 10.0  # white plate around the pattern
    thickness_mm: Pos = 5.0  # the plate (aluminium composite)

    @model_validator(mode="after")
    def _check(self) -> BoardSpec:
        if self.marker_mm >= self.square_mm:
            raise ValueError(f"marker_mm ({self.marker_mm}) must be smaller than square_mm ({self.square_mm})")
        return self


class BoardMountSpec(Model):
    """Where the board sits as drawn (what the cell is told, its nominal; the calibration measures it): on the
    flange (``X_FB``, for the fixed cameras) and on the table (``X_WB``, for the arm's camera)."""

    # The pattern's origin in the flange frame tool0 (x out of the flange along the torch, the arm camera on +z):
    # on a bracket under the torch, clear of it, the printed face looking along the flange's -z.
    X_FB_xyz_m: Vec3 = (0.04, -0.10, -0.08)
    X_FB_rpy_deg: Angles3 = (0.0, 0.0, 0.0)
    on_table_xy_m: tuple[float, float] | None = None  # pattern centre on the table (world); None: the table's centre


class CalibrationRunSpec(Model):
    """How ``cell calibrate`` measures the cameras (docs/calibration.md): the board, its mounts, the number of poses
    per camera (a quarter more are held out to check the result), the robot's repeatability (data sheet), the
    tolerances beyond which a camera's intrinsics or depth scale are flagged."""

    board: BoardSpec = BoardSpec()
    mount: BoardMountSpec = BoardMountSpec()
    poses: Annotated[int, Field(ge=4, le=60)] = 12
    held_out: Annotated[int, Field(ge=0, le=20)] = 4
    range_m: tuple[Pos, Pos] = (0.7, 1.1)  # board distance from a fixed camera, nearest and farthest [m]
    hand_range_m: tuple[Pos, Pos] = (0.50, 0.70)  # the arm's camera from the board on the table [m]
    tilt_deg: Annotated[float, Field(gt=0.0, le=60.0)] = 30.0  # largest tilt of the board against the sight line
    repeatability_mm: NonNeg = 0.03  # the robot's pose repeatability (KR 5 arc data sheet); the simulator draws it
    focal_tolerance: Annotated[float, Field(gt=0.0, le=0.5)] = 0.005  # a focal length off by more: flagged
    principal_tolerance_px: Pos = 4.0  # a principal point off by more: flagged
    depth_scale_tolerance: Annotated[float, Field(gt=0.0, le=0.5)] = 0.005  # depth off by more: flagged
    distortion_tolerance_px: Pos = 1.0  # a lens moving the image's corner this much more than stated: flagged
    board_scale_tolerance: Annotated[float, Field(gt=0.0, le=0.5)] = 0.02  # a board this far off its size: refused
