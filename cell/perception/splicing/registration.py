"""Registering one camera's cloud onto others for the splice (Open3D's ICP, the paper's or a robust one), and the
evidence the overlap gives about the correction: its coordinates and their patch-robust information
(docs/perception.md, "The splice's order, its ICP and the prioritised merge")."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

from cell.geometry import FloatArray, make_pose, readonly, transform_points
from cell.perception import _open3d
from cell.perception.splicing.pose_prior import PoseResidual, posterior
from cell.scenario import PerceptionSpec

_PROBE_POINTS = 20_000  # source points a registration uses (an even stride)
_TARGET_POINTS = 60_000  # target points a registration searches (an even stride)
MIN_OVERLAP = 200  # fewer source points in the overlap: no registration, the calibrated extrinsics stand
_SCORE_RCOND = 1e-10  # patch-score covariance eigenvalues below this share of the largest carry no information
_TUKEY_C = 4.685  # biweight cut-off [robust scales] (95 % efficiency on Gaussian residuals)
_MAD_TO_SIGMA = 1.4826  # median absolute deviation -> standard deviation (Gaussian)
_NORMAL_RADIUS_VOXELS = 2.0  # target normals from neighbours within this many voxels
_NORMAL_NEIGHBOURS = 50  # ... at most this many (the nearest)
_MIN_NOISE_M = 1e-4  # [m] floor of the measured noise (noise-free synthetic clouds)


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
    moved, at = _pairs(probe, tree, reach_m, X)
    n = normals[at]
    return moved, n, np.einsum("ij,ij->i", moved - target[at], n)


def _pairs(probe: FloatArray, tree: cKDTree, reach_m: float, X: FloatArray) -> tuple[FloatArray, npt.NDArray[np.intp]]:
    """(the probe points moved by X that have a target point within ``reach_m`` (k, 3), that point's index (k,))."""
    moved = transform_points(X, probe)
    dist, nearest = tree.query(moved, distance_upper_bound=reach_m, workers=-1)  # every core: same answers
    paired = np.isfinite(dist)
    return moved[paired], np.asarray(nearest[paired], np.intp)


def _split_normals(target: FloatArray, normals: FloatArray, radius_m: float) -> tuple[FloatArray, FloatArray]:
    """Two estimates of every target point's normal (each (m, 3), oriented as ``normals``), independent of each
    other: each from one half of the points (even / odd), taken at the point's nearest neighbour in that half."""
    out = []
    for half in (target[0::2], target[1::2]):
        n_half = _open3d.estimate_normals(half, radius_m, _NORMAL_NEIGHBOURS)
        _, nearest = cKDTree(half, balanced_tree=False, compact_nodes=False).query(target, workers=-1)
        n = n_half[nearest]
        out.append(np.where((np.einsum("ij,ij->i", n, normals) < 0.0)[:, None], -n, n))
    return out[0], out[1]


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


def _jacobian(p: FloatArray, n: FloatArray, centre: FloatArray, lever: float) -> FloatArray:
    """(k, 6) point-to-plane Jacobian of points p (k, 3) on planes n (k, 3) in the coordinates of
    :func:`coordinates` about ``centre`` (3,) with ``lever`` [m]."""
    return np.hstack([np.cross(p - centre, n) / lever, n])


def coordinates(X: FloatArray, centre: FloatArray, lever: float) -> FloatArray:
    """(6,) [m] coordinates of the motion X (4, 4): its rotation vector times ``lever``, then how far it moves
    ``centre`` (3,). :func:`pose_of` is the inverse."""
    moved = transform_points(X, np.asarray(centre)[None])[0]
    return np.concatenate([Rotation.from_matrix(X[:3, :3]).as_rotvec() * lever, moved - centre])


def pose_of(x: FloatArray, centre: FloatArray, lever: float) -> FloatArray:
    """(4, 4) motion of coordinates x (6,) (:func:`coordinates`): the rotation ``x[:3] / lever`` about ``centre``
    (3,), then the shift ``x[3:]``."""
    R = Rotation.from_rotvec(np.asarray(x[:3]) / lever).as_matrix()
    return make_pose(R, centre + x[3:] - R @ centre)


@dataclass(frozen=True)
class Evidence:
    """What an overlap says about a correction, in the coordinates of :func:`coordinates`.

    centre_R : (3,) centroid of the overlap (the probe points paired at the calibration) [m]; lever_m : their RMS
    radius about it [m]. x_data : (6,) the registration's estimate [m]. information : (6, 6) its information
    [1/m^2], the inverse of the patch-robust covariance (zero along a direction the overlap does not constrain).
    hessian : (6, 6) the Tukey-weighted normal matrix J^T W J at the estimate (unitless: the cost's curvature).
    """

    centre_R: FloatArray
    lever_m: float
    x_data: FloatArray
    information: FloatArray
    hessian: FloatArray

    def __post_init__(self) -> None:
        for name in ("centre_R", "x_data", "information", "hessian"):
            object.__setattr__(self, name, readonly(getattr(self, name)))


def evidence(
    probe: FloatArray,
    tree: cKDTree,
    target: FloatArray,
    normals: FloatArray,
    X: FloatArray,
    settings: RegistrationSettings,
    patch_m: float,
    calibrated: tuple[FloatArray, FloatArray, FloatArray],
    split: tuple[FloatArray, FloatArray],
) -> Evidence | None:
    """The estimate X (4, 4) of ``probe`` (n, 3) onto ``target`` (m, 3) (unit normals (m, 3), its KD-tree
    ``tree``) as :class:`Evidence`; None when fewer than :data:`MIN_OVERLAP` points pair at X.

    calibrated : :func:`_plane_residuals` of ``probe`` at the identity (its paired points fix the centre).
    split : :func:`_split_normals` of the target. The information is ``H S^+ H``: H the Tukey-weighted normal
    matrix of the point-to-plane residuals at X, S the covariance of their scores summed per patch of ``patch_m``
    and surface direction. The estimated normals are noisy, and ``J^T W J`` of one estimate counts their tilt as
    information (a plane's or a round body's axis' slide looks constrained, about by the number of points over
    the normals' neighbourhood, whatever the depth noise); H is made of the two independent estimates instead,
    ``(J_a^T W J_b + J_b^T W J_a) / 2``, whose tilts do not correlate (instrumental variables).
    """
    p0 = calibrated[0]
    centre = p0.mean(axis=0)
    lever = max(float(np.sqrt(np.mean(np.sum((p0 - centre) ** 2, axis=1)))), 1e-9)
    p, at = _pairs(probe, tree, settings.reach_m, X)
    if len(at) < MIN_OVERLAP:
        return None
    n = normals[at]
    r = np.einsum("ij,ij->i", p - target[at], n)
    w = _tukey(r, settings.tukey_k_m)
    moved_centre = transform_points(X, centre[None])[0]
    J_a, J_b = (_jacobian(p, half[at], moved_centre, lever) for half in split)
    H = 0.5 * ((J_a.T * w) @ J_b + (J_b.T * w) @ J_a)
    J = 0.5 * (J_a + J_b)
    patch = _patch_keys(p, n, patch_m)
    score = np.stack([np.bincount(patch, w * r * J[:, j], int(patch.max()) + 1) for j in range(6)], axis=1)
    S_pinv = np.linalg.pinv(score.T @ score, rcond=_SCORE_RCOND, hermitian=True)
    information = H @ S_pinv @ H
    return Evidence(centre, lever, coordinates(X, centre, lever), 0.5 * (information + information.T), H)


@dataclass(frozen=True)
class Estimate:
    """One registration's estimate of a camera's correction in R (p' = X p), with its prior.

    X_icp : (4, 4) open3d's ICP result, every direction as ICP left it.
    X_estimated : (4, 4) the data's estimate along the informed directions only (identity when none is).
    X_map : (4, 4) the MAP correction (:func:`cell.perception.splicing.pose_prior.posterior`): what may be applied.
    overlap : probe points with a target point within reach at the calibration; noise_m : robust standard
        deviation of their point-to-plane residuals [m].
    informed : directions (of six) where the data outweigh the prior; disagreement_sigmas : the data's largest
        disagreement with the prior along one of them [prior sigmas] (beyond 3: a camera fault).
    shift_m, map_shift_m : RMS displacement of the overlap by ``X_estimated`` / ``X_map`` [m].
    misfit_before_m, misfit_m : RMS over patches of the mean point-to-plane residual [m], at the calibration and
        after ``X_map``.
    residual : what is left unknown of the disagreement once ``X_map`` is applied (None: no estimate was made).
    strong_sigmas : the largest disagreement along a strongly informed direction [prior sigmas]
        (:data:`cell.perception.splicing.pose_prior.STRONG_RATIO`).
    """

    X_icp: FloatArray
    X_estimated: FloatArray
    X_map: FloatArray
    overlap: int = 0
    noise_m: float = 0.0
    informed: int = 0
    disagreement_sigmas: float = 0.0
    shift_m: float = 0.0
    map_shift_m: float = 0.0
    misfit_before_m: float = math.inf
    misfit_m: float = math.inf
    residual: PoseResidual | None = None
    strong_sigmas: float = 0.0

    def __post_init__(self) -> None:
        for name in ("X_icp", "X_estimated", "X_map"):
            object.__setattr__(self, name, readonly(getattr(self, name)))


def register(
    source: FloatArray,
    target: FloatArray,
    spec: PerceptionSpec,
    prior: Callable[[FloatArray, float], FloatArray],
) -> Estimate:
    """Open3D ICP of ``source`` (n, 3) [m] in R onto ``target`` (m, 3) in R, as ``spec.splice_icp`` says, and the
    correction it supports against ``prior``: (overlap centroid (3,), lever [m]) -> (6, 6) prior covariance of the
    disagreement in the coordinates of :func:`coordinates` (:func:`.pose_prior.relative_covariance`).

    Every estimate is the identity when the overlap is too small. Runs ``spec.icp_iterations`` iterations at
    most; distances from :func:`registration_settings`. The paper's ICP runs on every point, the robust one and
    the evidence on an even stride of the points.
    """
    eye = np.eye(4)
    probe = np.asarray(source, dtype=np.float64)[:: max(1, math.ceil(len(source) / _PROBE_POINTS))]
    sub = np.asarray(target, dtype=np.float64)[:: max(1, math.ceil(len(target) / _TARGET_POINTS))]
    if len(probe) < MIN_OVERLAP or len(sub) < MIN_OVERLAP:
        return Estimate(eye, eye, eye)
    settings = registration_settings(spec, 0.0)
    normals = _open3d.estimate_normals(sub, settings.normal_radius_m, _NORMAL_NEIGHBOURS)
    tree = cKDTree(sub, balanced_tree=False, compact_nodes=False)  # built in half the time, same answers
    calibrated = _plane_residuals(probe, tree, sub, normals, settings.reach_m, eye)
    p0, n0, r0 = calibrated
    if len(r0) < MIN_OVERLAP:
        return Estimate(eye, eye, eye, overlap=len(r0))
    noise = _MAD_TO_SIGMA * float(np.median(np.abs(r0)))  # about 0, not the median: an offset widens it
    settings = registration_settings(spec, noise)
    corr = settings.max_correspondence_m
    if spec.splice_icp == "paper":  # as the paper ran it: every point, no subsampling
        X_icp = _open3d.icp(source, target, corr, spec.icp_iterations).X_TS
    else:
        X_icp = _open3d.icp(probe, sub, corr, spec.icp_iterations, None, normals, settings.tukey_k_m).X_TS
    before = _patch_misfit(r0, _tukey(r0, settings.tukey_k_m), _patch_keys(p0, n0, spec.merge_cell_m))
    split = _split_normals(sub, normals, settings.normal_radius_m)
    found = evidence(probe, tree, sub, normals, X_icp, settings, spec.merge_cell_m, calibrated, split)
    if found is None:
        return Estimate(X_icp, eye, eye, len(r0), noise, misfit_before_m=before, misfit_m=before)
    P_prior = prior(found.centre_R, found.lever_m)
    post = posterior(found.x_data, found.information, P_prior)
    X_estimated = pose_of(post.x_informed, found.centre_R, found.lever_m)
    X_map = pose_of(post.x_map, found.centre_R, found.lever_m)
    p, n, r = _plane_residuals(probe, tree, sub, normals, settings.reach_m, X_map)
    after = math.inf
    if len(r):
        after = _patch_misfit(r, _tukey(r, settings.tukey_k_m), _patch_keys(p, n, spec.merge_cell_m))

    def rms(X: FloatArray) -> float:
        return float(np.sqrt(np.mean(np.sum((transform_points(X, probe) - probe) ** 2, axis=1))))

    return Estimate(
        X_icp,
        X_estimated,
        X_map,
        len(r0),
        noise,
        post.informed,
        post.disagreement_sigmas,
        rms(X_estimated),
        rms(X_map),
        before,
        after,
        PoseResidual(_left(post.covariance, P_prior, before, after), found.centre_R, found.lever_m, after),
        post.strong_sigmas,
    )


def _left(posterior_cov: FloatArray, prior_cov: FloatArray, misfit_before_m: float, misfit_m: float) -> FloatArray:
    """(6, 6) [m^2] what a correction leaves unknown: the posterior's covariance, and at least the share of the
    prior that the overlap's patch misfit still shows after the correction (``misfit_m / misfit_before_m``, squared).
    The information takes the patches as independent and the sensor's biases are not (exact cameras stated at
    1 mm / 0.1 deg get informed estimates of up to 2.5 mm, docs/perception.md): the posterior alone is too sure."""
    share = misfit_m / misfit_before_m if 0.0 < misfit_before_m < math.inf and math.isfinite(misfit_m) else 1.0
    return np.asarray(posterior_cov + min(share, 1.0) ** 2 * prior_cov)
