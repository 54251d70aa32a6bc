"""Errors carry their data: a code and the figure that decided, read by code and written into the report."""

from __future__ import annotations

import math

import pytest

from cell.errors import AlignmentError, AlignmentFailure, CellError, SensorError
from cell.export.report import _error


def test_an_alignment_failure_carries_its_code_and_figures_into_the_report() -> None:
    e = AlignmentError("fitness 0.496 < 0.500", code=AlignmentFailure.LOW_FITNESS, value=0.4961, needed=0.5)
    assert isinstance(e, RuntimeError) and e.exit_code == 14
    rep = _error(e)
    assert rep == {
        "type": "AlignmentError",
        "message": "fitness 0.496 < 0.500",
        "exit_code": 14,
        "code": "low_fitness",
        "value": 0.4961,
        "needed": 0.5,
    }


def test_a_sensor_failure_names_every_lost_camera() -> None:
    e = SensorError("no usable camera", lost={"cam_left": "0 valid pixels", "cam_right": "frozen"})
    assert _error(e)["lost"] == {"cam_left": "0 valid pixels", "cam_right": "frozen"}  # type: ignore[index]
    assert _error(SensorError("no images"))["lost"] == {}  # type: ignore[index]


def test_messages_are_one_line_and_fields_default_to_nan() -> None:
    e = AlignmentError("the map\n   shifted 76 mm\tfits better", code=AlignmentFailure.AMBIGUOUS)
    assert e.message == "the map shifted 76 mm fits better"
    assert math.isnan(e.value) and math.isnan(e.needed)
    with pytest.raises(TypeError):
        AlignmentError("no code")  # type: ignore[call-arg]
    assert _error(None) is None and _error(CellError("x"))["exit_code"] == 1  # type: ignore[index]
