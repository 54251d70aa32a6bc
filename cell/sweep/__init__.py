"""Tolerance studies: N varied builds of a scenario run through the pipeline (one Ray task each), and per seam
the probability it is found, within the weld tolerance and welded (docs/sweep.md).

Only :mod:`cell.sweep.engine` imports Ray; the rest are values and plain functions.
"""

from __future__ import annotations

from cell.sweep.task import STAGES, Stage, run_task
from cell.sweep.variations import VARY_WORDS, Tolerances, Variation, parse_vary, variation, variations, varied

__all__ = [
    "STAGES",
    "VARY_WORDS",
    "Stage",
    "Tolerances",
    "Variation",
    "parse_vary",
    "run_task",
    "variation",
    "variations",
    "varied",
]
