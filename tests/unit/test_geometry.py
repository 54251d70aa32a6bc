"""The frame and vector helpers of cell.geometry that hot loops use in place of numpy's general ones."""

from __future__ import annotations

import numpy as np

from cell.geometry import cross3


def test_cross3_is_numpys_cross_to_the_bit() -> None:
    rng = np.random.default_rng(7)
    scale = rng.choice([1e-3, 1.0, 1e3], size=(2000, 1))
    for a, b in zip(rng.normal(size=(2000, 3)) * scale, rng.normal(size=(2000, 3)), strict=True):
        assert np.array_equal(cross3(a, b), np.cross(a, b))
    assert np.array_equal(cross3(np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])), [0.0, 0.0, 1.0])
