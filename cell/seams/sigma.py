"""Each locator's sigma: the standard deviation of its seam line across the seam [m], calibrated on the scenarios.

A sigma is calibrated when about 95 % of the seams a locator finds lie within 2 sigma of their true seam (lateral
error, what the torch feels). ``benchmarks/bench_coverage.py`` measures that on fence1-exact, fence1 and fence2
(seeds 0-2, realistic noise) and on fence1's fault variants (``benchmarks/results/coverage.json``); the constants
here were chosen from its rows:

- ours: its own statistical standard error (the faces' offsets through the angle between them) is too small
  alone (88 % within 2 sigma on the three scenarios: it cannot see the cameras' calibration, the voxel order, the
  part's tilt). Combined in quadrature with a floor of 0.05 mm (``OursSettings.sigma_floor_m``) it covers 96 %
  (lateral) and 95 % (endpoint); 0.03 mm covers 93 % / 89 %. Up close the floor is the close-up's own (the re-scan
  sets it, :data:`cell.config.rescan.CLOSEUP_OURS_OPTIONS`).
- the paper's method: nothing it computes predicts its error (the start read on 1 cm voxel faces, the end from
  the map's vector), so the sigma is fixed by what it saw: both faces read (confidence 0.9 or more: 95th
  percentile of the lateral error 1.7 mm on the scenarios, 3.6 mm on the faults) 0.9 mm; a face not seen
  (confidence below 0.9: the raw boundary value, up to 29 mm off on the faults) 10 mm.
- RANSAC: the spread of its runs does not rank its errors (Spearman 0.24 on the scenarios, 0.02 on the faults),
  and its plane fits' residuals are those of a 1 cm voxel cloud, not of its bias; fixed at 1.6 mm (95th
  percentile of the lateral error 3.2 mm on the scenarios, 2.6 mm on the faults).

The weld gate (:mod:`cell.pipeline.weld`) welds a seam only when ``rescan.bound_sigmas`` sigma is within
``rescan.weld_tolerance_mm``.
"""

from __future__ import annotations

import math

PAPER_SIGMA_M = 0.0009  # both faces of the start read (confidence >= PAPER_FACES_CONFIDENCE)
PAPER_SIGMA_UNSEEN_M = 0.010  # a face of the start not seen: the paper's raw boundary value
PAPER_FACES_CONFIDENCE = 0.9  # the paper locator's confidence when at least its faces were read
RANSAC_SIGMA_M = 0.0016


def ours_sigma(se_m: float, floor_m: float) -> float:
    """Our locator's sigma [m]: its statistical standard error ``se_m`` of the line across itself [m] and the
    ``floor_m`` [m] for what it cannot see, in quadrature (inf stays inf)."""
    return math.hypot(se_m, floor_m)


def paper_sigma(confidence: float) -> float:
    """The paper locator's sigma [m] from its confidence (which says which faces it read)."""
    return PAPER_SIGMA_M if confidence >= PAPER_FACES_CONFIDENCE - 1e-9 else PAPER_SIGMA_UNSEEN_M


def ransac_sigma() -> float:
    """RANSAC's sigma [m]: fixed (its runs' spread does not predict its error)."""
    return RANSAC_SIGMA_M


__all__ = [
    "PAPER_FACES_CONFIDENCE",
    "PAPER_SIGMA_M",
    "PAPER_SIGMA_UNSEEN_M",
    "RANSAC_SIGMA_M",
    "ours_sigma",
    "paper_sigma",
    "ransac_sigma",
]
