"""What the session's shared runs (tests/conftest.py) are made of and hand the scenario tests.

``half_resolution`` is a test-only shortcut: half the cameras' width and height is a quarter of the pixels to
render and deproject, enough for a fault's refusals (an alignment refused, a camera dropped), never for
sub-millimetre seams; a test that uses it says so. ``Preview`` is ``cell preview fence1`` run once.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from cell import pipeline
    from cell.scenario import Scenario


def half_resolution(s: Scenario) -> Scenario:
    """``s`` with every camera at half its resolution (the scenario file keeps its own)."""
    cams = {
        n: c.model_copy(update={"resolution": (c.resolution[0] // 2, c.resolution[1] // 2)})
        for n, c in s.cameras.items()
    }
    return s.model_copy(update={"cameras": cams})


@dataclass(frozen=True)
class Preview:
    """``cell preview fence1 --out folder`` run once: its exit code and stderr, and the run its pictures show."""

    folder: Path
    exit_code: int
    stderr: str
    run: pipeline.WeldRun
