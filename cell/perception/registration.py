"""Registering one camera's cloud onto others for the splice (:mod:`cell.perception.splice`), and the test of
what the registration found.

:func:`register` is open3d's ICP, through :mod:`cell.perception._open3d`, chosen by ``PerceptionSpec.splice_icp``:

- ``"paper"``: the paper's point-to-point ICP on every point, max correspondence ``icp_max_correspondence_m``
  (1 mm), ``icp_iterations`` (50). On clouds with 1-3 mm of depth noise and 1.5-4 mm point spacing it latches onto
  chance near-coincidences: it "corrects" exact extrinsics by tenths of a millimetre and removes only part of
  a real calibration error.
- ``"robust"`` (default): point-to-plane ICP with a Tukey kernel, target normals estimated by open3d; the
  kernel width, correspondence distance and normal radius are derived in one place
  (:func:`registration_settings`) from the voxel size and the noise measured in the overlap; source and
  target are thinned to an even stride of at most :data:`_PROBE_POINTS` / :data:`_TARGET_POINTS` points.

A correction's motion along a direction the overlap does not constrain (a view of top faces alone says nothing
about a shift along them) is dropped: that direction stays as calibrated. So is its motion along a constrained
direction that the data do not support on its own: in the eigenvectors of the information matrix of the
point-to-plane problem, a direction is kept only if its part of the motion lowers the patch misfit by
:data:`MIN_DIRECTION_DROP` of the misfit at the calibration (removing it alone from the correction raises the
misfit that much), unless the whole correction lowers the misfit by :data:`CLEAR_DROP` (a real calibration
error). The sensor's errors are not independent from patch to patch (flying pixels at the edges each camera sees,
faces one camera sees head-on and the other at grazing incidence), so with exact extrinsics a long part seen
along its length gives an estimate of 0.5-3 mm along it with a chi-square in the hundreds and a misfit gain of
0-3 %: the misfit, not the chi-square, tells a calibration error from that. (Without the flying pixels the
largest such estimate fell from 3.1 to 0.7 mm; one direction of 1.2-1.8 mm that lowers the misfit by 1-3 % can
remain, and the splice's overall misfit test refuses it.) :func:`significance` measures how much the data
support what is left (shift, patch-robust chi-square and the smallest per-direction z score, patch misfit before
and after); the splice decides from those whether to apply it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

from cell.geometry import FloatArray, invert, make_pose, transform_points
from cell.perception import _open3d
from cell.scenario import PerceptionSpec

_PROBE_POINTS = 20_000  # source points a registration uses (an even stride)
_TARGET_POINTS = 60_000  # target points a registration searches (an even stride)
_MIN_OVERLAP = 200  # fewer source points in the overlap: no registration, the calibrated extrinsics stand
_WEAK_DIRECTION = 0.005  # a direction holding less than this share of the constraint is left as calibrated
_TUKEY_C = 4.685  # biweight cut-off [robust scales] (95 % efficiency on Gaussian residuals)
_MAD_TO_SIGMA = 1.4826  # median absolute deviation -> standard deviation (Gaussian)
_NORMAL_RADIUS_VOXELS = 2.0  # target normals from neighbours within this many voxels
_NORMAL_NEIGHBOURS = 50  # ... at most this many (the nearest)
_MIN_NOISE_M = 1e-4  # [m] floor of the measured noise (noise-free synthetic clouds)
MIN_DIRECTION_DROP = 0.001  # a constrained direction is kept only if its motion lowers the patch misfit by this
CLEAR_DROP = 0.15  # ... unless the whole correction lowers the patch misfit by this share (a calibration error)


@dataclass(frozen=True)
class RegistrationSettings:
    """The distances of one registration [m], all derived in :func:`registration_settings`.

    reach_m : correspondence search of the overlap and of the significance test.
    normal_radius_m : neighbourhood of the target normals (open3d ``estimate_normals``).
    max_correspondence_m : ICP's max correspondence distance.
    tukey_k_m : width of the Tukey kernel (robust ICP and the significance test's weights).
    """

    reach_m: float
    normal_radius_m: float
    max_correspondence_m: float
    tukey_k_m: float


def registration_settings(spec: PerceptionSpec, noise_m: float) -> RegistrationSettings:
    """The one place the registration's distances come from: the voxel size and the measured noise [m].

    noise_m : robust standard deviation of the point-to-plane residuals in the overlap at the calibrated
    extrinsics (both clouds' noise, and the miscalibration's spread). Points pair within a voxel (an ICP
    correspondence is a point-to-point distance: it must cover the point spacing and the miscalibration; the
    kernel, not the distance, rejects the outliers); the Tukey width is :data:`_TUKEY_C` noise deviations. The
    paper's mode pairs within ``spec.icp_max_correspondence_m`` instead.
    """
    return RegistrationSettings(
        reach_m=spec.voxel_m,
        normal_radius_m=_NORMAL_RADIUS_VOXELS * spec.voxel_m,
        max_correspondence_m=spec.icp_max_correspondence_m if spec.splice_icp == "paper" else spec.voxel_m,
        tukey_k_m=_TUKEY_C * max(noise_m, _MIN_NOISE_M),
    )


def _plane_residuals(
    probe: FloatArray, tree: cKDTree, target: FloatArray, normals: FloatArray, reach_m: float, X: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Point-to-plane residuals of the probe points moved by X against their nearest target points within reach.

    tree : the KD-tree of ``target``, built once per registration (a registration asks 10-12 times). Returns
    (moved probe points (k, 3), their target normals (k, 3), signed residuals (k,) [m]).
    """
    moved = transform_points(X, probe)
    dist, nearest = tree.query(moved, distance_upper_bound=reach_m, workers=-1)  # every core: same answers
    paired = np.isfinite(dist)
    moved, at = moved[paired], nearest[paired]
    n = normals[at]
    return moved, n, np.einsum("ij,ij->i", moved - target[at], n)


def _patch_keys(points: FloatArray, normals: FloatArray, patch_m: float) -> npt.NDArray[np.intp]:
    """(n,) patch index: points in one cube of edge ``patch_m`` whose normals share an axis direction."""
    axis = np.argmax(np.abs(normals), axis=1)
    direction = axis * 2 + (normals[np.arange(len(normals)), axis] < 0.0)
    ijk = np.floor(points / patch_m).astype(np.int64)
    ijk -= ijk.min(axis=0)
    dims = ijk.max(axis=0) + 1
    key = ((ijk[:, 0] * dims[1] + ijk[:, 1]) * dims[2] + ijk[:, 2]) * 6 + direction
    _, inverse = np.unique(key, return_inverse=True)
    return np.asarray(inverse.reshape(-1), np.intp)


def _tukey(r: FloatArray, k_m: float) -> FloatArray:
    u = r / k_m
    return np.where(np.abs(u) < 1.0, (1.0 - u * u) ** 2, 0.0)


def _patch_misfit(r: FloatArray, w: FloatArray, patch: npt.NDArray[np.intp]) -> float:
    """RMS over patches (weighted by their weight) of each patch's weighted mean residual [m]."""
    sw = np.bincount(patch, w)
    used = sw > 0.0
    mean = np.bincount(patch, w * r)[used] / sw[used]
    return float(np.sqrt(np.sum(sw[used] * mean**2) / np.sum(sw[used]))) if used.any() else math.inf


def _constrained(p: FloatArray, n: FloatArray, w: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray, float]:
    """The point-to-plane least-squares problem of points p (k, 3) on planes of normals n (k, 3), weights w (k,).

    Coordinates: rotation vector scaled to metres at the points' RMS radius ``lever`` about their centroid,
    then shift. Returns (J (k, 6), the constrained directions D (6, d) (eigenvectors of the weighted normal
    matrix holding at least :data:`_WEAK_DIRECTION` of its trace), centroid (3,), lever [m]).
    """
    centre = p.mean(axis=0)
    lever = max(float(np.sqrt(np.mean(np.sum((p - centre) ** 2, axis=1)))), 1e-9)
    J = _jacobian(p, n, centre, lever)
    vals, vecs = np.linalg.eigh((J.T * w) @ J)
    return J, vecs[:, vals >= _WEAK_DIRECTION * max(float(vals.sum()), 1e-300)], centre, lever


def _jacobian(p: FloatArray, n: FloatArray, centre: FloatArray, lever: float) -> FloatArray:
    """(k, 6) point-to-plane Jacobian of points p (k, 3) on planes n (k, 3) in the coordinates of
    :func:`_constrained` about ``centre`` (3,) with ``lever`` [m]."""
    return np.hstack([np.cross(p - centre, n) / lever, n])


def _restricted(X: FloatArray, D: FloatArray, centre: FloatArray, lever: float) -> FloatArray:
    """X (4, 4), a motion that puts points at ``centre`` (3,), keeping only its part along the directions D (6, d)
    (coordinates of :func:`_constrained`): a motion along a direction the overlap does not see is arbitrary."""
    c0 = transform_points(invert(X), centre[None])[0]  # X moves c0 to the centre: X p = R (p - c0) + centre
    est = np.concatenate([Rotation.from_matrix(X[:3, :3]).as_rotvec() * lever, centre - c0])
    kept = D @ (D.T @ est)
    R = Rotation.from_rotvec(kept[:3] / lever).as_matrix()
    return make_pose(R, c0 + kept[3:] - R @ c0)


def significance(
    probe: FloatArray,
    target: FloatArray,
    normals: FloatArray,
    X_icp: FloatArray,
    settings: RegistrationSettings,
    patch_m: float,
    tree: cKDTree | None = None,
    calibrated: tuple[FloatArray, FloatArray, FloatArray] | None = None,
) -> tuple[FloatArray, dict[str, float]]:
    """The part of the correction X_icp (4, 4) of ``probe`` (n, 3) onto ``target`` (m, 3) (unit normals (m, 3))
    that the overlap constrains, and how much the data support it (all in R).

    Returns (X (4, 4): X_icp without its motion along directions the overlap does not constrain or the data do
    not support (:func:`_supported`); diagnostics directions_constrained, constrained (the directions kept),
    shift_m, chi2, z_min, misfit_before_m, misfit_m of X, see :class:`cell.perception.splice.Registration`).
    The chi-square is a sandwich (patch-robust) covariance of a point-to-plane least-squares estimate at X:
    Tukey-weighted residuals, one score per patch of ``patch_m`` and surface direction, in the constrained
    directions. ``tree`` : the KD-tree of ``target`` when the caller has one (built here otherwise);
    ``calibrated`` : :func:`_plane_residuals` of ``probe`` at the identity when the caller has them (with that tree).
    """
    reach, k = settings.reach_m, settings.tukey_k_m
    tree = cKDTree(target, balanced_tree=False, compact_nodes=False) if tree is None else tree
    info = {"constrained": 0.0, "directions_constrained": 0.0, "shift_m": 0.0, "chi2": 0.0, "z_min": 0.0}
    info |= {"misfit_before_m": math.inf, "misfit_m": math.inf}
    if calibrated is None:
        calibrated = _plane_residuals(probe, tree, target, normals, reach, np.eye(4))
    p0, n0, r0 = calibrated
    p, n, r = _plane_residuals(probe, tree, target, normals, reach, X_icp)
    if len(r0) < _MIN_OVERLAP or len(r) < _MIN_OVERLAP:
        return np.eye(4), info
    info["misfit_before_m"] = _patch_misfit(r0, _tukey(r0, k), _patch_keys(p0, n0, patch_m))
    _, D, centre, lever = _constrained(p, n, _tukey(r, k))
    info["directions_constrained"] = float(D.shape[1])
    D = _supported(probe, tree, target, normals, X_icp, D, centre, lever, settings, patch_m, info["misfit_before_m"])
    if D.shape[1] == 0:
        return np.eye(4), info
    X = _restricted(X_icp, D, centre, lever)
    p, n, r = _plane_residuals(probe, tree, target, normals, reach, X)
    if len(r) < _MIN_OVERLAP:
        return np.eye(4), info
    w = _tukey(r, k)
    patch = _patch_keys(p, n, patch_m)
    info["misfit_m"] = _patch_misfit(r, w, patch)
    info["shift_m"] = float(np.sqrt(np.mean(np.sum((transform_points(X, probe) - probe) ** 2, axis=1))))
    Jd = _jacobian(p, n, centre, lever) @ D  # the kept directions, as they were chosen
    score = np.stack([np.bincount(patch, w * r * Jd[:, j], int(patch.max()) + 1) for j in range(D.shape[1])], 1)
    c0 = transform_points(invert(X), centre[None])[0]
    est = D.T @ np.concatenate([Rotation.from_matrix(X[:3, :3]).as_rotvec() * lever, centre - c0])
    try:
        H_inv = np.linalg.inv((Jd.T * w) @ Jd)
        cov = H_inv @ (score.T @ score) @ H_inv
        chi2 = float(est @ np.linalg.solve(cov, est))
        z_min = float(np.min(np.abs(est) / np.sqrt(np.maximum(np.diag(cov), 1e-300))))
    except np.linalg.LinAlgError:
        chi2, z_min = 0.0, 0.0
    info |= {"constrained": float(D.shape[1]), "chi2": chi2, "z_min": z_min}
    return X, info


def _supported(
    probe: FloatArray,
    tree: cKDTree,
    target: FloatArray,
    normals: FloatArray,
    X_icp: FloatArray,
    D: FloatArray,
    centre: FloatArray,
    lever: float,
    settings: RegistrationSettings,
    patch_m: float,
    misfit_before_m: float,
) -> FloatArray:
    """The columns of D (6, d) (eigenvectors of the information matrix, coordinates of :func:`_constrained`)
    along which X_icp's motion lowers the patch misfit on its own: removing that direction's part from the
    correction raises the misfit by at least :data:`MIN_DIRECTION_DROP` x ``misfit_before_m``; all of them when
    the whole correction lowers the misfit by :data:`CLEAR_DROP` or more (a miscalibration of 1 mm / 0.1 deg
    lowers it by 20-40 %, what the sensor's edges fake by 0-10 %: a real error's small components along weak
    directions do not lower the misfit on their own, yet they matter far from the overlap). Returns (6, d')."""
    c0 = transform_points(invert(X_icp), centre[None])[0]
    e = D.T @ np.concatenate([Rotation.from_matrix(X_icp[:3, :3]).as_rotvec() * lever, centre - c0])

    def misfit(keep: npt.NDArray[np.bool_]) -> float:
        kept = D[:, keep] @ e[keep]
        R = Rotation.from_rotvec(kept[:3] / lever).as_matrix()
        p, n, r = _plane_residuals(probe, tree, target, normals, settings.reach_m, make_pose(R, c0 + kept[3:] - R @ c0))
        return _patch_misfit(r, _tukey(r, settings.tukey_k_m), _patch_keys(p, n, patch_m)) if len(r) else math.inf

    every = np.ones(D.shape[1], dtype=bool)
    full = misfit(every)
    if full <= (1.0 - CLEAR_DROP) * misfit_before_m:  # a calibration error explains the misfit: every direction
        return D
    gain = np.array([misfit(every & (np.arange(len(every)) != j)) - full for j in range(len(every))])
    return D[:, gain >= MIN_DIRECTION_DROP * misfit_before_m]


def register(source: FloatArray, target: FloatArray, spec: PerceptionSpec) -> tuple[FloatArray, dict[str, float]]:
    """Open3D ICP of ``source`` (n, 3) [m] in R onto ``target`` (m, 3) in R, as ``spec.splice_icp`` says.

    Returns the estimated correction X (4, 4) in R (p' = X p) and diagnostics: overlap, noise_m and those of
    :func:`significance` (X is restricted to the constrained directions there). X is the identity when the
    overlap is too small. Runs ``spec.icp_iterations`` iterations at most; distances from
    :func:`registration_settings`. The paper's ICP runs on every point, the robust one and the test on an
    even stride of the points.
    """
    probe = np.asarray(source, dtype=np.float64)[:: max(1, math.ceil(len(source) / _PROBE_POINTS))]
    sub = np.asarray(target, dtype=np.float64)[:: max(1, math.ceil(len(target) / _TARGET_POINTS))]
    info = {"overlap": 0.0, "noise_m": 0.0, "constrained": 0.0, "directions_constrained": 0.0, "shift_m": 0.0}
    info |= {"chi2": 0.0, "z_min": 0.0, "misfit_before_m": math.inf, "misfit_m": math.inf}
    if len(probe) < _MIN_OVERLAP or len(sub) < _MIN_OVERLAP:
        return np.eye(4), info
    settings = registration_settings(spec, 0.0)
    normals = _open3d.estimate_normals(sub, settings.normal_radius_m, _NORMAL_NEIGHBOURS)
    tree = cKDTree(sub, balanced_tree=False, compact_nodes=False)  # built in half the time, same answers
    calibrated = _plane_residuals(probe, tree, sub, normals, settings.reach_m, np.eye(4))
    r0 = calibrated[2]
    info["overlap"] = float(len(r0))
    if len(r0) < _MIN_OVERLAP:
        return np.eye(4), info
    noise = _MAD_TO_SIGMA * float(np.median(np.abs(r0)))  # about 0, not the median: an offset widens it
    settings = registration_settings(spec, noise)
    info["noise_m"] = noise
    corr = settings.max_correspondence_m
    if spec.splice_icp == "paper":  # as the paper ran it: every point, no subsampling
        X = _open3d.icp(source, target, corr, spec.icp_iterations).X_TS
    else:
        X = _open3d.icp(probe, sub, corr, spec.icp_iterations, None, normals, settings.tukey_k_m).X_TS
    X, stats = significance(probe, sub, normals, X, settings, spec.merge_cell_m, tree, calibrated)
    return X, info | stats
