"""The report's values (docs/report.md): numbers rounded with NaN as null, points, a seam's errors against its truth,
and the failure that stopped a run, as every report writes them (:mod:`cell.export.reports.report` and the others)."""

from __future__ import annotations

import enum
import math
from typing import Any

import numpy as np

from cell.errors import CellError
from cell.types import SeamMetrics


def rounded(v: float, nd: int = 6) -> float | None:
    """Round for the report; NaN/inf become null (JSON has no NaN)."""
    return None if not math.isfinite(v) else round(float(v), nd)


def point(p: np.ndarray) -> list[float | None]:
    """A point [m] for the report, to 0.1 um."""
    return [rounded(float(x), 7) for x in p]


def metrics_entry(m: SeamMetrics) -> dict[str, Any]:
    """A seam's errors against its truth [mm] (``error_mm`` in the report)."""
    return {
        "paper_me": rounded(m.paper_me_mm, 4),
        "endpoint": rounded(m.endpoint_mm, 4),
        "lateral": rounded(m.lateral_mm, 4),
        "end_along": [rounded(v, 4) for v in m.end_along_mm],
    }


def error_entry(e: CellError | None) -> dict[str, Any] | None:
    """The failure that stopped a run early (the seams still say why each was not done), or None: its class,
    message and exit code, and the fields it carries (a code, the figure that decided it, the lost cameras)."""
    if e is None:
        return None
    out: dict[str, Any] = {"type": type(e).__name__, "message": e.message, "exit_code": e.exit_code}
    for key, value in vars(e).items():
        if isinstance(value, str | bool | int):  # enum codes are str
            out[key] = str(value) if isinstance(value, enum.Enum) else value
        elif isinstance(value, float):
            out[key] = rounded(value, 6)
        elif isinstance(value, dict) and all(isinstance(v, str) for v in value.values()):
            out[key] = {str(k): v for k, v in value.items()}
    return out
