"""A calibration capture folder: what ``cell calibrate`` took (``--save-capture DIR``) or a real cell recorded, read
back by ``cell calibrate --capture DIR`` without a simulator. ``board_capture.yaml`` holds the board as printed
(``calibration.board``'s keys), each camera's mount and intrinsics, and one entry per image: the camera, the flange
pose X_RF the robot reported (4 x 4, metres, robot base frame) and the colour (8-bit RGB PNG) and depth (16-bit PNG
in ``depth_scale_m`` units, 0 invalid) files beside it."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
import yaml

from cell.errors import CaptureError
from cell.geometry import FloatArray, readonly
from cell.outputs import write_atomic
from cell.recorded.depth_png import encode, read_png, to_metres, write_png
from cell.types import CameraIntrinsics

INDEX = "board_capture.yaml"
FORMAT = "cell-calibration-capture/1"
DEPTH_SCALE_M = 0.0001  # 0.1 mm per unit


@dataclass(frozen=True)
class BoardShot:
    """One image of the board: the camera, the flange pose X_RF (4, 4) the robot reported, colour (H, W, 3) uint8 and
    depth (H, W) [m] (0 invalid)."""

    camera: str
    X_RF: FloatArray
    rgb: npt.NDArray[np.uint8]
    depth_m: npt.NDArray[np.float32]

    def __post_init__(self) -> None:
        object.__setattr__(self, "X_RF", readonly(self.X_RF))


@dataclass(frozen=True)
class BoardCapture:
    """A calibration capture: the board's spec (a mapping of ``calibration.board`` keys), each camera's mount
    (``fixed`` or ``eye_in_hand``) and intrinsics, the shots in the order taken."""

    board: Mapping[str, Any]
    mounts: Mapping[str, str]
    intrinsics: Mapping[str, CameraIntrinsics]
    shots: tuple[BoardShot, ...]


def write_board_capture(folder: Path, capture: BoardCapture) -> Path:
    """Write ``capture`` into ``folder`` (created, one level); returns the index file."""
    from PIL import Image

    folder.mkdir(exist_ok=True)
    images = []
    for k, shot in enumerate(capture.shots):
        colour, depth = f"{shot.camera}_{k:03d}.png", f"{shot.camera}_{k:03d}_depth.png"
        Image.fromarray(np.ascontiguousarray(shot.rgb)).save(folder / colour, format="PNG", compress_level=1)
        write_png(folder / depth, encode(shot.depth_m, DEPTH_SCALE_M).units)
        images.append(
            {"camera": shot.camera, "colour": colour, "depth": depth, "X_RF": np.round(shot.X_RF, 9).tolist()}
        )
    cameras = {
        name: {
            "mount": capture.mounts[name],
            "intrinsics": {k: getattr(intr, k) for k in ("width", "height", "fx", "fy", "cx", "cy")}
            | ({"distortion": [float(d) for d in intr.distortion]} if intr.distorted else {}),
        }
        for name, intr in capture.intrinsics.items()
    }
    doc = {
        "format": FORMAT,
        "depth_scale_m": DEPTH_SCALE_M,
        "board": dict(capture.board),
        "cameras": cameras,
        "images": images,
    }
    return write_atomic(folder / INDEX, yaml.safe_dump(doc, sort_keys=False).encode("utf-8"), what="capture index")


def read_board_capture(folder: Path, cameras: Sequence[str] | None = None) -> BoardCapture:
    """The capture in ``folder`` (only ``cameras``' images when given); CaptureError naming the file at fault."""
    from PIL import Image

    index = folder / INDEX
    try:
        doc = yaml.safe_load(index.read_text(encoding="utf-8"))
    except (OSError, yaml.YAMLError) as e:
        raise CaptureError(
            f"{index}: cannot read it ({e}); valid: a folder cell calibrate --save-capture wrote", path=str(index)
        ) from None
    if not isinstance(doc, dict) or doc.get("format") != FORMAT:
        raise CaptureError(f"{index} is not a calibration capture (format: {FORMAT})", path=str(index))
    try:
        mounts = {str(n): str(c["mount"]) for n, c in doc["cameras"].items()}
        intr = {str(n): _intrinsics(c["intrinsics"]) for n, c in doc["cameras"].items()}
        scale = float(doc["depth_scale_m"])
        entries = list(doc["images"])
        board = dict(doc["board"])
    except (KeyError, TypeError, ValueError) as e:
        raise CaptureError(f"{index}: missing or malformed key ({e})", path=str(index)) from None
    wanted = set(cameras) if cameras else set(mounts)
    shots = []
    for entry in entries:
        if entry["camera"] not in wanted:
            continue
        i = intr[entry["camera"]]
        path = folder / entry["colour"]
        try:
            with Image.open(path) as im:
                rgb = np.asarray(im.convert("RGB"), dtype=np.uint8)
        except OSError:
            raise CaptureError(f"colour image {path} is missing or not an image", path=str(path)) from None
        depth = to_metres(read_png(folder / entry["depth"], (i.width, i.height)), scale)
        if rgb.shape != (i.height, i.width, 3):
            raise CaptureError(
                f"colour image {path} is {rgb.shape[1]} x {rgb.shape[0]}, its camera's {i.width} x {i.height}",
                path=str(path),
            )
        X_RF = np.asarray(entry["X_RF"], dtype=float)
        if X_RF.shape != (4, 4) or not np.all(np.isfinite(X_RF)):
            raise CaptureError(f"{index}: image {entry['colour']}'s X_RF is not a finite 4 x 4 pose", path=str(index))
        shots.append(BoardShot(str(entry["camera"]), X_RF, rgb, depth))
    return BoardCapture(board, {n: mounts[n] for n in wanted}, {n: intr[n] for n in wanted}, tuple(shots))


def _intrinsics(entry: dict[str, Any]) -> CameraIntrinsics:
    """A camera's pinhole and, when stated, its lens' distortion (k1, k2, p1, p2, k3; absent: none)."""
    d = [float(v) for v in entry.get("distortion", [0.0] * 5)]
    if len(d) != 5:
        raise ValueError(f"distortion has {len(d)} coefficients, five are needed (k1, k2, p1, p2, k3)")
    rest = {k: v for k, v in entry.items() if k != "distortion"}
    return CameraIntrinsics(**rest, distortion=(d[0], d[1], d[2], d[3], d[4]))
