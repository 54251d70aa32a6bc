"""The planes our locator fits for one seam (frame R, metres): the weld faces, the ends, a plane's support for one
fit, and what a seam's pass asks the batched fit for (:mod:`cell.seams.ours.locator`)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray
from cell.seams.ours._points import Points

IntArray = npt.NDArray[np.intp]


@dataclass
class Face:
    """A plane being fitted: unit normal n (3,), offset d [m], noise scale [m], offset standard error [m]."""

    n: FloatArray
    d: float
    scale: float
    name: str
    se: float = float("inf")
    count: int = 0
    source: str = "points"  # or "edge of <face>" (an adjacent face of the same part)
    area: float = 0.0  # area of its support region [m^2] (what a head-on view would fill with points)
    note: str = ""  # how well an edge placed it (for the reason)


@dataclass
class End:
    """One end of the seam: a plane across the line (A's side face or the table), or the extent of face A."""

    n: FloatArray
    d: float
    on_table: bool
    s: float = 0.0  # parameter along the line [m]
    se: float = float("inf")
    scale: float = 0.003  # noise of the side face's points [m]
    source: str = "map"


@dataclass
class Selection:
    """A plane's support for one fit: the plane (a weld face or a side face at an end), the residuals r (n,) of
    all the seam's points from it [m], the indices of its support and of the points fitted (an even stride of
    the support above ``max_fit_points``), the points it needs; after the fit: whether it was fitted, the
    offset it moved by [m], the offset's standard error [m] and the fitted points' weights."""

    plane: Face | End
    r: FloatArray
    sel: IntArray
    fit: IntArray
    need: int = 0
    ok: bool = False
    offset: float = 0.0
    se: float = float("inf")
    weights: FloatArray = field(default_factory=lambda: np.zeros(0))


@dataclass(frozen=True)
class FitRequest:
    """What one seam's pass needs fitted: its planes' selections of ``pts``, whether it is the first pass, and
    the tilt steps to take after the fit (selection, face, the other weld face, p0 (3,) and t (3,) of the
    line)."""

    selections: list[Selection]
    pts: Points
    first: bool
    tilts: list[tuple[Selection, Face, Face, FloatArray, FloatArray]]


def thin(idx: IntArray, cap: int) -> IntArray:
    """An even stride of the indices ``idx`` leaving at most about ``cap`` of them (deterministic)."""
    return idx[:: len(idx) // cap] if len(idx) > 2 * cap else idx
