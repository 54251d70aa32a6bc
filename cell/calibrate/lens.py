"""A camera's lens (Brown-Conrady: k1, k2, p1, p2, k3, OpenCV's model) for the packages above the calibration:
pixels seen through it moved to where a pinhole puts them, and an image resampled at given places. OpenCV does the
work (:mod:`cell.calibrate._opencv`)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

from cell.calibrate import _opencv
from cell.geometry import FloatArray


def to_pinhole(px: npt.ArrayLike, K: FloatArray, distortion: Sequence[float]) -> FloatArray:
    """(k, 2) [px] where a pinhole of K puts what the lens (K, distortion) shows at px (k, 2)."""
    return _opencv.undistort_px(np.asarray(px, dtype=float), K, distortion)


def resample(image: npt.ArrayLike, map_x: FloatArray, map_y: FloatArray, *, nearest: bool) -> npt.NDArray[Any]:
    """out[v, u] = image at (map_x[v, u], map_y[v, u]) [px]: bilinear, or the nearest pixel (values that must not
    blend, such as depth); 0 outside the image."""
    return _opencv.remap(image, map_x, map_y, nearest)
