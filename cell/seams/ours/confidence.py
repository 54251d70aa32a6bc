"""How sure our locator is of a seam: the standard errors of its faces' offsets and its ends, and the confidence
in [0, 1] computed from them, each face's support and the residual noise."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cell.seams.ours._planes import End, Face
from cell.seams.ours.options import OursOptions

SUPPORT_FULL_MARKS = 0.4  # share of a well-seen surface's points on a face that earns full confidence


@dataclass(frozen=True)
class SeamErrors:
    """Standard errors [m] of a seam found by :class:`~cell.seams.ours.OursLocator` (what its confidence is
    computed from).

    lateral_m : of the seam line across itself (from the two faces' offsets).
    start_m, end_m : of the ends along the line.
    face_a_m, face_b_m : of the offsets of A's and B's weld faces (an edge-placed face: its edge's).
    tilt_m : of the seam line across itself at its ends from the faces' tilts that the points leave within the
        parts' angular tolerance (in the sigma, not in the confidence: every seam carries some).
    """

    lateral_m: float
    start_m: float
    end_m: float
    face_a_m: float
    face_b_m: float
    tilt_m: float = 0.0


NO_ERRORS = SeamErrors(*(5 * (float("inf"),)))  # a seam not found


def errors_of(face_a: Face, face_b: Face, ends: tuple[End, End]) -> SeamErrors:
    """The seam's standard errors from its faces' offsets and its ends (the line moves by the faces' offsets
    over the sine of the angle between them)."""
    sin_ab = float(np.linalg.norm(np.cross(face_a.n, face_b.n)))
    lateral = float(np.hypot(face_a.se, face_b.se)) / max(sin_ab, 0.1)
    tilt = float(np.hypot(face_a.tilt_se, face_b.tilt_se)) / max(sin_ab, 0.1)
    return SeamErrors(lateral, ends[0].se, ends[1].se, face_a.se, face_b.se, tilt)


def confidence(face_a: Face, face_b: Face, errors: SeamErrors, spacing: float, o: OursOptions) -> float:
    """Confidence in [0, 1] from the standard errors of the line (lateral) and of the ends, the support of
    each face (its points against what a well-seen surface of its region at the cloud's point ``spacing``
    [m] would give; 40 % of that earns full marks) and the residual noise. A face placed from an edge enters by
    its edge's standard error (:func:`cell.seams.ours._faces.face_from_edge`)."""
    se_lat, se_end = errors.lateral_m, max(errors.start_m, errors.end_m)
    support = 1.0
    if np.isfinite(spacing) and spacing > 0.0:
        for f in (face_a, face_b):
            if f.source == "points":
                expect = max(f.area, 1e-6) / spacing**2
                support = min(support, f.count / (SUPPORT_FULL_MARKS * expect))
    noise = min(1.0, 2.0 * o.sensor_sigma_m / max(face_a.scale, face_b.scale))
    conf = (
        np.sqrt(support * noise) / (1.0 + (se_lat / o.target_se_m) ** 2) / (1.0 + (se_end / (4.0 * o.target_se_m)) ** 2)
    )
    return float(np.clip(conf, 0.0, 1.0))
