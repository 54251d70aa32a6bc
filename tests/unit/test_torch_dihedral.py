"""The torch on the bisector of any fillet: a mitred brace's acute and obtuse corners, not only the square T."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cell.process.torch import fillet_angle, measured_angles, torch_rotation


def _corner(theta_deg: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Seam along y; face B the floor (n_b = +z); face A rising from it at theta from the floor, its outward
    normal turned towards the fillet."""
    th = math.radians(theta_deg)
    d = np.array([0.0, 1.0, 0.0])
    n_b = np.array([0.0, 0.0, 1.0])
    n_a = np.array([math.sin(th), 0.0, -math.cos(th)])  # face A runs along (cos th, 0, sin th) from the seam
    return d, n_a, n_b


@pytest.mark.parametrize("theta", [35.0, 55.0, 90.0, 125.0, 150.0])
def test_fillet_angle_and_the_torch_on_its_bisector(theta: float) -> None:
    d, n_a, n_b = _corner(theta)
    assert math.degrees(fillet_angle(d, n_a, n_b)) == pytest.approx(theta, abs=1e-9)
    R = torch_rotation(d, n_a, n_b, math.radians(45.0), 0.0)
    half = math.radians(theta / 2.0)
    bisector = np.array([-math.cos(half), 0.0, -math.sin(half)])  # into the corner, halfway between the faces
    assert np.allclose(R[:, 2], bisector, atol=1e-12)
    work, travel = measured_angles(np.block([[R, np.zeros((3, 1))], [np.zeros((1, 3)), np.ones((1, 1))]]), d, n_a, n_b)
    assert math.degrees(work) == pytest.approx(45.0, abs=1e-9) and travel == pytest.approx(0.0, abs=1e-12)


def test_a_square_fillet_keeps_its_exact_pose() -> None:
    d, n_a, n_b = _corner(90.0)
    assert fillet_angle(d, n_a, n_b) == 0.5 * math.pi
    R = torch_rotation(d, n_a, n_b, math.radians(40.0), math.radians(-10.0))
    w = math.radians(40.0)
    u = math.cos(w) * np.array([1.0, 0.0, 0.0]) + math.sin(w) * n_b
    assert np.allclose(R[:, 2], -math.cos(math.radians(-10.0)) * u + math.sin(math.radians(-10.0)) * d, atol=1e-15)
