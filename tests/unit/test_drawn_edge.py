"""A face the cloud continues past the edge the drawing gives it (cell/perception/align/drawn.py): the flat tee's
cross tube face beside a fillet, scanned as drawn and as built 17 mm further along, on a 2 mm grid with 1 mm noise."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from cell.perception.align.drawn import past_drawn_edge
from cell.weldmap import read_map

MAP = Path(__file__).resolve().parents[2] / "maps" / "tee_flat.dxf"
SEAM = "LONG_TUBE>CROSS_TUBE:+y"


def _face(y_end_m: float, rng: np.random.Generator) -> np.ndarray:
    """The cross tube's -x face (x = 304.8 mm) beside the long tube (y from 25.4 mm to ``y_end_m``), z 0-50.8 mm,
    and the long tube's +y wall beside it (so that what belongs to another part is seen to be left out)."""
    y, z = np.meshgrid(np.arange(0.0254, y_end_m, 0.002), np.arange(0.0, 0.0508, 0.002))
    face = np.column_stack([np.full(y.size, 0.3048), y.ravel(), z.ravel()])
    x, z = np.meshgrid(np.arange(0.25, 0.3048, 0.002), np.arange(0.0, 0.0508, 0.002))
    wall = np.column_stack([x.ravel(), np.full(x.size, 0.0254), z.ravel()])
    P = np.vstack([face, wall])
    return P + rng.normal(0.0, 0.001, P.shape)


def test_a_face_running_past_its_drawn_edge_is_measured_and_one_as_drawn_is_not() -> None:
    m = read_map(MAP)
    seam = m.seam(SEAM)
    rng = np.random.default_rng(5)
    assert past_drawn_edge(m, "CROSS_TUBE", "-x", seam, _face(0.0488, rng), 0.006) is None  # ends where drawn
    past = past_drawn_edge(m, "CROSS_TUBE", "-x", seam, _face(0.0488 + 0.017, rng), 0.006)
    assert past is not None and (past.part, past.face) == ("CROSS_TUBE", "-x")
    # The points 6-17 mm past the edge (those within the 6 mm band are not past it): 5.5 of the grid's columns of 26
    # points; how far past, their 95th percentile: the 17 mm, give or take the noise.
    assert past.past_m == pytest.approx(0.017, abs=1.5e-3)
    assert past.points == pytest.approx(143, rel=0.2)
    assert "up to 16 mm past" in past.describe() or "up to 17 mm past" in past.describe()
    # The long tube's wall lies in no face's plane beyond it: its own face is as drawn.
    assert past_drawn_edge(m, "LONG_TUBE", "+y", seam, _face(0.0488 + 0.017, rng), 0.006) is None
