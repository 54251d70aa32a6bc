"""The floor in the simulator's images, put in after TinyRenderer has drawn the rest (docs/bodies.md section 1).

The floor is a plane z = 0 in W bounded by a square; TinyRenderer walks the screen rectangle of every triangle it
draws, and the floor's two triangles span the whole screen of every camera that sees it, so drawing it costs 40 %
of a 1280 x 720 image of fence1. Its pixels are those that no other body covers and whose ray meets the plane
within its square and the camera's clip planes: the same pixels TinyRenderer covers, with the depth along the ray
(TinyRenderer's own depth buffer carries up to 10 um of rounding there) and the colour TinyRenderer gives the
plane, which depends on its RGBA and not on the viewpoint (no specular term, no shadows)."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray
from cell.sim.quiet import BulletClient, pybullet, silenced_fds
from cell.types import CameraIntrinsics


@dataclass(frozen=True)
class Floor:
    """The floor plane z = ``z_m`` in W, within |x|, |y| <= ``half_m`` [m], drawn in ``rgb`` (the colour TinyRenderer
    shades a plane of that RGBA, facing up)."""

    z_m: float
    half_m: tuple[float, float]
    rgb: tuple[int, int, int]

    def fill(
        self,
        rgb: npt.NDArray[np.uint8],
        depth_m: FloatArray,
        X_WC: FloatArray,
        intrinsics: CameraIntrinsics,
        near_m: float,
        far_m: float,
    ) -> tuple[npt.NDArray[np.uint8], FloatArray]:
        """Colour (H, W, 3) and depth (H, W) [m] along the optical axis with the floor where nothing nearer was
        drawn (depth 0) and a pixel's ray meets it between ``near_m`` and ``far_m``; written in place, returned."""
        u = (np.arange(intrinsics.width) - intrinsics.cx) / intrinsics.fx
        v = (np.arange(intrinsics.height) - intrinsics.cy) / intrinsics.fy
        R, o = np.asarray(X_WC)[:3, :3], np.asarray(X_WC)[:3, 3]

        def along(i: int) -> FloatArray:  # the W coordinate i of each pixel's ray at depth 1 (optical z = 1)
            return np.asarray(R[i, 0] * u[None, :] + R[i, 1] * v[:, None] + R[i, 2])

        dz = along(2)
        down = (depth_m == 0.0) & (dz < 0.0)
        t = np.where(down, (self.z_m - o[2]) / np.where(down, dz, -1.0), -1.0)
        hit = down & (t >= near_m) & (t < far_m)
        hit &= np.abs(o[0] + t * along(0)) <= self.half_m[0]
        hit &= np.abs(o[1] + t * along(1)) <= self.half_m[1]
        depth_m[hit] = t[hit]
        rgb[hit] = self.rgb
        return rgb, depth_m


@cache
def floor_colour(rgba: tuple[float, float, float, float]) -> tuple[int, int, int]:
    """The colour TinyRenderer draws an up-facing plane of ``rgba`` in: a 2 x 2 image of one, straight down, in a
    simulator of its own (the cell's bodies and ids untouched)."""
    with silenced_fds():
        client = BulletClient(connection_mode=pybullet.DIRECT)
    try:
        top = [[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [1.0, 1.0, 0.0], [-1.0, 1.0, 0.0]]
        visual = client.createVisualShape(
            pybullet.GEOM_MESH, vertices=top, indices=[0, 1, 2, 0, 2, 3], normals=[[0.0, 0.0, 1.0]] * 4,
            rgbaColor=list(rgba),
        )  # fmt: skip
        client.createMultiBody(baseMass=0.0, baseVisualShapeIndex=visual)
        view = client.computeViewMatrix([0.0, 0.0, 1.0], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0])
        proj = client.computeProjectionMatrixFOV(30.0, 1.0, 0.1, 2.0)
        _, _, pixels, _, _ = client.getCameraImage(
            2, 2, viewMatrix=view, projectionMatrix=proj, renderer=pybullet.ER_TINY_RENDERER,
            flags=pybullet.ER_NO_SEGMENTATION_MASK,
        )  # fmt: skip
    finally:
        client.disconnect()
    r, g, b = np.asarray(pixels, dtype=np.uint8).reshape(2, 2, 4)[0, 0, :3]
    return int(r), int(g), int(b)
