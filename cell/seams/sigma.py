"""Each locator's sigma: the standard deviation of its seam line across the seam and of each end along it [m].

A sigma is calibrated when about 95 % of the seams a locator finds lie within 2 sigma of their true seam; how each
constant here was chosen, and on what: docs/seams.md section 2 and docs/trust.md section 4."""

from __future__ import annotations

import math

from cell.config.seams import PART_TOLERANCE_M
from cell.types import EndSource

# A member's angle as built [rad], one standard deviation: ISO 13920 class A's angular tolerance for the welded
# constructions' shorter leg up to 400 mm (+-20 arcmin) taken as two sigma. What our locator's tilt prior
# (``OursSettings.tilt_prior_deg``, tighter) holds a face to, the points may not pin: its line carries the rest
# (docs/reference.md section 4).
TILT_TOLERANCE_RAD = math.radians(10.0 / 60.0)
PAPER_SIGMA_M = 0.0009  # both faces of the start read (confidence >= PAPER_FACES_CONFIDENCE)
PAPER_SIGMA_UNSEEN_M = 0.010  # a face of the start not seen: the paper's raw boundary value
PAPER_FACES_CONFIDENCE = 0.9  # the paper locator's confidence when at least its faces were read
RANSAC_SIGMA_M = 0.0016

# Our locator's floor per end source [m], in quadrature with its standard error of the end.
OURS_END_FLOOR_M = {
    EndSource.EDGE: 0.0001,
    EndSource.FACE_END: 0.0002,
    EndSource.OTHER_PART: 0.0001,
    EndSource.DRAWN: 0.0,
}
# How far an as-built gap between two parts may differ from the drawn one [m]: parts placed to about 1 mm (bracket:
# the gusset 0.4 mm and the upright 0.5 mm off, its back 0.9-1.1 mm from the upright where the map draws it on it).
GAP_SIGMA_M = 0.0005
PAPER_START_SIGMA_M = 0.002  # the paper's start along the seam, read on 1 cm voxel faces
RANSAC_END_SIGMA_M = 0.014  # RANSAC's ends: the extent of its inliers along the line on a 1 cm voxel cloud


# How much wider than its fits' standard errors our locator's spread is, across the seam and along it at each
# end: the errors assume independent points, and a depth camera's are not quite (quantised disparity, pixels split
# and merged by the voxel grid, flying pixels at the edges a robust fit still weighs). Calibrated on cells nobody
# tuned for: 200 random cells of seed 1 (benchmarks/bench_trust.py, exact extrinsics, realistic noise, 329 seams):
# 1.4 puts 64 % of the seams within 1 sigma across, 96 % within 2 and 99.4 % within 3 (1.0: 43 / 88 / 96 %); the
# check is seed 0's 200 cells (docs/trust.md).
SE_INFLATION = 1.4


def ours_sigma(se_m: float, floor_m: float) -> float:
    """Our locator's sigma [m]: its statistical standard error ``se_m`` of the line across itself [m], widened by
    :data:`SE_INFLATION`, and the ``floor_m`` [m] for what it cannot see, in quadrature (inf stays inf)."""
    return math.hypot(SE_INFLATION * se_m, floor_m)


# An as-built part may be up to this share of its length longer or shorter than drawn (docs/reference.md, the
# paper's industrial tolerance), so a seam along it too.
LENGTH_SHARE = 0.05


def length_tolerance_m(tolerance_m: float, length_m: float) -> float:
    """How far [m] an as-built seam of drawn length ``length_m`` [m] may be longer or shorter than drawn: the part
    tolerance ``tolerance_m`` [m] and :data:`LENGTH_SHARE` of its length."""
    return tolerance_m + LENGTH_SHARE * length_m


def drawn_end_sigma(tolerance_m: float = PART_TOLERANCE_M, length_m: float = 0.0) -> float:
    """The sigma [m] of an end only the drawn length places, on a seam of drawn length ``length_m`` [m]: the part
    tolerance ``tolerance_m`` [m], and the length's share of it (:data:`LENGTH_SHARE`) spread over both ends."""
    return math.hypot(tolerance_m, 0.5 * LENGTH_SHARE * length_m)


def ours_end_sigma(
    se_m: float,
    source: EndSource,
    against_part: bool = False,
    slope: float = 0.0,
    floor_scale: float = 1.0,
    bias_m: float = 0.0,
) -> float:
    """Our locator's sigma [m] of one end along the seam: its standard error ``se_m`` [m] (widened by
    :data:`SE_INFLATION`) and the floor of its ``source`` in quadrature (:data:`OURS_END_FLOOR_M`; an end the map
    alone places takes :func:`drawn_end_sigma`); an end ``against_part`` (A's hidden side on another part's face, the
    drawn gap short of it) also the as-built gap's uncertainty (:data:`GAP_SIGMA_M`), and an end on a side face at
    an angle to the seam that gap's uncertainty times the face's ``slope`` across face A (a mitred brace's, a
    gusset's sloped side: the end moves along the seam by the slope times the gap's error). ``floor_scale``: the
    floor's share (a close-up's own); ``bias_m`` [m]: what no sample shrinks (an edge's blur and sampling where a
    face's points stop, a section's size tolerance), not widened."""
    sigma = math.hypot(SE_INFLATION * se_m, floor_scale * OURS_END_FLOOR_M[source], slope * GAP_SIGMA_M, bias_m)
    return math.hypot(sigma, GAP_SIGMA_M) if against_part else sigma


def paper_end_sigmas(confidence: float, length_m: float) -> tuple[float, float]:
    """The paper locator's end sigmas [m] (start, end) on a seam drawn ``length_m`` [m] long: its start read on the
    faces (wider when it read none, as across the seam), its end the start plus the map's vector (the drawn
    length's tolerance too)."""
    start = PAPER_START_SIGMA_M if confidence >= PAPER_FACES_CONFIDENCE - 1e-9 else PAPER_SIGMA_UNSEEN_M
    return start, math.hypot(start, drawn_end_sigma(PART_TOLERANCE_M, length_m))


def paper_sigma(confidence: float) -> float:
    """The paper locator's sigma [m] from its confidence (which says which faces it read)."""
    return PAPER_SIGMA_M if confidence >= PAPER_FACES_CONFIDENCE - 1e-9 else PAPER_SIGMA_UNSEEN_M


def ransac_sigma() -> float:
    """RANSAC's sigma [m]: fixed (its runs' spread does not predict its error)."""
    return RANSAC_SIGMA_M


__all__ = [
    "LENGTH_SHARE",
    "OURS_END_FLOOR_M",
    "PAPER_FACES_CONFIDENCE",
    "PAPER_SIGMA_M",
    "PAPER_SIGMA_UNSEEN_M",
    "PAPER_START_SIGMA_M",
    "RANSAC_END_SIGMA_M",
    "RANSAC_SIGMA_M",
    "SE_INFLATION",
    "TILT_TOLERANCE_RAD",
    "drawn_end_sigma",
    "length_tolerance_m",
    "ours_end_sigma",
    "ours_sigma",
    "paper_end_sigmas",
    "paper_sigma",
    "ransac_sigma",
]
