"""Splicing the camera clouds into one (paper section 3.3), generalised to 1, 2 or more cameras.

The paper: (1) ICP of camera 1's cloud onto camera 2's, (2) merge the two with priority (each side from the
camera nearer to it), (3) ICP of the eye-in-hand cloud onto that, (4) merge again. Here: the eye-in-hand camera
(calibrated to the robot) is the reference when there is one, else the second fixed camera; then the fixed
cameras in the paper's order are each registered onto all the cameras registered before them; the prioritised
merge (:func:`cell.perception.merge.prioritised_merge`) then makes the paper's cloud, ``Spliced.dense``. The
cloud of all cameras registered but *not* merged is kept as well (``Spliced.registered``): a locator that
weighs each camera by its own noise loses nothing to the merge.

Registration (:func:`register`) is open3d's, through :mod:`cell.perception._open3d`, chosen by
``PerceptionSpec.splice_icp``:

- ``"paper"``: the paper's point-to-point ICP on every point, max correspondence ``icp_max_correspondence_m``
  (1 mm), ``icp_iterations`` (50). On clouds with 1-3 mm of depth noise and 1.5-4 mm point spacing it latches onto
  chance near-coincidences: it "corrects" exact extrinsics by tenths of a millimetre and removes only part of
  a real calibration error.
- ``"robust"`` (default): point-to-plane ICP with a Tukey kernel, target normals estimated by open3d; the
  kernel width, correspondence distance and normal radius are derived in one place
  (:func:`registration_settings`) from the voxel size and the noise measured in the overlap; source and
  target are thinned to an even stride of at most :data:`_PROBE_POINTS` / :data:`_TARGET_POINTS` points.

A correction's motion along a direction the overlap does not constrain (a view of top faces alone says nothing
about a shift along them) is dropped: that direction stays as calibrated.
Either way the correction is *applied* only when it is significant (a test, not a solver): its displacement
of the overlap exceeds :data:`MIN_SHIFT_M`, its chi-square against a covariance that treats every patch of
``merge_cell_m`` as one independent measurement (edges, flying pixels and shadows bias whole patches, not
single points) exceeds :data:`SIGNIFICANCE_CHI2`, and the patch misfit (point-to-plane) drops by at least
:data:`MIN_MISFIT_DROP`. With exact extrinsics nothing is applied; a miscalibration of 0.3-1 mm / 0.03-0.1 deg
is taken out.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt
from scipy.spatial.transform import Rotation

from cell.errors import SensorError
from cell.geometry import FloatArray, invert, make_pose, readonly, transform_points
from cell.perception import _open3d
from cell.perception.merge import prioritised_merge, surface_normals
from cell.scenario import PerceptionSpec
from cell.types import Cloud, DepthImage

MOUNTS = ("fixed", "eye_in_hand")
MIN_SHIFT_M = 0.0001  # [m] a correction moving the overlap by less than this (RMS) is not applied
SIGNIFICANCE_CHI2 = 50.0  # a correction is applied only above this chi-square (patch-robust covariance)
MIN_MISFIT_DROP = 0.05  # ... and only if it lowers the patch misfit by at least this fraction
_PROBE_POINTS = 20_000  # source points a registration uses (an even stride)
_TARGET_POINTS = 60_000  # target points a registration searches (an even stride)
_MIN_OVERLAP = 200  # fewer source points in the overlap: no registration, the calibrated extrinsics stand
_WEAK_DIRECTION = 0.005  # a direction holding less than this share of the constraint is left as calibrated
_TUKEY_C = 4.685  # biweight cut-off [robust scales] (95 % efficiency on Gaussian residuals)
_MAD_TO_SIGMA = 1.4826  # median absolute deviation -> standard deviation (Gaussian)
_NORMAL_RADIUS_VOXELS = 2.0  # target normals from neighbours within this many voxels
_NORMAL_NEIGHBOURS = 50  # ... at most this many (the nearest)
_MIN_NOISE_M = 1e-4  # [m] floor of the measured noise (noise-free synthetic clouds)


@dataclass(frozen=True)
class Registration:
    """One splice registration: the cloud of ``source`` onto the registered cloud of the ``target`` cameras.

    X_corr : (4, 4) correction applied to the source cloud in R (p_R' = X_corr p_R); identity if not accepted.
    X_estimated : (4, 4) the correction the registration found, applied or not: open3d's ICP result without
        its motion along directions the overlap does not constrain.
    overlap : source probe points with a target point within reach (``voxel_m``) at the calibrated extrinsics.
    constrained : number of the six rigid degrees of freedom the overlap constrains (the chi-square's).
    shift_m : RMS displacement of the overlap by ``X_estimated`` [m].
    chi2 : its chi-square against the patch-robust covariance.
    misfit_before_m, misfit_m : RMS over patches of the mean point-to-plane residual [m], at the calibrated
        extrinsics and after ``X_estimated``.
    accepted : whether the correction was applied (see the module docstring).
    noise_m : robust standard deviation of the point-to-plane residuals in the overlap [m] (calibrated).
    """

    source: str
    target: tuple[str, ...]
    X_corr: FloatArray
    X_estimated: FloatArray
    overlap: int
    constrained: int
    shift_m: float
    chi2: float
    misfit_before_m: float
    misfit_m: float
    accepted: bool
    noise_m: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "X_corr", readonly(self.X_corr))
        object.__setattr__(self, "X_estimated", readonly(self.X_estimated))


@dataclass(frozen=True)
class Spliced:
    """The spliced clouds and how they were made, all in R, before Z passthrough and downsampling.

    dense : the paper's cloud: every camera registered, then the prioritised merge; ``camera`` tags each point.
    registered : every camera registered, nothing merged away (per-point ``camera`` index).
    registrations : the registrations in the order they were made.
    kept : camera name -> number of its points that survived the prioritised merge.
    """

    dense: Cloud
    registered: Cloud
    registrations: tuple[Registration, ...] = ()
    kept: dict[str, int] = field(default_factory=dict)


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
    probe: FloatArray, target: FloatArray, normals: FloatArray, reach_m: float, X: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Point-to-plane residuals of the probe points moved by X against their nearest target points within reach.

    Returns (moved probe points (k, 3), their target normals (k, 3), signed residuals (k,) [m]).
    """
    pairs = _open3d.correspondences(probe, target, reach_m, X)
    moved = transform_points(X, probe[pairs[:, 0]])
    n = normals[pairs[:, 1]]
    return moved, n, np.einsum("ij,ij->i", moved - target[pairs[:, 1]], n)


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
    J = np.hstack([np.cross(p - centre, n) / lever, n])
    vals, vecs = np.linalg.eigh((J.T * w) @ J)
    return J, vecs[:, vals >= _WEAK_DIRECTION * max(float(vals.sum()), 1e-300)], centre, lever


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
) -> tuple[FloatArray, dict[str, float]]:
    """The part of the correction X_icp (4, 4) of ``probe`` (n, 3) onto ``target`` (m, 3) (unit normals (m, 3))
    that the overlap constrains, and how much the data support it (all in R).

    Returns (X (4, 4): X_icp without its motion along directions the overlap does not constrain; diagnostics
    constrained, shift_m, chi2, misfit_before_m, misfit_m of X, see :class:`Registration`). The chi-square is a
    sandwich (patch-robust) covariance of a point-to-plane least-squares estimate at X: Tukey-weighted
    residuals, one score per patch of ``patch_m`` and surface direction, in the constrained directions.
    """
    reach, k = settings.reach_m, settings.tukey_k_m
    info = {"constrained": 0.0, "shift_m": 0.0, "chi2": 0.0, "misfit_before_m": math.inf, "misfit_m": math.inf}
    p0, n0, r0 = _plane_residuals(probe, target, normals, reach, np.eye(4))
    p, n, r = _plane_residuals(probe, target, normals, reach, X_icp)
    if len(r0) < _MIN_OVERLAP or len(r) < _MIN_OVERLAP:
        return np.eye(4), info
    info["misfit_before_m"] = _patch_misfit(r0, _tukey(r0, k), _patch_keys(p0, n0, patch_m))
    _, D, centre, lever = _constrained(p, n, _tukey(r, k))
    X = _restricted(X_icp, D, centre, lever)
    p, n, r = _plane_residuals(probe, target, normals, reach, X)
    if len(r) < _MIN_OVERLAP:
        return np.eye(4), info
    w = _tukey(r, k)
    patch = _patch_keys(p, n, patch_m)
    info["misfit_m"] = _patch_misfit(r, w, patch)
    info["shift_m"] = float(np.sqrt(np.mean(np.sum((transform_points(X, probe) - probe) ** 2, axis=1))))
    J, D, centre, lever = _constrained(p, n, w)
    Jd = J @ D
    score = np.stack([np.bincount(patch, w * r * Jd[:, j], int(patch.max()) + 1) for j in range(D.shape[1])], 1)
    c0 = transform_points(invert(X), centre[None])[0]
    est = D.T @ np.concatenate([Rotation.from_matrix(X[:3, :3]).as_rotvec() * lever, centre - c0])
    try:
        H_inv = np.linalg.inv((Jd.T * w) @ Jd)
        chi2 = float(est @ np.linalg.solve(H_inv @ (score.T @ score) @ H_inv, est))
    except np.linalg.LinAlgError:
        chi2 = 0.0
    info |= {"constrained": float(D.shape[1]), "chi2": chi2}
    return X, info


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
    info = {"overlap": 0.0, "noise_m": 0.0, "constrained": 0.0, "shift_m": 0.0, "chi2": 0.0}
    info |= {"misfit_before_m": math.inf, "misfit_m": math.inf}
    if len(probe) < _MIN_OVERLAP or len(sub) < _MIN_OVERLAP:
        return np.eye(4), info
    settings = registration_settings(spec, 0.0)
    normals = _open3d.estimate_normals(sub, settings.normal_radius_m, _NORMAL_NEIGHBOURS)
    _, _, r0 = _plane_residuals(probe, sub, normals, settings.reach_m, np.eye(4))
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
    X, stats = significance(probe, sub, normals, X, settings, spec.merge_cell_m)
    return X, info | stats


def splice_order(images: Mapping[str, DepthImage], names: tuple[str, ...]) -> tuple[str, ...]:
    """Splicing order: the eye-in-hand cameras (the first is the reference), then the 2nd fixed camera, the 1st
    fixed and the other fixed ones (the paper registers camera 1 onto camera 2)."""
    for name in names:
        if name not in images:
            raise ValueError(f"splice: no depth image for camera {name!r}; images: {', '.join(images)}")
        if images[name].mount not in MOUNTS:
            raise ValueError(f"camera {name!r} has mount {images[name].mount!r}; valid: {', '.join(MOUNTS)}")
    fixed = [n for n in names if images[n].mount == "fixed"]
    moving = [n for n in names if images[n].mount != "fixed"]
    if len(fixed) >= 2:
        fixed = [fixed[1], fixed[0], *fixed[2:]]
    return (*moving, *fixed)


def splice(
    clouds: Mapping[str, Cloud], images: Mapping[str, DepthImage], X_WR: FloatArray, spec: PerceptionSpec
) -> Spliced:
    """Splice per-camera clouds (frame R, from :func:`clouds_in_robot_frame`) into one in R (module docstring).

    images : the captures the clouds came from (their mounts and calibrated poses X_WC, intrinsics fx).
    Empty clouds are skipped; :class:`SensorError` if every cloud is empty.
    """
    names = tuple(n for n in clouds if len(clouds[n]) > 0)
    if not names:
        raise SensorError(f"nothing to splice: every camera cloud is empty ({', '.join(clouds) or 'none given'})")
    for n in names:
        if clouds[n].frame != "R":
            raise ValueError(f"splice: cloud of {n!r} is in frame {clouds[n].frame!r}; expected 'R'")
    order = splice_order(images, names)
    # Keep the clouds' shared camera tuple when they have one (indices stay valid), else index by name order.
    shared = {clouds[n].cameras for n in names}
    cameras = shared.pop() if len(shared) == 1 else names
    if not set(names) <= set(cameras):
        cameras = names
    index = {n: cameras.index(n) for n in names}
    X_RW = invert(np.asarray(X_WR, dtype=np.float64))
    X_RC = {index[n]: X_RW @ images[n].X_WC for n in order}
    fx = {index[n]: images[n].intrinsics.fx for n in order}
    points = np.concatenate([np.asarray(clouds[n].points) for n in order])
    camera = np.concatenate([np.full(len(clouds[n]), index[n], np.int16) for n in order])
    bounds = np.cumsum([0] + [len(clouds[n]) for n in order])
    eyes = {i: X[:3, 3] for i, X in X_RC.items()}
    registrations = []
    # Normals from plane fits twice the voxel wide (a voxel-wide fit of 2-3 mm noise is as noisy as the depth).
    normals = surface_normals(points, camera, eyes, 2.0 * spec.voxel_m, spec.merge_cell_m)
    for k, name in enumerate(order[1:], start=1):
        part = slice(bounds[k], bounds[k + 1])
        X, info = register(points[part], points[: bounds[k]], spec)
        accepted = (
            info["shift_m"] >= MIN_SHIFT_M
            and info["chi2"] >= SIGNIFICANCE_CHI2
            and info["misfit_m"] <= (1.0 - MIN_MISFIT_DROP) * info["misfit_before_m"]
        )
        X_corr = X if accepted else np.eye(4)
        registrations.append(
            Registration(
                name,
                order[:k],
                X_corr,
                X,
                int(info["overlap"]),
                int(info["constrained"]),
                info["shift_m"],
                info["chi2"],
                info["misfit_before_m"],
                info["misfit_m"],
                accepted,
                info["noise_m"],
            )
        )
        if accepted:
            points[part] = transform_points(X_corr, points[part])
            X_RC[index[name]] = X_corr @ X_RC[index[name]]
    registered = Cloud(points, "R", camera, cameras)
    keep = prioritised_merge(points, camera, X_RC, fx, spec.merge_cell_m, spec.voxel_m, normals)
    kept = {n: int(np.count_nonzero(keep[bounds[k] : bounds[k + 1]])) for k, n in enumerate(order)}
    return Spliced(registered.select(keep), registered, tuple(registrations), kept)
