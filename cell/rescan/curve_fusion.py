"""A doubtful curved seam re-located from its close-ups: the close-up images' points gathered into one cloud (each
image its own camera: its own noise, its own pose error), the curve located in it by the curve locator, its
sigma with the eye-in-hand camera's calibration (:func:`relocate`), then fused with the fixed cameras' curve sample
by sample (:func:`fuse_curve`) as a straight seam's ends are (:func:`cell.rescan.fusion.fuse_along`). Frame R,
metres (docs/curves.md section 6)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace

import numpy as np
from scipy.spatial import cKDTree

from cell.geometry import FloatArray, invert
from cell.rescan.fusion import fuse_along
from cell.seams.curved.locate import curve_confidence, locate_curve
from cell.seams.curved.results import with_calibration
from cell.types import Cloud, CurvedSeam, DepthImage, SeamScene, SeamStatus, WeldMap
from cell.types.curve_estimate import CurveEstimate

MATCH_M = 0.003  # [m] a close-up sample farther than this from a first sample is not its partner (a curve cut
# differently by a third part): that first sample keeps its own estimate
# Each surface's shift along its normal that no fit sees, as a share of its points' noise scale: the fixed cameras'
# 0.12 mm (SURFACE_BIAS_M) at the 1.2 mm scale of round-brace's cameras where it was measured; a stereo camera's
# depth errors, its quantisation's too, grow as the square of the distance, so a close-up's shrinks with its noise.
BIAS_SHARE = 0.1


def closeup_curve_scene(
    images: Sequence[DepthImage], X_WR: FloatArray, samples_R: FloatArray, base: SeamScene, margin_m: float
) -> SeamScene:
    """One SeamScene of the close-up ``images`` of a curve through ``samples_R`` (n, 3): every image's points in R
    (deprojected with its believed pose) inside the curve's bounding box grown by ``margin_m`` [m], image k's
    camera named ``<camera>@<k>`` (its own noise scale and pose error in the fit), its centre in ``eyes_R``;
    the aligned map, joints and table of ``base``."""
    from cell.perception import deproject

    lo, hi = samples_R.min(axis=0) - margin_m, samples_R.max(axis=0) + margin_m
    X_RW = invert(np.asarray(X_WR, dtype=float))
    pts, cams, names, eyes = [], [], [], {}
    for k, image in enumerate(images):
        in_R = replace(image, X_WC=X_RW @ image.X_WC)
        p = deproject(in_R)
        p = p[np.all((p >= lo) & (p <= hi), axis=1)]
        name = f"{image.camera}@{k + 1}"
        pts.append(p)
        cams.append(np.full(len(p), k, np.int16))
        names.append(name)
        eyes[name] = np.asarray(in_R.X_WC, dtype=float)[:3, 3]
    p_R = np.concatenate(pts) if pts else np.zeros((0, 3))
    cam = np.concatenate(cams) if cams else np.zeros(0, np.int16)
    dense = Cloud(p_R, "R", cam, tuple(names))
    return SeamScene(
        voxel=lambda: dense,
        dense=dense,
        weldmap=base.weldmap,
        joints=base.joints,
        table_z=base.table_z,
        eyes_R=eyes,
    )


def facet_floor_m(seam: CurvedSeam, weldmap: WeldMap) -> tuple[float, float]:
    """[m] half the sagitta r (1 - cos(pi / n)) of each part of the seam's joint (abutting, receiving) drawn as a
    round with n flat facets (0 for a true round or a flat part): a shift of that surface, the same for every
    camera (a circle fitted to a polygon), which no close-up takes away."""
    if seam.joint is None:
        return 0.0, 0.0
    out = []
    for name in (seam.joint.abutting, seam.joint.receiving):
        c = weldmap.part(name).cylinder
        out.append(0.5 * c.radius * (1.0 - math.cos(math.pi / c.facets)) if c is not None and c.facets > 0 else 0.0)
    return out[0], out[1]


def shared_sigma(est: CurveEstimate, floor_m: tuple[float, float]) -> FloatArray:
    """(n,) [m] the part of each sample's sigma that every estimate of the curve shares: the surfaces' shifts
    ``floor_m`` (abutting, receiving; :func:`facet_floor_m`) carried through the crossing at that sample (the
    least-norm step that keeps it on both surfaces: larger where they meet at an acute angle)."""
    J = np.stack([np.asarray(est.n_abutting_R), np.asarray(est.n_receiving_R)], axis=1)  # (n, 2, 3)
    pinv = np.transpose(J, (0, 2, 1)) @ np.linalg.inv(J @ np.transpose(J, (0, 2, 1)))  # (n, 3, 2)
    col = np.linalg.norm(pinv, axis=1)  # (n, 2): how far a unit shift of each surface moves the sample
    return np.asarray(np.hypot(floor_m[0] * col[:, 0], floor_m[1] * col[:, 1]))


def relocate(scene: SeamScene, seam: CurvedSeam, calibration_m: float) -> CurveEstimate:
    """``seam`` located in the close-ups' ``scene`` (:func:`closeup_curve_scene`), every sample kept whatever its
    sigma (where no close-up looked, the fit's extrapolation says so in its sigma: the fusion weighs it out), with
    ``calibration_m`` [m] (the eye-in-hand camera's pose error across the curve) in quadrature."""
    est = locate_curve(scene, seam, max_sigma_m=math.inf, bias_share=BIAS_SHARE)
    return with_calibration(est, calibration_m)


def fuse_curve(
    first: CurveEstimate, closeup: CurveEstimate | None, shared_m: FloatArray | None = None
) -> tuple[CurveEstimate, float]:
    """The fixed cameras' curve ``first`` and a close-up's fused sample by sample: (fused curve, the close-up's
    mean weight over the samples; 0: ``first`` kept). Each first sample and its close-up partner (the same index
    when both have as many samples, else the nearest within :data:`MATCH_M`) are fused across the seam by
    :func:`~cell.rescan.fusion.fuse_along` on the line through them: by inverse variance when they agree within
    three combined sigmas, else the close-up's position with a sigma of at least half their distance; ``shared_m``
    (n,) [m] (:func:`shared_sigma` of ``first``): the part of both sigmas that is one error, taken out before and
    put back after (never averaged away). The first's samples, ends and closure are kept (a close-up says nothing
    of where a drawn end is)."""
    if closeup is None or closeup.status is not SeamStatus.FOUND or first.status is not SeamStatus.FOUND:
        return first, 0.0
    p1, s1 = np.asarray(first.p_RS), np.asarray(first.sigma_m)
    if len(closeup.p_RS) == len(p1) and closeup.closed == first.closed:
        idx, ok = np.arange(len(p1)), np.ones(len(p1), bool)
    else:
        d, idx = cKDTree(closeup.p_RS).query(p1)
        ok = d <= MATCH_M
    c = np.zeros(len(p1)) if shared_m is None else np.asarray(shared_m)
    u1 = np.sqrt(np.maximum(s1**2 - c**2, 0.0))
    p, sigma, w = p1.copy(), s1.copy(), np.zeros(len(p1))
    na, nb = np.array(first.n_abutting_R), np.array(first.n_receiving_R)
    for i in np.flatnonzero(ok):
        j = int(idx[i])
        q, u2 = closeup.p_RS[j], math.sqrt(max(float(closeup.sigma_m[j]) ** 2 - c[i] ** 2, 0.0))
        gap_v = q - p1[i]
        gap = float(np.linalg.norm(gap_v))
        x, u = fuse_along(0.0, float(u1[i]), gap, u2)
        p[i] = p1[i] + (x / gap) * gap_v if gap > 0.0 else p1[i]
        sigma[i] = math.hypot(u, c[i])
        w[i] = x / gap if gap > 0.0 else (u1[i] ** 2 / (u1[i] ** 2 + u2**2) if u1[i] + u2 > 0.0 else 0.5)
        na[i] = _blend(first.n_abutting_R[i], closeup.n_abutting_R[j], w[i])
        nb[i] = _blend(first.n_receiving_R[i], closeup.n_receiving_R[j], w[i])
    weight = float(w.mean())
    if weight <= 0.0:
        return first, 0.0
    fused = replace(
        first,
        p_RS=p,
        n_abutting_R=na,
        n_receiving_R=nb,
        sigma_m=sigma,
        confidence=curve_confidence(sigma),
        time_s=first.time_s + closeup.time_s,
    )
    return fused, weight


def _blend(n1: FloatArray, n2: FloatArray, w: float) -> FloatArray:
    """The unit vector between unit normals n1 and n2 at weight ``w`` of n2."""
    v = (1.0 - w) * np.asarray(n1) + w * np.asarray(n2)
    return np.asarray(v / max(float(np.linalg.norm(v)), 1e-12))


__all__ = ["BIAS_SHARE", "MATCH_M", "closeup_curve_scene", "facet_floor_m", "fuse_curve", "relocate", "shared_sigma"]
