"""Options of the close-up re-scan (:mod:`cell.rescan`, the loop in :mod:`cell.pipeline.rescan`); lengths [m]."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

from cell.config.motion import ViewOptions
from cell.config.seams import OursSettings

# Below this confidence a seam is worth a close look (benchmarks/bench_confidence.py: 144 seams of fence1-exact,
# fence1 and fence2, realistic noise; 20 fall below it, with 2 of the 3 seams more than 0.15 mm off). A scenario
# can override it (``rescan.confidence_threshold``).
CONFIDENCE_THRESHOLD = 0.55

# The standard error that earns a close-up full confidence [m]: ours' target_se_m on a close-up cloud, and the
# re-scan's confidence scale of a close-up.
CLOSEUP_TARGET_SE_M = 0.00002

# The weld gate (docs/reference.md section 4: an arc-welded seam must be found to about half the wire diameter,
# +-0.5 mm): a seam is welded only when BOUND_SIGMAS times its sigma is within WELD_TOLERANCE_MM; a scenario can
# override both (``rescan.weld_tolerance_mm``, ``rescan.bound_sigmas``).
WELD_TOLERANCE_MM = 0.5
BOUND_SIGMAS = 3.0

# The ends' gate: a bead more than 1 mm past or short of its joint's end is a defect (past: metal on the bare face
# beyond the joint, or into another part; short: joint left open), so a seam is welded only when BOUND_SIGMAS times
# each end's sigma along the seam is within END_TOLERANCE_MM (``rescan.end_tolerance_mm``).
END_TOLERANCE_MM = 1.0

# The sane range of the gate's figures: beyond them the gate is off in all but name (a 100 mm tolerance or a bound
# of 0.01 sigma welds any seam found). A scenario goes beyond them only with ``rescan.allow_loose_gate: true``, and
# ``cell scenario check`` then warns. 2 mm is half the smallest fillet leg the WPS rows weld (4 mm): a seam further off
# puts the wire beside the root; 5 mm at an end is a bead past the joint's end by a wire's stick-out and more.
SANE_WELD_TOLERANCE_MM = 2.0
SANE_END_TOLERANCE_MM = 5.0
SANE_BOUND_SIGMAS = (2.0, 6.0)  # fewer than 2 sigma lets one seam in 20 past; more than 6 welds almost nothing

# Ours' sigma floor up close [m]: what no number of close-up points averages away. The depth output's quantisation
# (CLOSEUP_DEPTH_UNIT_M, the D4xx's finest depth unit) is shared by the points of a face seen at one depth: unit /
# sqrt 12 on each weld face, the two in quadrature; and the arm's pose accuracy and hand-eye calibration on a real
# cell (0.02 mm; exact kinematics in the simulator). The fixed cameras' calibration, which the first pass's floor
# stands for, does not apply. docs/seams.md section 2.
CLOSEUP_DEPTH_UNIT_M = 1e-4
CLOSEUP_SIGMA_FLOOR_M = round(math.hypot(2e-5, math.sqrt(2.0 / 12.0) * CLOSEUP_DEPTH_UNIT_M), 7)  # 0.0455 mm

# A face placed from the edge of its neighbour up close is read by one camera, whose last sample lies on average
# half a point pitch inside the edge, a bias no second camera averages: half a pitch joins its standard error
# (the fixed cameras' edges, read by two or three cameras at once: OursSettings.edge_pitch_factor).
CLOSEUP_EDGE_PITCH_FACTOR = 0.5

# Ours' floors of the ends' sigmas up close, as a share of the fixed cameras' (cell/seams/sigma.py): the close-ups of
# fence1's faults/two-cameras-dead and of bracket end 0.00-0.03 mm off where an edge is seen and 0.02-0.16 mm where a
# face is seen ending; the fixed cameras' floors (0.1 / 0.2 mm) made a close-up weigh less than the first estimate.
CLOSEUP_END_FLOOR_SCALE = 0.25

# Options of the "ours" locator for a close-up cloud (~0.2 mm noise and ~0.35 mm pixels at 0.35 m instead of
# ~4 mm and ~1.6 mm at 1.6 m): the standard error that earns full confidence and the bands cut along edges and
# corners shrink with the sensor. The noise assumed before it is measured (sensor_sigma_m) stays: it also sets
# the first pass's gate, which must span the aligned map's local error (up to ~8 mm on fence1's posts).
CLOSEUP_OURS_OPTIONS: dict[str, float | int | str | bool] = {
    "target_se_m": CLOSEUP_TARGET_SE_M,
    "edge_band_m": 0.002,
    "corner_band_m": 0.003,
    "sigma_floor_m": CLOSEUP_SIGMA_FLOOR_M,
    "end_floor_scale": CLOSEUP_END_FLOOR_SCALE,
    "edge_pitch_factor": CLOSEUP_EDGE_PITCH_FACTOR,
}


@dataclass(frozen=True)
class RescanOptions:
    """Options of the close-up re-scan (lengths [m]).

    first_scale_m : the confidence scale of a fused estimate (confidence 1/2 at this sigma: ours' default
        ``target_se_m``). The fusion weighs each estimate by its locator's own sigma (``SeamEstimate.sigma_m``,
        :mod:`cell.seams.sigma`).
    closeup_locator_options : locator name -> options merged into that locator's for a close-up cloud.
    """

    camera: str | None = None  # the eye-in-hand camera; None: the scenario's only one
    crop_margin_m: float = 0.08  # the box around the seam grown by this (the locator's tube and end search)
    min_points: int = 2000  # fewer points in that box: nothing seen
    first_scale_m: float = OursSettings.target_se_m
    closeup_locator_options: Mapping[str, Mapping[str, float | int | str | bool]] = field(
        default_factory=lambda: {"ours": CLOSEUP_OURS_OPTIONS}
    )
    return_to_scan: bool = True  # go back to the scan configuration after the last view (straight, or the way it came)
    view: ViewOptions = field(default_factory=ViewOptions)
