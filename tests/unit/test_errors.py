"""Errors carry their data: a code and the figure that decided, read by code and written into the report; the one
table of exit codes (docs/architecture.md section 4) is what the error classes carry."""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest

from cell import errors
from cell.cli.krl import EXIT_CHECK_FAILED
from cell.errors import AlignmentError, AlignmentFailure, CellError, SensorError
from cell.export.reports.report_values import error_entry


def test_an_alignment_failure_carries_its_code_and_figures_into_the_report() -> None:
    e = AlignmentError("fitness 0.496 < 0.500", code=AlignmentFailure.LOW_FITNESS, value=0.4961, needed=0.5)
    assert isinstance(e, RuntimeError) and e.exit_code == 14
    rep = error_entry(e)
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
    assert error_entry(e)["lost"] == {"cam_left": "0 valid pixels", "cam_right": "frozen"}  # type: ignore[index]
    assert error_entry(SensorError("no images"))["lost"] == {}  # type: ignore[index]


def test_messages_are_one_line_and_fields_default_to_nan() -> None:
    e = AlignmentError("the map\n   shifted 76 mm\tfits better", code=AlignmentFailure.AMBIGUOUS)
    assert e.message == "the map shifted 76 mm fits better"
    assert math.isnan(e.value) and math.isnan(e.needed)
    with pytest.raises(TypeError):
        AlignmentError("no code")  # type: ignore[call-arg]
    assert error_entry(None) is None and error_entry(CellError("x"))["exit_code"] == 1  # type: ignore[index]


def _exit_code_table() -> list[tuple[list[str], int]]:
    """The rows of docs/architecture.md section 4: the classes each names (backticked) and its exit code."""
    text = (Path(__file__).resolve().parents[2] / "docs" / "architecture.md").read_text(encoding="utf-8")
    section = text.split("## 4. Errors and exit codes", 1)[1].split("\n## ", 1)[0]
    rows = re.findall(r"^\| (.+?) \| (\d+) \| .+ \|$", section, flags=re.M)
    return [(re.findall(r"`(\w+Error)", names), int(code)) for names, code in rows]


def test_the_one_table_of_exit_codes_is_what_the_code_raises() -> None:
    table = _exit_code_table()
    named = {name: code for names, code in table for name in names}
    classes = {
        name: obj
        for name, obj in vars(errors).items()
        if isinstance(obj, type) and issubclass(obj, CellError) and obj is not CellError
    }
    assert not sorted(set(classes) - set(named)), "an error class of cell/errors.py missing from the table"
    wrong = {n: (named[n], c.exit_code) for n, c in classes.items() if named[n] != c.exit_code}
    assert not wrong, f"docs/architecture.md section 4 gives other exit codes than cell/errors.py: {wrong}"
    constants = {errors.EXIT_OK, errors.EXIT_INTERNAL, errors.EXIT_USAGE, errors.EXIT_PARTIAL, errors.EXIT_INTERRUPTED}
    constants |= {errors.EXIT_HANGUP, errors.EXIT_TERMINATED}  # cell weld's stop signals (cell/journal/signals.py)
    codes = [code for _, code in table]
    assert len(codes) == len(set(codes)), "one row per exit code"
    assert set(codes) == constants | {c.exit_code for c in classes.values()} | {EXIT_CHECK_FAILED}
