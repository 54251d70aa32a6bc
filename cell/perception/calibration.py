"""The cameras' calibration in each seam's sigma: a seam carries the stated pose error of the cameras its points come
from, at their range and in proportion to their share (the model: docs/perception.md, "The cameras' calibration in
each seam's sigma")."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import replace

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray
from cell.perception.splicing.decision import Registration
from cell.perception.splicing.pose_prior import PoseResidual, PoseUncertainty
from cell.types import Cloud, SeamEstimate, SeamStatus

__all__ = [
    "PoseUncertainty",
    "calibration_sigma",
    "closeup_sigma",
    "curve_calibration_sigma",
    "reference_of",
    "residuals_of",
    "seam_calibration_sigma",
    "support_shares",
    "with_calibration",
]

SUPPORT_RADIUS_M = 0.015  # points within this of the located segment are the seam's support (both faces' strips)


def reference_of(registrations: Sequence[Registration]) -> dict[str, str]:
    """Camera name -> the camera whose calibration its points rest on: a corrected camera its registration's
    reference (the first target, followed through), every other camera itself."""
    tied: dict[str, str] = {}
    for r in registrations:
        if r.accepted and r.target:
            ref = r.target[0]
            tied[r.source] = tied.get(ref, ref)
    return tied


def residuals_of(registrations: Sequence[Registration]) -> dict[str, tuple[PoseResidual, ...]]:
    """Camera name -> what its applied correction left unknown (the splice's posterior), for every corrected
    camera whose registration computed one, followed by its corrected targets' (a camera registered onto a corrected
    one carries that one's residual too: counted whole, conservatively, whatever its share of the target)."""
    out: dict[str, tuple[PoseResidual, ...]] = {}
    for r in registrations:  # in the splice's order: a target's residuals are known before its sources'
        if r.accepted and r.residual is not None:
            out[r.source] = (r.residual, *(x for t in r.target for x in out.get(t, ())))
    return out


def calibration_sigma(
    shares: Mapping[str, float],
    mid_R: FloatArray,
    origins_R: Mapping[str, FloatArray],
    uncertainty: Mapping[str, PoseUncertainty],
    tied: Mapping[str, str],
    residuals: Mapping[str, Sequence[PoseResidual]] | None = None,
) -> float:
    """sigma_cal [m] of a seam at ``mid_R`` whose support is split ``shares`` (camera -> fraction) between cameras
    (module docstring); ``residuals``: a corrected camera's posterior (:func:`residuals_of`). A camera with no
    stated uncertainty or no known origin contributes nothing."""
    groups: dict[str, float] = {}
    total = 0.0
    for camera, w in shares.items():
        source = tied.get(camera, camera)
        groups[source] = groups.get(source, 0.0) + w
        for left in (residuals or {}).get(camera, ()) if source != camera else ():
            total += (w * left.sigma_at(mid_R)) ** 2
    for source, w in groups.items():
        u = uncertainty.get(source)
        origin = origins_R.get(source)
        if u is None or u.zero or origin is None:
            continue
        total += (w * u.sigma_at(float(np.linalg.norm(np.asarray(mid_R) - origin)))) ** 2
    return math.sqrt(total)


def support_shares(
    cloud: Cloud, p0: FloatArray, p1: FloatArray, radius_m: float = SUPPORT_RADIUS_M
) -> dict[str, float]:
    """Camera name -> share of ``cloud``'s points within ``radius_m`` of the segment p0-p1 (empty: none near)."""
    _, cams = _support(cloud, p0, p1, radius_m)
    return _shares(cloud, cams)


def _shares(cloud: Cloud, cams: npt.NDArray[np.int16]) -> dict[str, float]:
    """Camera name -> share of the camera indices ``cams`` (unknown ones left out; empty: none)."""
    cams = cams[cams >= 0]
    if cams.size == 0:
        return {}
    idx, counts = np.unique(cams, return_counts=True)
    return {cloud.cameras[int(i)]: float(c) / float(cams.size) for i, c in zip(idx, counts, strict=True)}


def _support(cloud: Cloud, p0: FloatArray, p1: FloatArray, radius_m: float) -> tuple[FloatArray, npt.NDArray[np.int16]]:
    """The points (k, 3) of ``cloud`` within ``radius_m`` of the segment p0-p1 and their camera indices (k,)."""
    lo = np.minimum(p0, p1) - radius_m
    hi = np.maximum(p0, p1) + radius_m
    pts = cloud.points
    box = np.all((pts >= lo) & (pts <= hi), axis=1)
    near, cams = pts[box], cloud.camera[box]
    t = p1 - p0
    length2 = float(t @ t)
    s = np.clip(((near - p0) @ t) / length2, 0.0, 1.0) if length2 > 0.0 else np.zeros(len(near))
    d = np.linalg.norm(near - (p0 + s[:, None] * t), axis=1)
    return near[d <= radius_m], cams[d <= radius_m]


def seam_calibration_sigma(
    cloud: Cloud,
    est: SeamEstimate,
    faces: tuple[FloatArray, float, FloatArray, float] | None,
    origins_R: Mapping[str, FloatArray],
    uncertainty: Mapping[str, PoseUncertainty],
    tied: Mapping[str, str],
    residuals: Mapping[str, Sequence[PoseResidual]],
) -> float:
    """sigma_cal [m] of one found seam. Without its weld faces' planes (``faces``: n_a, d_a, n_b, d_b), from
    its whole support (module docstring). With them, through each face: an error source ``s`` (a camera group,
    or a corrected camera's residual) of per-axis sigma ``sigma_s`` that holds the shares ``a_s``, ``b_s`` of the
    two faces' strips moves their offsets by ``(a_s n_a . e, b_s n_b . e)``, and the line, where the two planes
    meet, by ``x`` with ``|x|^2 = delta^T G^-1 delta`` (``G`` the faces' normals' Gram matrix). With ``C`` the
    offsets' covariance, ``x``'s per-axis RMS across the seam is ``sqrt(tr(G^-1 C) / 2)``: one camera seeing both
    faces moves the line rigidly (its own sigma), one camera per face moves each face alone (its own sigma too,
    where the shares would have said 1 / sqrt 2), and a sharp dihedral amplifies both. The lateral error is the
    distance ``|x|`` over both axes, so the sigma returned is that RMS times sqrt(-2 ln 0.05) / 2 (1.22): two
    of it hold 95 % of such a distance."""
    P, cams = _support(cloud, est.p_start, est.p_end, SUPPORT_RADIUS_M)
    mid = 0.5 * (est.p_start + est.p_end)
    if faces is None or len(P) == 0:
        return calibration_sigma(_shares(cloud, cams), mid, origins_R, uncertainty, tied, residuals)
    n_a, d_a, n_b, d_b = faces
    on_a = np.abs(P @ n_a - d_a) < np.abs(P @ n_b - d_b)
    strips = (_shares(cloud, cams[on_a]), _shares(cloud, cams[~on_a]))
    sources: dict[tuple[str, int], list[float]] = {}  # (source, k) -> [sigma, share of A, share of B]
    for side, shares in enumerate(strips):
        for camera, w in shares.items():
            group = tied.get(camera, camera)
            u, origin = uncertainty.get(group), origins_R.get(group)
            if u is not None and not u.zero and origin is not None:
                src = sources.setdefault((group, -1), [u.sigma_at(float(np.linalg.norm(mid - origin))), 0.0, 0.0])
                src[1 + side] += w
            for k, left in enumerate(residuals.get(camera, ()) if group != camera else ()):
                sources.setdefault((camera, k), [left.sigma_at(mid), 0.0, 0.0])[1 + side] += w
    c = float(np.clip(n_a @ n_b, -0.995, 0.995))
    C = np.zeros((2, 2))
    for sigma, a, b in sources.values():
        C += sigma**2 * np.array([[a * a, a * b * c], [a * b * c, b * b]])
    G_inv = np.linalg.inv(np.array([[1.0, c], [c, 1.0]]))
    # |x| is a distance over two axes: 95 % of it lies within sqrt(-2 ln 0.05) per-axis RMS (chi-square, two
    # degrees), and the sigma is read as 95 % within two of it.
    return math.sqrt(max(float(np.trace(G_inv @ C)), 0.0) / 2.0 * -2.0 * math.log(0.05) / 4.0)


def with_calibration(
    estimates: Sequence[SeamEstimate],
    registered: Cloud,
    origins_R: Mapping[str, FloatArray],
    uncertainty: Mapping[str, PoseUncertainty],
    registrations: Sequence[Registration],
    faces: Mapping[str, tuple[FloatArray, float, FloatArray, float]] | None = None,
) -> tuple[SeamEstimate, ...]:
    """Every found seam's sigma with its cameras' calibration in quadrature (module docstring); the estimates
    unchanged when no camera states an uncertainty. ``faces``: seam id -> its weld faces' planes (n_a, d_a, n_b,
    d_b) in R, for the term per face (:func:`seam_calibration_sigma`)."""
    if all(u.zero for u in uncertainty.values()):
        return tuple(estimates)
    tied = reference_of(registrations)
    left = residuals_of(registrations)
    out = []
    for est in estimates:
        if est.status is not SeamStatus.FOUND or not math.isfinite(est.sigma_m):
            out.append(est)
            continue
        cal = seam_calibration_sigma(registered, est, (faces or {}).get(est.id), origins_R, uncertainty, tied, left)
        out.append(with_term(est, cal) if cal > 0.0 else est)
    return tuple(out)


def with_term(est: SeamEstimate, sigma_cal: float) -> SeamEstimate:
    """``est`` with a calibration term ``sigma_cal`` [m] in quadrature, across the seam and at each end along it
    (a camera's pose error moves its points rigidly, along the seam as much as across it)."""
    ends = est.end_sigma_m
    return replace(
        est,
        sigma_m=math.hypot(est.sigma_m, sigma_cal),
        end_sigma_m=(math.hypot(ends[0], sigma_cal), math.hypot(ends[1], sigma_cal)),
    )


def closeup_sigma(est: SeamEstimate, origin_R: FloatArray, uncertainty: PoseUncertainty) -> SeamEstimate:
    """A close-up estimate (one camera, at ``origin_R``) with that camera's calibration in its sigma."""
    if est.status is not SeamStatus.FOUND or uncertainty.zero or not math.isfinite(est.sigma_m):
        return est
    mid = 0.5 * (est.p_start + est.p_end)
    cal = uncertainty.sigma_at(float(np.linalg.norm(mid - np.asarray(origin_R))))
    return with_term(est, cal)


def curve_calibration_sigma(
    cloud: Cloud,
    p_R: FloatArray,
    origins_R: Mapping[str, FloatArray],
    uncertainty: Mapping[str, PoseUncertainty],
    registrations: Sequence[Registration],
) -> float:
    """sigma_cal [m] of a located curve through the samples p_R (n, 3) in R, as an RMS distance across it (both
    axes: sqrt 2 times the per-axis :func:`calibration_sigma`, from the shares of ``cloud``'s points within
    :data:`SUPPORT_RADIUS_M` of a sample, at the curve's middle); 0 when no camera states an uncertainty."""
    if len(p_R) == 0 or all(u.zero for u in uncertainty.values()):
        return 0.0
    from scipy.spatial import cKDTree

    lo, hi = p_R.min(axis=0) - SUPPORT_RADIUS_M, p_R.max(axis=0) + SUPPORT_RADIUS_M
    box = np.all((cloud.points >= lo) & (cloud.points <= hi), axis=1)
    d, _ = cKDTree(p_R).query(cloud.points[box])
    shares = _shares(cloud, cloud.camera[box][d <= SUPPORT_RADIUS_M])
    tied, left = reference_of(registrations), residuals_of(registrations)
    return math.sqrt(2.0) * calibration_sigma(shares, p_R.mean(axis=0), origins_R, uncertainty, tied, left)
