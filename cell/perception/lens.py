"""A depth image through its camera's lens made a pinhole's: each pixel of the pinhole image (the same K) takes the
depth the lens put where its ray lands (Brown-Conrady, :meth:`cell.types.CameraIntrinsics.distort`), the nearest
pixel's (a depth never blends across an edge); 0 where the ray lands outside the image. Everything downstream
(back-projection, sight checks, re-scan views) then holds a pinhole."""

from __future__ import annotations

from dataclasses import replace
from functools import lru_cache

import numpy as np
from scipy.ndimage import map_coordinates

from cell.geometry import FloatArray
from cell.types import CameraIntrinsics, DepthImage

_PINHOLE = (0.0, 0.0, 0.0, 0.0, 0.0)


@lru_cache(maxsize=16)
def _source(k: CameraIntrinsics) -> FloatArray:
    """(2, h, w) the row and column in the lens' image of every pinhole pixel of ``k``."""
    u, v = np.meshgrid(np.arange(k.width, dtype=float), np.arange(k.height, dtype=float))
    x, y = k.distort((u - k.cx) / k.fx, (v - k.cy) / k.fy)
    out = np.stack([y * k.fy + k.cy, x * k.fx + k.cx])
    out.setflags(write=False)
    return out


def undistort(image: DepthImage) -> DepthImage:
    """``image`` as a pinhole of the same K would have taken it (itself when its intrinsics say no distortion)."""
    k = image.intrinsics
    if not k.distorted:
        return image
    depth = map_coordinates(np.asarray(image.depth, dtype=np.float32), _source(k), order=0, mode="constant", cval=0.0)
    return replace(image, depth=depth.astype(np.float32), intrinsics=replace(k, distortion=_PINHOLE))
