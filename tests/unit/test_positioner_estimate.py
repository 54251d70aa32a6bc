"""What a positioner would take for the operator's turn (cell/planning/positioner.py): one axis from rest to rest."""

from __future__ import annotations

import math

import pytest

from cell.config.motion import PositionerFigures
from cell.planning.positioner import positioner_turn_s


def test_a_half_turn_takes_a_few_seconds_and_grows_with_the_angle() -> None:
    half, quarter = positioner_turn_s(math.pi), positioner_turn_s(-math.pi / 2.0)
    f = PositionerFigures()
    assert math.pi / f.speed < half < math.pi / f.speed + f.speed / f.accel + f.accel / f.jerk + 1e-9
    assert quarter < half and positioner_turn_s(math.pi / 2.0) == pytest.approx(quarter)  # either way round
    slow = PositionerFigures(speed=f.speed / 2.0)
    assert positioner_turn_s(math.pi, slow) > half + 1.0
    assert positioner_turn_s(0.0) == 0.0
