"""Pinhole geometry for tests that check rendered depth images independently of cell.perception."""

from __future__ import annotations

import numpy as np

from cell.geometry import FloatArray
from cell.types import DepthImage


def pixel_rays_W(image: DepthImage) -> FloatArray:
    """(H, W, 3) ray directions in W with unit z in the optical frame (so that p_W = eye + depth * ray)."""
    k = image.intrinsics
    u, v = np.meshgrid(np.arange(k.width), np.arange(k.height))
    rays_C = np.stack([(u - k.cx) / k.fx, (v - k.cy) / k.fy, np.ones(u.shape)], axis=-1)
    return np.asarray(rays_C @ image.X_WC[:3, :3].T)


def deproject(image: DepthImage) -> FloatArray:
    """(H, W, 3) pinhole back-projection of every pixel into W [m] (invalid: camera centre)."""
    return image.X_WC[:3, 3] + image.depth[..., None].astype(float) * pixel_rays_W(image)
