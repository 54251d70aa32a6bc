"""The floor put into the simulator's images after TinyRenderer (cell/sim/floor.py): the pixels, colour and depth
TinyRenderer gives the floor's face when it draws it, at a fraction of the cost."""

from __future__ import annotations

import math

import numpy as np

from cell.geometry import make_pose
from cell.sim.bodies import add_box, add_floor
from cell.sim.camera import intrinsics_for
from cell.sim.floor import Floor, floor_colour
from cell.sim.quiet import BulletClient, pybullet
from cell.sim.render_cache import RenderCache, draw
from cell.types import Box

FLOOR_RGBA = (0.35, 0.35, 0.35, 1.0)
FLOOR = Box(make_pose(p=(0.0, 0.0, -0.01)), np.array([20.0, 20.0, 0.02]))
TABLE = Box(make_pose(p=(0.2, 0.1, 0.45)), np.array([1.2, 0.8, 0.9]))


def _image(floor_drawn: bool, X_WC: np.ndarray, far_m: float) -> tuple[np.ndarray, np.ndarray]:
    client = BulletClient(connection_mode=pybullet.DIRECT)
    try:
        add_floor(client, FLOOR, FLOOR_RGBA, drawn=floor_drawn)
        add_box(client, TABLE, (0.55, 0.45, 0.35, 1.0))
        k = intrinsics_for(320, 240, math.radians(65.0))
        floor = None if floor_drawn else Floor(0.0, (10.0, 10.0), floor_colour(FLOOR_RGBA))
        return draw(client, {}, X_WC, k, 0.1, far_m, RenderCache(), floor=floor)
    finally:
        client.disconnect()


def _looking(eye: list[float], target: list[float]) -> np.ndarray:
    z = np.subtract(target, eye) / np.linalg.norm(np.subtract(target, eye))
    x = np.cross(z, [0.0, 0.0, 1.0])
    x /= np.linalg.norm(x)
    return make_pose(np.column_stack([x, np.cross(z, x), z]), eye)


def test_the_floor_is_where_tinyrenderer_draws_it_in_its_colour_within_20_um() -> None:
    """Two views: one down over the table with the floor round it, one low and long whose far floor passes the far
    plane (left empty) and whose horizon leaves sky: the same pixels covered and coloured, the floor's depth
    within 20 um (TinyRenderer's depth buffer rounds it by up to 10 um at 4 m), everything else to the bit."""
    for eye, target, far_m in (([1.6, -1.3, 2.0], [0.2, 0.1, 0.9], 4.0), ([2.5, -2.5, 0.6], [-2.0, 2.0, 0.0], 6.0)):
        X_WC = _looking(eye, target)
        rgb_ref, depth_ref = _image(True, X_WC, far_m)
        rgb, depth = _image(False, X_WC, far_m)
        floor = np.all(rgb_ref == floor_colour(FLOOR_RGBA), axis=-1) & (depth_ref > 0)
        assert floor.sum() > 5000 and (depth_ref == 0).sum() > 1000  # both in view: floor, and nothing
        assert np.array_equal(depth_ref == 0, depth == 0) and np.array_equal(rgb_ref, rgb)
        assert np.array_equal(depth_ref[~floor], depth[~floor])
        assert np.abs(depth_ref[floor] - depth[floor]).max() < 2e-5
