"""The last check before the arc: a located seam against what it cannot be, from the aligned map alone (across,
length, an end in a body, an end off the faces its joint joins); :func:`last_check` returns the first test failed
as a :class:`~cell.types.CheckFail`, None when the seam passes. Frame R, metres. The tests: docs/seams.md section 4."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from cell.geometry import FloatArray
from cell.seams.checks.ends import bead_entry
from cell.types import CheckFail, Joint, LastCheck, MapSeam, Part, SeamEstimate, SeamStatus

CHECK_SIGMAS = 3.0  # the estimate's own sigma counts this many times in the across budget


@dataclass(frozen=True)
class Budget:
    """How far a located seam may lie from the aligned map [m] (see the module docstring)."""

    across_m: float
    length_m: float
    body_m: float
    face_m: float


def budget(
    map_tolerance_m: float, calibration_m: float, sigma_m: float, end_sigma_m: tuple[float, float] = (0.0, 0.0)
) -> Budget:
    """The budget of one estimate [m]: the as-built faces and ends may lie ``map_tolerance_m`` from the aligned map
    (the build's deviations and the placement the alignment leaves; a whole part's offset moves its seams by up
    to twice that, as the locators' search allows), a camera's stated calibration ``calibration_m`` moves what it
    saw, and the estimate carries its own ``sigma_m`` across the seam and ``end_sigma_m`` (start, end) along it
    (``CHECK_SIGMAS`` of each: the length adds its ends' sigmas in quadrature, an end off its faces the larger;
    a sigma not given, inf, adds nothing)."""
    own = calibration_m + CHECK_SIGMAS * _finite(sigma_m)
    ends = [_finite(s) for s in end_sigma_m]
    return Budget(
        across_m=2.0 * map_tolerance_m + own,
        length_m=map_tolerance_m + own + CHECK_SIGMAS * math.hypot(*ends),
        body_m=0.5 * map_tolerance_m + own,
        face_m=2.0 * map_tolerance_m + own + CHECK_SIGMAS * max(ends),
    )


def _finite(sigma_m: float) -> float:
    """A sigma [m], 0 when it is not given (inf or nan)."""
    return float(sigma_m) if math.isfinite(sigma_m) else 0.0


def _outside(part: Part, p: FloatArray, at_least: float) -> float:
    """How far [m] point p (3,) lies outside the part's body, to a tenth of a mm (at least ``at_least``)."""
    lo, hi = at_least, at_least + 2.0 * part.radius
    while hi - lo > 1e-4:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if bool(part.contains(p, margin=mid)) else (mid, hi)
    return hi


def _across(est: SeamEstimate, drawn: MapSeam) -> FloatArray:
    """(2,) distances [m] of the estimate's ends from the drawn seam's (infinite) line."""
    d = drawn.direction
    ends = np.stack([est.p_start, est.p_end]) - drawn.p_start
    return np.asarray(np.linalg.norm(ends - np.outer(ends @ d, d), axis=1))


def last_check(
    est: SeamEstimate, drawn: MapSeam, joint: Joint | None, parts: Sequence[Part], limits: Budget
) -> CheckFail | None:
    """The first test a found estimate fails against the aligned map (None: it passes, or it is not found).

    drawn : the seam as the aligned map draws it; joint : its joint (None: the tests of the ends against its faces
    and its bodies are skipped, every part counting as another); parts : the aligned map's parts.
    """
    if est.status is not SeamStatus.FOUND:
        return None
    names = ("start", "end")
    across = _across(est, drawn)
    k = int(np.argmax(across))
    if across[k] > limits.across_m:
        return CheckFail(LastCheck.ACROSS, float(across[k]), limits.across_m, names[k])
    length = float(np.linalg.norm(est.p_end - est.p_start))
    if abs(length - drawn.length) > limits.length_m:
        return CheckFail(LastCheck.LENGTH, abs(length - drawn.length), limits.length_m)
    own = {joint.abutting, joint.receiving} if joint is not None else set()
    for name, p in zip(names, (est.p_start, est.p_end), strict=True):
        for part in parts:
            if part.name not in own and bool(part.contains(p, margin=-limits.body_m)):
                return CheckFail(LastCheck.END_IN_BODY, _depth(part, p, limits.body_m), limits.body_m, name, part.name)
    if length > 0.0 and joint is not None:
        t = (est.p_end - est.p_start) / length
        for name, u_end in zip(names, (0.0, length), strict=True):
            hit = bead_entry(parts, joint, est.p_start, t, 0.5 * length, u_end)
            if hit is not None and abs(u_end - hit[0]) > limits.body_m:
                return CheckFail(LastCheck.END_IN_BODY, abs(u_end - hit[0]), limits.body_m, name, hit[1])
    if joint is None:
        return None
    by_name = {p.name: p for p in parts}
    for name, p in zip(names, (est.p_start, est.p_end), strict=True):
        for part_name in (joint.abutting, joint.receiving):
            joined = by_name.get(part_name)
            if joined is not None and not bool(joined.contains(p, margin=limits.face_m)):
                return CheckFail(
                    LastCheck.END_OFF_FACE, _outside(joined, p, limits.face_m), limits.face_m, name, part_name
                )
    return None


def _depth(part: Part, p: FloatArray, at_least: float) -> float:
    """How deep [m] point p (3,) lies inside the part's body, to a tenth of a mm (at least ``at_least``)."""
    lo, hi = at_least, at_least + 2.0 * part.radius
    while hi - lo > 1e-4:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if bool(part.contains(p, margin=-mid)) else (lo, mid)
    return lo
