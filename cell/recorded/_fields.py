"""Reading the capture folder's JSON fields: every value checked, a one-line CaptureError naming the key otherwise.

Poses are 4 x 4 row-major nested lists [m]; numbers are JSON floats (Python's repr, so they round-trip exactly).
A truth file's part is a box (``X_WB``, ``size_m``) or a polyhedral body (``vertices_m``: (k, 3) nested lists in W,
``faces``: vertex-index lists counter-clockwise seen from outside, ``face_names``), beside each other in one file.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from cell.errors import CaptureError
from cell.geometry import FloatArray
from cell.types import Box, CameraIntrinsics, Part, Polyhedron

TRUTH_FORMAT = "weld-cell-truth"
TRUTH_VERSION = 1


def load_json(path: Path, what: str) -> dict[str, Any]:
    """The JSON object in ``path``; CaptureError if the file is missing, not JSON or not an object."""
    if not path.is_file():
        raise CaptureError(f"{what} {path} is missing; valid: a capture folder (docs/capture.md)", path=str(path))
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as e:
        raise CaptureError(f"{what} {path} is not JSON ({e}); valid: docs/capture.md", path=str(path)) from None
    if not isinstance(data, dict):
        raise CaptureError(f"{what} {path} holds a {type(data).__name__}; valid: a JSON object", path=str(path))
    return data


def field(data: Mapping[str, Any], key: str, where: str, path: Path) -> Any:
    """``data[key]``, or CaptureError naming ``where.key`` as missing."""
    if key not in data:
        raise CaptureError(f"{path}: {where}{key} is missing; valid: docs/capture.md", path=str(path))
    return data[key]


def numbers(value: Any, count: int, where: str, path: Path) -> list[float]:
    """``count`` finite numbers (a flat JSON list)."""
    ok = isinstance(value, list) and len(value) == count
    ok = ok and all(isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v) for v in value)
    if not ok:
        raise CaptureError(f"{path}: {where} is {_short(value)}; valid: {count} finite numbers", path=str(path))
    return [float(v) for v in value]


def positive_int(value: Any, where: str, path: Path) -> int:
    if not isinstance(value, int) or isinstance(value, bool) or value <= 0:
        raise CaptureError(f"{path}: {where} is {_short(value)}; valid: a positive integer", path=str(path))
    return value


def positive(value: Any, where: str, path: Path) -> float:
    if not isinstance(value, int | float) or isinstance(value, bool) or not (math.isfinite(value) and value > 0):
        raise CaptureError(f"{path}: {where} is {_short(value)}; valid: a positive number", path=str(path))
    return float(value)


def pose(value: Any, where: str, path: Path) -> FloatArray:
    """A rigid 4 x 4 pose (row-major nested lists): last row 0 0 0 1, rotation orthonormal within 1e-6."""
    rows = value if isinstance(value, list) and len(value) == 4 else None
    if rows is None:
        raise CaptureError(f"{path}: {where} is {_short(value)}; valid: a 4 x 4 pose (4 rows of 4)", path=str(path))
    X = np.array([numbers(r, 4, f"{where} row {i}", path) for i, r in enumerate(rows)])
    R = X[:3, :3]
    rigid = np.array_equal(X[3], [0.0, 0.0, 0.0, 1.0]) and np.allclose(R.T @ R, np.eye(3), atol=1e-6)
    if not rigid or np.linalg.det(R) <= 0:
        raise CaptureError(f"{path}: {where} is not a rigid pose; valid: [[R, p], [0 0 0 1]]", path=str(path))
    return X


def camera_info(intr: CameraIntrinsics) -> dict[str, Any]:
    """The ROS ``sensor_msgs/CameraInfo`` fields of a pinhole camera without distortion."""
    return {
        "width": intr.width,
        "height": intr.height,
        "distortion_model": "plumb_bob",
        "D": [0.0] * 5,
        "K": [float(v) for v in intr.K.ravel()],
    }


def intrinsics(info: Any, where: str, path: Path) -> CameraIntrinsics:
    """CameraIntrinsics from CameraInfo fields; a camera with distortion or skew is refused (pinhole only)."""
    if not isinstance(info, dict):
        raise CaptureError(f"{path}: {where} is {_short(info)}; valid: CameraInfo fields", path=str(path))
    width = positive_int(field(info, "width", f"{where}.", path), f"{where}.width", path)
    height = positive_int(field(info, "height", f"{where}.", path), f"{where}.height", path)
    K = numbers(field(info, "K", f"{where}.", path), 9, f"{where}.K", path)
    if K[1] != 0 or K[3] != 0 or K[6] != 0 or K[7] != 0 or K[8] != 1 or K[0] <= 0 or K[4] <= 0:
        raise CaptureError(
            f"{path}: {where}.K {K} is not a pinhole without skew; valid: [fx, 0, cx, 0, fy, cy, 0, 0, 1]",
            path=str(path),
        )
    D = info.get("D", [])
    if not isinstance(D, list) or any(not isinstance(d, int | float) or d != 0 for d in D):
        raise CaptureError(
            f"{path}: {where}.D is {_short(D)}: distortion is not supported; valid: zeros (an undistorted image)",
            path=str(path),
        )
    return CameraIntrinsics(width, height, K[0], K[4], K[2], K[5])


def truth_json(parts_W: tuple[Part, ...] | list[Part]) -> dict[str, Any]:
    """The as-built parts in W as the truth file's object."""
    return {
        "format": TRUTH_FORMAT,
        "version": TRUTH_VERSION,
        "frame": "W",
        "note": "ground truth for measuring only: perception never reads this file",
        "parts": [_part_json(p) for p in parts_W],
    }


def _part_json(part: Part) -> dict[str, Any]:
    if part.is_box:
        return {"name": part.name, "X_WB": part.box.X_AB.tolist(), "size_m": part.box.size.tolist()}
    body = part.body
    assert isinstance(body, Polyhedron)
    return {
        "name": part.name,
        "drawn_as": part.drawn_as,
        "vertices_m": np.asarray(body.vertices).tolist(),
        "faces": [list(f) for f in body.faces],
        "face_names": list(body.names),
    }


def _polyhedron(p: dict[str, Any], where: str, path: Path) -> Part:
    """A polyhedral part of a truth file: finite vertices, faces of 3 or more valid indices, one name per face."""
    verts = p.get("vertices_m")
    if not isinstance(verts, list) or len(verts) < 4:
        raise CaptureError(f"{path}: {where}.vertices_m is {_short(verts)}; valid: 4 or more [x, y, z]", path=str(path))
    v = np.array([numbers(q, 3, f"{where}.vertices_m[{i}]", path) for i, q in enumerate(verts)])
    faces, names = p.get("faces"), p.get("face_names")
    if not isinstance(faces, list) or not all(
        isinstance(f, list) and all(isinstance(i, int) and not isinstance(i, bool) for i in f) for f in faces
    ):
        raise CaptureError(f"{path}: {where}.faces is {_short(faces)}; valid: lists of vertex indices", path=str(path))
    if not isinstance(names, list) or not all(isinstance(n, str) for n in names):
        raise CaptureError(f"{path}: {where}.face_names is {_short(names)}; valid: one name per face", path=str(path))
    drawn_as = p.get("drawn_as", "")
    try:
        body = Polyhedron(v, tuple(tuple(f) for f in faces), tuple(names))
    except ValueError as e:
        raise CaptureError(f"{path}: {where} is not a closed body ({e})", path=str(path)) from None
    return Part(p["name"], body, drawn_as if isinstance(drawn_as, str) else "")


def truth_parts(path: Path) -> tuple[Part, ...]:
    """The as-built parts (frame W) of a truth file."""
    data = load_json(path, "truth file")
    if data.get("format") != TRUTH_FORMAT or data.get("version") != TRUTH_VERSION or data.get("frame") != "W":
        got = f"{data.get('format')!r} version {data.get('version')!r} frame {data.get('frame')!r}"
        raise CaptureError(f"{path}: {got}; valid: {TRUTH_FORMAT!r} version {TRUTH_VERSION} frame 'W'", path=str(path))
    parts = field(data, "parts", "", path)
    if not isinstance(parts, list):
        raise CaptureError(f"{path}: parts is {_short(parts)}; valid: a list of parts", path=str(path))
    out = []
    for i, p in enumerate(parts):
        if not isinstance(p, dict) or not isinstance(p.get("name"), str):
            raise CaptureError(
                f"{path}: parts[{i}] has no name; valid: {{name, X_WB, size_m}} or {{name, vertices_m, faces}}",
                path=str(path),
            )
        if "vertices_m" in p:
            out.append(_polyhedron(p, f"parts[{i}]", path))
            continue
        X_WB = pose(field(p, "X_WB", f"parts[{i}].", path), f"parts[{i}].X_WB", path)
        size = [
            positive(s, f"parts[{i}].size_m", path) for s in numbers(p.get("size_m"), 3, f"parts[{i}].size_m", path)
        ]
        out.append(Part(p["name"], Box(X_WB, np.array(size))))
    return tuple(out)


def _short(value: Any) -> str:
    text = json.dumps(value) if not isinstance(value, str) else repr(value)
    return text if len(text) <= 60 else text[:57] + "..."
