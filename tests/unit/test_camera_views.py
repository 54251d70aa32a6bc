"""A camera is judged by the others only where they could have seen its points: a face one camera sees and the
others see edge-on or not at all is no disagreement (the eye-in-hand camera, noise-free, on a web the fixed cameras
see edge-on), while a camera whose points hang in the space the others see empty is still dropped."""

from __future__ import annotations

import numpy as np

from cell.geometry import look_at
from cell.perception.camera_health import disagreeing_cameras, seen_by
from cell.types import CameraIntrinsics, Cloud, DepthImage

K = CameraIntrinsics(width=160, height=120, fx=100.0, fy=100.0, cx=79.5, cy=59.5)
X_WR = np.eye(4)


def _looking_down(name: str, x: float, depth_m: float = 1.0) -> DepthImage:
    """A camera 1 m above the point (x, 0, 0) looking straight down on the plane z = 0 it sees everywhere."""
    depth = np.full((K.height, K.width), depth_m, np.float32)
    return DepthImage(name, depth, K, look_at((x, 0.0, 1.0), (x, 0.0, 0.0), up=(0.0, 1.0, 0.0)))


def _grid(z: float, step: float = 0.005, half: float = 0.25) -> np.ndarray:
    g = np.arange(-half, half + 1e-9, step)
    x, y = np.meshgrid(g, g)
    return np.column_stack([x.ravel(), y.ravel(), np.full(x.size, z)])


def _cloud(points: np.ndarray) -> Cloud:
    return Cloud(points, "R")


def test_seen_by_keeps_what_the_camera_could_have_seen() -> None:
    image = _looking_down("a", 0.0)
    p_R = np.array(
        [
            [0.0, 0.0, 0.5],  # in front of the plane it sees: seen
            [0.1, 0.05, 0.0],  # on it: seen
            [0.1, 0.05, -0.005],  # behind it within the tolerance: seen
            [0.0, 0.0, -0.2],  # behind it: hidden
            [2.0, 0.0, 0.0],  # outside its image
            [0.0, 0.0, 1.5],  # behind the camera
        ]
    )
    np.testing.assert_array_equal(seen_by(p_R, image, X_WR, 0.01), [True, True, True, False, False, False])
    blind = DepthImage("a", np.zeros((K.height, K.width), np.float32), K, image.X_WC)
    assert not seen_by(p_R, blind, X_WR, 0.01).any()  # no depth there: it saw nothing to judge by


def test_a_face_hidden_from_the_others_is_no_disagreement() -> None:
    plane, near = _grid(0.0), _grid(0.0, half=0.1)  # what a and b see; the part of it the eye sees too
    y, z = np.meshgrid(np.arange(-0.2, 0.2, 0.005), np.arange(-0.3, -0.01, 0.005))
    face = np.column_stack([np.full(y.size, 0.1), y.ravel(), z.ravel()])  # under the plane: hidden from a and b
    clouds = {
        "a": _cloud(plane),
        "b": _cloud(plane + np.array([0.002, 0.0, 0.0])),
        "eye": _cloud(np.vstack([near, face])),
    }
    views = ({n: _looking_down(n, x) for n, x in (("a", -0.05), ("b", 0.05), ("eye", 0.0))}, X_WR)
    # Judged on everything, the eye's face (under the plane a and b see) outweighs what they share: dropped.
    assert set(disagreeing_cameras(clouds)) == {"eye"}
    assert disagreeing_cameras(clouds, views=views) == {}
    # Points where a and b see empty space (the plane lifted 10 cm) are a disagreement they can judge.
    lifted = dict(clouds, eye=_cloud(np.vstack([near + np.array([0.0, 0.0, 0.1]), face])))
    assert set(disagreeing_cameras(lifted, views=views)) == {"eye"}
