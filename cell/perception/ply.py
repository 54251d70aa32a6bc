"""PLY files in and out, so clouds from real cameras (or other tools) enter the same pipeline: binary PLY with the
camera index per point and the capture names and frame in header comments, read back with them."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from cell.errors import CloudFileError, SensorError
from cell.perception import _open3d
from cell.types import Cloud

_CAMERAS = b"comment cell-cameras "
_FRAME = b"comment cell-frame "


def _header(path: Path) -> list[bytes]:
    lines = []
    with path.open("rb") as f:
        for _ in range(1000):  # a PLY header is a few dozen lines
            line = f.readline()
            if not line:
                break
            lines.append(line.rstrip(b"\r\n"))
            if lines[-1] == b"end_header":
                break
    return lines


def save_ply(cloud: Cloud, path: str | Path) -> None:
    """Write ``cloud`` to ``path`` (binary PLY, metres, in the cloud's frame; see the module docstring)."""
    path = Path(path)
    if any("," in c or "\n" in c for c in cloud.cameras):
        raise ValueError(f"save_ply: camera names must not contain ',' or newlines: {cloud.cameras}")
    _open3d.write_ply(path, np.asarray(cloud.points), np.asarray(cloud.camera))
    data = path.read_bytes()
    first = data.index(b"\n") + 1  # after the "ply" line; the format line must come right after it
    second = data.index(b"\n", first) + 1
    extra = _FRAME + cloud.frame.encode() + b"\n"
    if cloud.cameras:
        extra += _CAMERAS + ",".join(cloud.cameras).encode() + b"\n"
    path.write_bytes(data[:second] + extra + data[second:])


def load_ply(path: str | Path, frame: str = "R") -> Cloud:
    """Read a point cloud from ``path`` as a :class:`Cloud` in ``frame`` (coordinates are taken as metres).

    Raises :class:`SensorError` if the file is missing, unreadable, disagrees with its header (checked as
    :func:`~cell.perception.cloud_files.read_cloud` checks it) or holds no finite points.
    """
    from cell.perception._cloud_formats import parse_ply

    path = Path(path)
    if not path.is_file():
        raise SensorError(f"point cloud file {str(path)!r} does not exist")
    header = _header(path)
    if not header or header[0] != b"ply":
        raise SensorError(f"{str(path)!r} is not a PLY file (it does not start with 'ply')")
    try:
        body = parse_ply(path, path.read_bytes())
    except CloudFileError as e:
        raise SensorError(e.message) from None
    points, camera = _open3d.read_ply(path)
    if len(points) != body.count or (body.xyz is not None and not np.array_equal(points, body.xyz, equal_nan=True)):
        raise SensorError(f"point cloud file {str(path)!r}: open3d read other points than its header and body hold")
    finite = np.all(np.isfinite(points), axis=1)
    if not finite.any():
        raise SensorError(f"point cloud file {str(path)!r} holds no finite points")
    cameras: tuple[str, ...] = ()
    for line in header:
        if line.startswith(_CAMERAS):
            cameras = tuple(line[len(_CAMERAS) :].decode().split(","))
    if camera is None or (cameras and (camera.min() < -1 or camera.max() >= len(cameras))):
        return Cloud(points[finite], frame)
    return Cloud(points[finite], frame, camera[finite].astype(np.int16), cameras)
