"""ROS message fields to the project's values: depth Images, CameraInfo, stamps, camera names from topics.

The messages are read by attribute (duck-typed: the objects rosbags deserialises, or anything with the same
fields), so this module imports no ROS library; :mod:`cell.recorded.bag` reads the bag. Errors are one-line
:class:`~cell.errors.CaptureError` naming the bag and the topic.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from cell.errors import CaptureError
from cell.types import CameraIntrinsics

DEPTH_SCALE_M = {"16UC1": 1e-3, "32FC1": 1.0}  # encoding -> metres per stored unit (REP 118)
_DTYPE = {"16UC1": "u2", "32FC1": "f4"}


def fail(bag: Path, what: str) -> CaptureError:
    return CaptureError(f"bag {bag}: {what}", path=str(bag))


def camera_names(topics: Sequence[str]) -> dict[str, str]:
    """Image topic -> camera name: the topic's first namespace component (``/cam_right/depth/image_rect_raw`` ->
    ``cam_right``) when that tells the topics apart, else the namespace joined by ``_``, else the whole topic;
    characters outside ``[A-Za-z0-9_-]`` become ``_`` (the name is part of file names)."""

    def clean(s: str) -> str:
        return re.sub(r"[^A-Za-z0-9_-]", "_", s) or "camera"

    parts = {t: [p for p in t.split("/") if p] or ["camera"] for t in topics}
    for pick in (lambda p: p[0], lambda p: "_".join(p[:-1]) or p[0], lambda p: "_".join(p)):
        names = {t: clean(pick(p)) for t, p in parts.items()}
        if len(set(names.values())) == len(names):
            return names
    return {t: f"{name}_{i}" for i, (t, name) in enumerate(names.items())}  # topics equal once cleaned


def info_topic_of(image_topic: str) -> str:
    """The CameraInfo topic beside an image topic (image_transport's convention)."""
    return image_topic.rsplit("/", 1)[0] + "/camera_info"


def stamp_ns(msg: Any) -> int:
    return int(msg.header.stamp.sec) * 1_000_000_000 + int(msg.header.stamp.nanosec)


def depth_of(msg: Any, bag: Path, topic: str) -> npt.NDArray[np.float32]:
    """(height, width) float32 depth [m] of a ``16UC1`` / ``32FC1`` Image message; 0 where invalid."""
    enc = str(msg.encoding)
    if enc not in DEPTH_SCALE_M:
        raise fail(bag, f"{topic} has encoding {enc!r}; valid depth encodings: 16UC1 (millimetres), 32FC1 (metres)")
    h, w, step = int(msg.height), int(msg.width), int(msg.step)
    dtype = np.dtype(_DTYPE[enc]).newbyteorder(">" if msg.is_bigendian else "<")
    data = np.asarray(msg.data, dtype=np.uint8)
    if h <= 0 or w <= 0 or step < w * dtype.itemsize or data.size < step * h:
        raise fail(
            bag,
            f"{topic}: a {w} x {h} {enc} image needs {w * dtype.itemsize} bytes a row, "
            f"holds step {step} and {data.size} bytes",
        )
    rows = data[: step * h].reshape(h, step)[:, : w * dtype.itemsize]
    raw = np.ascontiguousarray(rows).view(dtype).reshape(h, w).astype(np.float64)
    depth = raw * DEPTH_SCALE_M[enc]
    depth[~np.isfinite(depth) | (depth <= 0.0)] = 0.0
    return depth.astype(np.float32)


def intrinsics_of(info: Any, bag: Path, topic: str) -> CameraIntrinsics:
    """Pinhole intrinsics from a CameraInfo message; refuses distortion, skew, binning and a region of interest."""
    K = np.asarray(info.k, dtype=float).reshape(3, 3)
    D = np.asarray(info.d, dtype=float)
    if D.size and np.any(D != 0.0):
        raise fail(
            bag,
            f"{topic}: distortion {info.distortion_model} D = {np.round(D, 6).tolist()} is not zero; "
            "only undistorted (rectified) depth is read: record image_rect_raw, whose D is zero",
        )
    ok = K[0, 0] > 0 and K[1, 1] > 0 and K[0, 1] == 0 and np.allclose(K[2], [0, 0, 1]) and np.all(np.isfinite(K))
    if not ok:
        raise fail(bag, f"{topic}: K = {K.ravel().tolist()} is not a pinhole without skew (fx, fy > 0, K[0,1] = 0)")
    if (
        max(int(info.binning_x), 1) != 1
        or max(int(info.binning_y), 1) != 1
        or int(info.roi.width)
        not in (
            0,
            int(info.width),
        )
    ):
        raise fail(bag, f"{topic}: binning or a region of interest is set; valid: full-resolution images only")
    return CameraIntrinsics(int(info.width), int(info.height), K[0, 0], K[1, 1], K[0, 2], K[1, 2])
