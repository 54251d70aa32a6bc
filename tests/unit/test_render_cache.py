"""The simulator's kept images (cell/sim/render_cache.py): the same scene from the same camera is read back to the
bit, any change a camera could see is drawn afresh, and a scene the key cannot describe is never kept."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from test_sim import tiny_scenario

from cell.geometry import make_pose, pose_from_xyz_rpy
from cell.sim import SimCell
from cell.sim.bodies import add_mesh
from cell.sim.render_cache import RenderCache, draw, scene_key
from cell.types import Box, Part
from cell.types.solid import Polyhedron

BOX = Box(pose_from_xyz_rpy([0.05, 0.02, 0.95], [0.0, 0.0, math.radians(20.0)]), np.array([0.2, 0.1, 0.1]))
PRISM = np.array([[0.2, 0.1, 0.9], [0.3, 0.1, 0.9], [0.25, 0.2, 0.9], [0.25, 0.15, 1.0]])  # a tetrahedron on the table
FACES = np.array([[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]])


def _image(sim: SimCell, cache: RenderCache, camera: str = "oblique") -> tuple[np.ndarray, np.ndarray]:
    spec = sim.camera_spec(camera)
    return draw(sim.client, sim._drawn, spec.X_WC, sim.intrinsics(camera), spec.near_m, spec.far_m, cache)


def test_the_same_scene_is_read_back_to_the_bit_from_another_cell_and_a_moved_body_is_drawn_afresh(
    tmp_path: Path,
) -> None:
    cache = RenderCache()
    sc = tiny_scenario(tmp_path)
    with SimCell(sc, [Part("BOX", BOX)]) as a:
        rgb, _ = _image(a, cache)
        rgb[:] = 0  # the caller's copy: what is kept stays as drawn
    with SimCell(sc, [Part("BOX", BOX)]) as b:
        again = _image(b, cache)
        assert (cache.hits, cache.misses) == (1, 1)
        spec = b.camera_spec("oblique")
        drawn = draw(b.client, b._drawn, spec.X_WC, b.intrinsics("oblique"), spec.near_m, spec.far_m, RenderCache())
        assert np.array_equal(again[0], drawn[0]) and np.array_equal(again[1], drawn[1])
        assert again[0].any()  # the kept copy, not the caller's zeroed one
        b.place("BOX", make_pose(p=[0.1, 0.0, 0.95]))  # the box moved 5 cm: a new image
        moved = _image(b, cache)
        assert cache.misses == 2 and not np.array_equal(moved[1], drawn[1])
        assert not np.array_equal(_image(b, cache, "odd")[1], moved[1]) and cache.misses == 3  # another camera


def test_a_mesh_body_is_kept_by_its_vertices_and_an_unregistered_one_is_never_kept(tmp_path: Path) -> None:
    cache = RenderCache()
    sc = tiny_scenario(tmp_path)
    lifted = PRISM + np.array([0.0, 0.0, 0.02])
    with SimCell(sc, [Part("P", Polyhedron(PRISM, FACES))]) as a:
        first = _image(a, cache)
    with SimCell(sc, [Part("P", Polyhedron(lifted, FACES))]) as b:  # the same body id and pose kind, other vertices
        second = _image(b, cache)
        assert cache.misses == 2 and not np.array_equal(first[1], second[1])
        add_mesh(b.client, PRISM + np.array([0.3, 0.0, 0.0]), FACES, (1.0, 0.0, 0.0, 1.0))  # not through the cell
        spec = b.camera_spec("oblique")
        assert scene_key(b.client, b._drawn, spec.X_WC, b.intrinsics("oblique"), spec.near_m, spec.far_m) is None
        _image(b, cache)
        _image(b, cache)
        assert (cache.hits, cache.misses) == (0, 2)  # drawn twice, asked of the cache never


def test_the_least_recently_used_images_go_beyond_the_byte_budget(tmp_path: Path) -> None:
    one = 320 * 240 * (3 + 8)  # a colour and a depth image of the oblique camera
    cache = RenderCache(max_bytes=2 * one)
    with SimCell(tiny_scenario(tmp_path), [Part("BOX", BOX)]) as sim:
        for x in (0.0, 0.1, 0.2):
            sim.place("BOX", make_pose(p=[x, 0.0, 0.95]))
            _image(sim, cache)
        sim.place("BOX", make_pose(p=[0.2, 0.0, 0.95]))
        _image(sim, cache)
        assert cache.hits == 1
        sim.place("BOX", make_pose(p=[0.0, 0.0, 0.95]))
        _image(sim, cache)
        assert cache.hits == 1 and cache.misses == 4  # the first was dropped


@pytest.mark.parametrize("near_m", [0.1, 0.2])
def test_the_clip_planes_are_part_of_the_key(tmp_path: Path, near_m: float) -> None:
    with SimCell(tiny_scenario(tmp_path), [Part("BOX", BOX)]) as sim:
        spec = sim.camera_spec("oblique")
        K = sim.intrinsics("oblique")
        assert scene_key(sim.client, sim._drawn, spec.X_WC, K, near_m, 4.0) != scene_key(
            sim.client, sim._drawn, spec.X_WC, K, near_m + 0.05, 4.0
        )
