"""A located curved seam's derived figures: tangents, length and the largest sigma, open and closed."""

import math

import numpy as np
import pytest

from cell.types import CurveEstimate, SeamStatus


def _circle(n: int, r: float) -> np.ndarray:
    t = np.linspace(0.0, 2.0 * math.pi, n, endpoint=False)
    return np.stack([r * np.cos(t), r * np.sin(t), np.zeros(n)], axis=1)


def test_a_closed_circle_has_its_length_and_tangents() -> None:
    p = _circle(400, 0.05)
    up = np.tile([0.0, 0.0, 1.0], (400, 1))
    e = CurveEstimate(
        "c",
        SeamStatus.FOUND,
        p_RS=p,
        n_abutting_R=p / 0.05,
        n_receiving_R=up,
        closed=True,
        sigma_m=np.full(400, 1e-4),
        end_sigma_m=(0.0, 0.0),
    )
    assert e.length_m == pytest.approx(2 * math.pi * 0.05, rel=1e-4)
    # the tangent is perpendicular to the radius everywhere, the wrap included
    assert np.abs(np.sum(e.tangent_R * p, axis=1)).max() < 1e-9
    assert e.sigma_max_m == pytest.approx(1e-4)


def test_an_open_arc_is_shorter_and_a_found_curve_needs_its_normals() -> None:
    p = _circle(400, 0.05)[:100]
    up = np.tile([0.0, 0.0, 1.0], (100, 1))
    e = CurveEstimate(
        "a", SeamStatus.FOUND, p_RS=p, n_abutting_R=p / 0.05, n_receiving_R=up, sigma_m=np.full(100, 2e-4)
    )
    assert e.length_m == pytest.approx(2 * math.pi * 0.05 * 99 / 400, rel=1e-4)
    with pytest.raises(ValueError, match="normals"):
        CurveEstimate("b", SeamStatus.FOUND, p_RS=p, n_abutting_R=p[:10], n_receiving_R=up, sigma_m=np.zeros(100))
    assert math.isinf(CurveEstimate("d", SeamStatus.NOT_FOUND).sigma_max_m)
