"""What a locator answers for a seam: its status, a reason code with its detail, the segment and its uncertainty.

Frame ``R`` (robot base), metres.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass, field

import numpy as np

from cell.geometry import FloatArray, readonly


class SeamStatus(enum.StrEnum):
    """What became of a seam."""

    FOUND = "found"
    NOT_VISIBLE = "not_visible"  # no camera can see it by design (against the table): flip the part
    NOT_FOUND = "not_found"  # visible, but the data does not support a seam there
    OCCLUDED = "occluded"  # visible by design, but something the map does not know is in the way: clear it


class Reason(enum.StrEnum):
    """Why a seam is not (or not yet) found, as a code that code and tests read; the detail text says more."""

    UNDERSIDE = "underside"  # against the table: no camera can see it until the part is turned over
    NO_SEARCH = "no_search"  # perception or the map's alignment failed: no seam was searched
    PART_MISSING = "part_missing"  # a part of its joint is not in the cloud
    OCCLUDED = "occluded"  # points the map does not explain stand in front of it
    LOW_CONFIDENCE = "low_confidence"  # found, but too weakly to be reported
    NO_SUPPORT = "no_support"  # the data does not hold the seam's faces or ends
    NOT_SUPPORTED = "not_supported"  # the locator cannot handle this seam's geometry


@dataclass(frozen=True)
class SeamEstimate:
    """A locator's answer for one seam, in frame ``R``.

    reason : the detail, for people; code : the reason as a :class:`Reason` (None for a found seam).
    p_start, p_end : (3,) [m] when ``status`` is FOUND; empty arrays otherwise.
    confidence : in [0, 1]; 0 when not found.
    sigma_m : the locator's own standard error of the seam line across it [m] (inf when it reports none).
    time_s : wall time the locator spent on this seam [s].
    """

    id: str
    status: SeamStatus
    reason: str = ""
    p_start: FloatArray = field(default_factory=lambda: np.zeros(0))
    p_end: FloatArray = field(default_factory=lambda: np.zeros(0))
    confidence: float = 0.0
    time_s: float = 0.0
    sigma_m: float = math.inf
    code: Reason | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "p_start", readonly(self.p_start))
        object.__setattr__(self, "p_end", readonly(self.p_end))
        if self.status is SeamStatus.FOUND and (self.p_start.shape != (3,) or self.p_end.shape != (3,)):
            raise ValueError(f"seam {self.id}: a found seam needs start and end points")
