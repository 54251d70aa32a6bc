"""The capture folder: what the cameras of a cell saw (16-bit depth PNGs, their CameraInfo and poses, the cell it was
taken in, the truth apart), written so a real cell could write it too (docs/capture.md)."""

from __future__ import annotations

import json
import re
import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from cell.errors import CaptureError
from cell.geometry import FloatArray, invert, readonly
from cell.outputs import write_atomic, write_text
from cell.recorded import _fields as f
from cell.recorded.depth_png import check_size, encode, read_png, to_metres, write_png
from cell.types import DepthImage, Part

FORMAT = "weld-cell-capture"
VERSION = 1
INDEX = "capture.json"
CELL = "cell.yaml"
TRUTH = "truth.json"
DEFAULT_DEPTH_SCALE_M = 0.0001  # 0.1 mm per unit, the simulated D415's depth unit [m]
MOUNTS = ("fixed", "eye_in_hand")
FLANGE_FRAME = "tool0"  # the robot's flange ($FLANGE)
POSE_TOLERANCE = 1e-9  # X_WC and X_WR @ X_RC may differ by rounding only [m, rad]
_NAME = re.compile(r"^[A-Za-z0-9_.-]+$")  # camera and file names: no folders, nothing a file system refuses

_NUMBER_LIST = re.compile(r"\[\s*([-+0-9.eE,\s]+?)\s*\]")  # a JSON list holding numbers only

Warn = Callable[[str], None]


def _warn(message: str) -> None:
    warnings.warn(message, stacklevel=3)


@dataclass(frozen=True)
class RecordedCapture:
    """A capture folder read back.

    images : camera name -> its depth image (X_WC in W, as calibrated), in the order of the index.
    X_WR : (4, 4) pose of the robot base in W.
    cell_yaml : the text of ``cell.yaml`` (None when the folder has none, e.g. a capture from a bag).
    truth_parts_W : the as-built parts in W (None when the station did not know them).
    provenance : what wrote the folder (``cell.provenance``), or None.
    depth_scale_m : camera name -> metres per depth unit of its PNG.
    X_RF : camera name -> (4, 4) flange pose in R when it took its image (eye-in-hand cameras that recorded it).
    """

    folder: Path
    images: dict[str, DepthImage]
    X_WR: FloatArray
    cell_yaml: str | None = None
    truth_parts_W: tuple[Part, ...] | None = None
    provenance: dict[str, Any] | None = None
    depth_scale_m: dict[str, float] = field(default_factory=dict)
    X_RF: dict[str, FloatArray] = field(default_factory=dict)

    def X_RC(self, camera: str) -> FloatArray:
        """(4, 4) pose of ``camera``'s optical frame in R."""
        return invert(self.X_WR) @ self.images[camera].X_WC


def write_capture(
    out_dir: str | Path,
    images: Mapping[str, DepthImage],
    X_WR: FloatArray,
    *,
    cell_yaml: str | None = None,
    truth_parts_W: tuple[Part, ...] | list[Part] | None = None,
    provenance: Mapping[str, Any] | None = None,
    flange: Mapping[str, FloatArray] | None = None,
    depth_scale_m: float | Mapping[str, float] | None = None,
    map_file: str | Path | None = None,
    warn: Warn | None = None,
) -> Path:
    """Write a capture folder at ``out_dir`` (created; files of an earlier capture there are replaced); returns it.

    images : camera name -> depth image (X_WC in W as calibrated). X_WR : (4, 4) robot base in W.
    cell_yaml : the cell's scenario text without ``simulation:`` (its ``map.file`` should name ``map_file``'s
        file name, which is copied beside it). truth_parts_W : the as-built parts in W, when known.
    provenance : what made it (default: ``cell.provenance.provenance(None)``).
    flange : camera name -> (4, 4) flange pose X_RF [m] when that (eye-in-hand) camera took its image.
    depth_scale_m : metres per PNG unit, one for all cameras or per camera (default 0.1 mm). A depth off that
        grid is rounded (replayed up to half a unit off) and one beyond 65535 units stored invalid: ``warn``
        says so (default: a Python warning).
    """
    warn = warn or _warn
    folder = Path(out_dir)
    X_WR = np.asarray(X_WR, dtype=float)
    if not images:
        raise CaptureError("no camera image to write; valid: at least one camera")
    bad = [n for n in images if not _NAME.match(n)]
    if bad:
        raise CaptureError(f"camera name(s) {', '.join(map(repr, bad))} cannot name a file; valid: [A-Za-z0-9_.-]+")
    mounts = [f"{n}: {im.mount!r}" for n, im in images.items() if im.mount not in MOUNTS]
    if mounts:
        raise CaptureError(f"camera mount(s) {', '.join(mounts)}; valid: {', '.join(MOUNTS)}")
    folder.mkdir(parents=True, exist_ok=True)
    for stale in (INDEX, CELL, TRUTH):  # an index is written last: a folder with one is complete
        (folder / stale).unlink(missing_ok=True)
    X_RW = invert(X_WR)
    cameras = []
    for name, image in images.items():
        scale = _scale(depth_scale_m, name)
        enc = encode(image.depth, scale)
        if enc.off_grid:
            warn(
                f"camera {name}: {enc.off_grid} depths not on the {scale * 1e3:g} mm grid of its PNG: the replay "
                f"differs from this capture by up to {enc.max_rounding_m * 1e3:.3g} mm (each rounded to a whole unit)"
            )
        if enc.too_far:
            warn(f"camera {name}: {enc.too_far} depths beyond {65535 * scale:g} m stored as invalid (0)")
        png = f"{name}.depth.png"
        write_png(folder / png, enc.units)
        entry: dict[str, Any] = {
            "name": name,
            "mount": image.mount,
            "depth": png,
            "depth_scale_m": scale,
            "camera_info": f.camera_info(image.intrinsics),
            "X_RC": (X_RW @ image.X_WC).tolist(),
            "X_WC": np.asarray(image.X_WC).tolist(),
        }
        if flange is not None and name in flange:
            entry["flange"] = {"frame": FLANGE_FRAME, "X_RF": np.asarray(flange[name], dtype=float).tolist()}
        cameras.append(entry)
    index: dict[str, Any] = {"format": FORMAT, "version": VERSION}
    index["provenance"] = dict(provenance) if provenance is not None else _provenance()
    index["X_WR"] = X_WR.tolist()
    index["cell"] = None
    index["truth"] = None
    if cell_yaml is not None:
        write_text(folder / CELL, cell_yaml, what="capture's cell")
        index["cell"] = CELL
        if map_file is not None and Path(map_file).resolve() != (folder / Path(map_file).name).resolve():
            write_atomic(folder / Path(map_file).name, Path(map_file).read_bytes(), what="capture's map")
    if truth_parts_W is not None:
        write_text(folder / TRUTH, dumps(f.truth_json(tuple(truth_parts_W))), what="capture's truth")
        index["truth"] = TRUTH
    index["cameras"] = cameras
    write_text(folder / INDEX, dumps(index), what="capture index")
    return folder


def read_capture(folder: str | Path) -> RecordedCapture:
    """Read a capture folder; CaptureError (one line) for a missing file, a bad value, an image that is not a
    16-bit PNG or disagrees with its CameraInfo, an unknown format or version. Nothing is guessed."""
    folder = Path(folder)
    if not folder.is_dir():
        raise CaptureError(
            f"capture folder {folder} does not exist; valid: a folder `cell capture` wrote", path=str(folder)
        )
    path = folder / INDEX
    data = f.load_json(path, "capture index")
    if data.get("format") != FORMAT:
        raise CaptureError(f"{path}: format {data.get('format')!r}; valid: {FORMAT!r}", path=str(path))
    if data.get("version") != VERSION:
        raise CaptureError(f"{path}: version {data.get('version')!r}; valid: {VERSION}", path=str(path))
    X_WR = f.pose(f.field(data, "X_WR", "", path), "X_WR", path)
    cams = f.field(data, "cameras", "", path)
    if not isinstance(cams, list) or not cams:
        raise CaptureError(f"{path}: cameras is empty or not a list; valid: one entry per camera", path=str(path))
    images: dict[str, DepthImage] = {}
    scales: dict[str, float] = {}
    flanges: dict[str, FloatArray] = {}
    for i, cam in enumerate(cams):
        where = f"cameras[{i}]"
        if not isinstance(cam, dict):
            raise CaptureError(f"{path}: {where} is not an object; valid: docs/capture.md", path=str(path))
        name = f.field(cam, "name", f"{where}.", path)
        if not isinstance(name, str) or not _NAME.match(name) or name in images:
            raise CaptureError(
                f"{path}: {where}.name {name!r}; valid: a new camera name ([A-Za-z0-9_.-]+)", path=str(path)
            )
        image, scales[name], X_RF = _camera(folder, path, cam, f"cameras[{name}]", X_WR)
        images[name] = image
        if X_RF is not None:
            flanges[name] = X_RF
    cell_yaml = _optional_text(folder, data, "cell", path)
    truth_name = _optional_name(data, "truth", path)
    truth = f.truth_parts(folder / truth_name) if truth_name is not None else None
    prov = data.get("provenance")
    return RecordedCapture(
        folder, images, X_WR, cell_yaml, truth, prov if isinstance(prov, dict) else None, scales, flanges
    )


def _camera(
    folder: Path, path: Path, cam: Mapping[str, Any], where: str, X_WR: FloatArray
) -> tuple[DepthImage, float, FloatArray | None]:
    """One camera entry of the index: its image, depth scale and flange pose (or None)."""
    mount = f.field(cam, "mount", f"{where}.", path)
    if mount not in MOUNTS:
        raise CaptureError(f"{path}: {where}.mount {mount!r}; valid: {', '.join(MOUNTS)}", path=str(path))
    scale = f.positive(f.field(cam, "depth_scale_m", f"{where}.", path), f"{where}.depth_scale_m", path)
    intr = f.intrinsics(f.field(cam, "camera_info", f"{where}.", path), f"{where}.camera_info", path)
    X_RC = f.pose(f.field(cam, "X_RC", f"{where}.", path), f"{where}.X_RC", path)
    X_WC = X_WR @ X_RC
    if "X_WC" in cam:  # the very floats of the capture; they must agree with X_WR @ X_RC
        recorded = f.pose(cam["X_WC"], f"{where}.X_WC", path)
        if not np.allclose(recorded, X_WC, rtol=0.0, atol=POSE_TOLERANCE):
            raise CaptureError(f"{path}: {where}.X_WC disagrees with X_WR @ X_RC; valid: the same pose", path=str(path))
        X_WC = recorded
    png_name = f.field(cam, "depth", f"{where}.", path)
    if not isinstance(png_name, str) or not _NAME.match(png_name):
        raise CaptureError(f"{path}: {where}.depth {png_name!r}; valid: a file name in the folder", path=str(path))
    check_size(folder / png_name, intr.width, intr.height)  # before the PNG is opened: no image is that large
    units = read_png(folder / png_name, (intr.width, intr.height))
    image = DepthImage(str(cam["name"]), to_metres(units, scale), intr, readonly(X_WC), str(mount))
    X_RF = None
    flange = cam.get("flange")
    if flange is not None:
        if not isinstance(flange, dict):
            raise CaptureError(f"{path}: {where}.flange is not an object; valid: {{frame, X_RF}}", path=str(path))
        X_RF = f.pose(f.field(flange, "X_RF", f"{where}.flange.", path), f"{where}.flange.X_RF", path)
    return image, scale, X_RF


def _optional_name(data: Mapping[str, Any], key: str, path: Path) -> str | None:
    name = data.get(key)
    if name is None:
        return None
    if not isinstance(name, str) or not _NAME.match(name):
        raise CaptureError(f"{path}: {key} {name!r}; valid: a file name in the folder, or null", path=str(path))
    return name


def _optional_text(folder: Path, data: Mapping[str, Any], key: str, path: Path) -> str | None:
    name = _optional_name(data, key, path)
    if name is None:
        return None
    try:
        return (folder / name).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as e:
        raise CaptureError(
            f"{folder / name} cannot be read ({e}); valid: the file {INDEX} names", path=str(folder / name)
        ) from None


def dumps(data: Mapping[str, Any]) -> str:
    """Indented JSON with each list of numbers on one line (a pose row, a K), floats as Python's repr (exact)."""
    text = json.dumps(data, indent=1, default=str)  # a path or a time in a provenance record: its text
    return _NUMBER_LIST.sub(lambda m: "[" + ", ".join(v.strip() for v in m.group(1).split(",")) + "]", text) + "\n"


def _scale(depth_scale_m: float | Mapping[str, float] | None, camera: str) -> float:
    value = depth_scale_m.get(camera) if isinstance(depth_scale_m, Mapping) else depth_scale_m
    return float(value) if value is not None and value > 0 else DEFAULT_DEPTH_SCALE_M


def _provenance() -> dict[str, Any]:
    from cell.provenance import provenance

    return provenance(None)
