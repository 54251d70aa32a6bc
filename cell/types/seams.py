"""What a locator answers for a seam: its status, a reason code with its detail, the segment and its uncertainty.

Frame ``R`` (robot base), metres.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Callable, Mapping
from dataclasses import asdict, dataclass, field
from functools import cached_property
from typing import Any

import numpy as np

from cell.geometry import FloatArray, readonly
from cell.types.map import WeldMap
from cell.types.sensing import Cloud, VoxelTable


class SeamStatus(enum.StrEnum):
    """What became of a seam."""

    FOUND = "found"
    NOT_VISIBLE = "not_visible"  # no camera can see it by design (against the table): turn the part over
    NOT_FOUND = "not_found"  # visible, but the data does not support a seam there
    OCCLUDED = "occluded"  # visible by design, but something the map does not know is in the way: clear it
    NOT_SUPPORTED = "not_supported"  # drawn in the map, but not a seam the cell can weld (a curve): never searched


class Reason(enum.StrEnum):
    """Why a seam is not (or not yet) found, as a code that code and tests read; the detail text says more."""

    UNDERSIDE = "underside"  # against the table: no camera can see it until the part is turned over
    NO_SEARCH = "no_search"  # perception or the map's alignment failed: no seam was searched
    PART_MISSING = "part_missing"  # a part of its joint is not in the cloud
    OCCLUDED = "occluded"  # points the map does not explain stand in front of it
    LOW_CONFIDENCE = "low_confidence"  # found, but too weakly to be reported
    NO_SUPPORT = "no_support"  # the data does not hold the seam's faces or ends
    NOT_SUPPORTED = "not_supported"  # the locator cannot handle this seam's geometry
    LENGTH_MISMATCH = "length_mismatch"  # the located length disagrees with the drawn one beyond the part tolerance


class EndSource(enum.StrEnum):
    """How a locator placed one end of a seam along it (its sigma follows from it: ``cell/seams/sigma.py``)."""

    EDGE = "edge"  # an edge seen: face A's own side face fitted where it meets the weld face, or a face's sharp edge
    FACE_END = "face_end"  # a face seen ending: the extent of face A's points along the seam
    OTHER_PART = "other_part"  # another part's face (a part it ends against, the table)
    DRAWN = "drawn"  # only the drawn length from the aligned map (the part tolerance is its sigma)


@dataclass(frozen=True)
class SeamEstimate:
    """A locator's answer for one seam, in frame ``R``.

    reason : the detail, for people; code : the reason as a :class:`Reason` (None for a found seam).
    p_start, p_end : (3,) [m] when ``status`` is FOUND; empty arrays otherwise.
    confidence : in [0, 1]; 0 when not found.
    sigma_m : the locator's calibrated standard deviation of the seam line across it [m] (``cell/seams/sigma.py``;
        inf when it gives none).
    time_s : wall time the locator spent on this seam [s].
    end_sigma_m : (start, end) the calibrated standard deviation of each end ALONG the seam [m] (inf when not
        given).
    end_source : (start, end) how each end was placed (:class:`EndSource`).
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
    end_sigma_m: tuple[float, float] = (math.inf, math.inf)
    end_source: tuple[EndSource, EndSource] = (EndSource.DRAWN, EndSource.DRAWN)

    def __post_init__(self) -> None:
        object.__setattr__(self, "p_start", readonly(self.p_start))
        object.__setattr__(self, "p_end", readonly(self.p_end))
        if self.status is SeamStatus.FOUND and (self.p_start.shape != (3,) or self.p_end.shape != (3,)):
            raise ValueError(f"seam {self.id}: a found seam needs start and end points")


@dataclass(frozen=True)
class Joint:
    """How a seam of the map is made: the edge of one part's face meeting another part's face.

    abutting : name of the part whose end meets the other (part A); the seam runs along an edge of its end face.
    receiving : name of the part it meets (part B); the seam lies on one of B's faces.
    face_abutting : A's box face (``"+x"``...``"-z"``) that meets B at the seam (for a T fillet, the face the torch
        sees on A, e.g. its top ``"+z"``).
    face_receiving : B's box face the seam lies on (its outward normal points towards A).
    end_face : A's face that faces B across the gap (parallel to ``face_receiving``).
    """

    seam_id: str
    abutting: str
    receiving: str
    face_abutting: str
    face_receiving: str
    end_face: str


@dataclass(frozen=True)
class SeamScene:
    """Everything a locator may look at, all in the robot frame R.

    voxel : the spliced, filtered, voxel-downsampled cloud (what the paper's method uses), or what makes it on
        first use (perception's merge, which a locator that never reads ``cloud`` never pays for); read it as
        ``cloud``.
    dense : every camera's registered, filtered points, not merged and not downsampled (full resolution, per-point
        camera index): what our locator and the map alignment read.
    weldmap : the welding map aligned to the cloud (frame ``"R"``).
    joints : seam id -> :class:`Joint`.
    table_z : height of the table top in R [m] (seams against it cannot be seen).
    dense_voxels : where the voxels of ``dense`` lie in it, when perception handed it on in voxel order (None:
        a locator that needs it orders ``dense`` itself).
    eyes_R : camera name (of ``dense.cameras``) -> its optical centre (3,) in R [m], where known: a camera sees a
        face only from in front of it (a hollow tube's inner wall, seen down its bore, is not its outer face).
    cache : per-scene scratch space a locator may fill once and reuse for every seam (e.g. a KD-tree);
        it is the one mutable member, and only ever holds values derived from the fields above.
    """

    voxel: Cloud | Callable[[], Cloud]
    dense: Cloud
    weldmap: WeldMap
    joints: Mapping[str, Joint]
    table_z: float
    dense_voxels: VoxelTable | None = None
    eyes_R: Mapping[str, FloatArray] = field(default_factory=dict)
    cache: dict[str, Any] = field(default_factory=dict, compare=False, repr=False)

    @cached_property
    def cloud(self) -> Cloud:
        """The voxel-downsampled cloud (``voxel``, made on first read when it is a function)."""
        return self.voxel if isinstance(self.voxel, Cloud) else self.voxel()


@dataclass(frozen=True)
class SeamMetrics:
    """One seam's errors [mm] (NaN when the seam was not found) and the locator's time [ms].

    end_along_mm : each end's signed error along the true seam (start, end) [mm]: positive past the true end,
        negative short of it (``cell/seams/metrics.py``).
    """

    id: str
    status: SeamStatus
    paper_me_mm: float
    endpoint_mm: float
    lateral_mm: float
    time_ms: float
    swapped: bool = False
    end_along_mm: tuple[float, float] = (math.nan, math.nan)

    @property
    def found(self) -> bool:
        return self.status is SeamStatus.FOUND


@dataclass(frozen=True)
class MetricsSummary:
    """Summary over a set of seams.

    seams : all seams; visible : those not NOT_VISIBLE (the locator ran on them); found : FOUND ones.
    Errors [mm] are over the found seams (NaN when none); the median time [ms] is over the visible seams.
    """

    seams: int
    visible: int
    found: int
    paper_me_mean_mm: float
    paper_me_p95_mm: float
    endpoint_mean_mm: float
    lateral_mean_mm: float
    time_ms_per_seam_median: float

    def as_dict(self) -> dict[str, float | int]:
        return asdict(self)
