"""Splicing the camera clouds into one (paper section 3.3), generalised to 1, 2 or more cameras.

The paper: (1) ICP of camera 1's cloud onto camera 2's, (2) merge the two with priority (each side from the
camera nearer to it), (3) ICP of the eye-in-hand cloud onto that, (4) merge again. Here: the second fixed
camera is the reference, the first fixed camera is registered onto it, then every further fixed camera and then
every eye-in-hand camera onto all the cameras registered before it; the prioritised merge
(:func:`cell.perception.merge.prioritised_merge`) then makes the paper's cloud, ``Spliced.dense``. The cloud of
all cameras registered but *not* merged is kept as well (``Spliced.registered``): a locator that weighs each
camera by its own noise loses nothing to the merge.

Registration (:func:`register`). The paper's point-to-point ICP with a 1 mm correspondence distance, on clouds
with 1-3 mm of depth noise and 1.5-4 mm point spacing, latches onto chance near-coincidences: it "corrects"
exact extrinsics by tenths of a millimetre and removes only a fraction of a real calibration error. Instead:

- each point's normal comes from a plane fit of its own camera's points (:func:`surface_normals`), snapped to
  one of the scene's dominant surface directions (:func:`direction_classes`): accurate normals from noisy
  points, and points only ever pair with points of a surface facing the same way;
- a source point's residual is its distance along that direction from the median of the nearest target points
  of its class, the neighbours chosen mostly *across* the direction (the normal coordinate is shrunk), so the
  depth noise does not choose them;
- Gauss-Newton point-to-plane steps, Tukey-weighted, solved only in the directions the overlap constrains (a
  view of top faces alone says nothing about a shift along them: such a direction is left as calibrated);
- the correction is *applied* only when it is significant: its displacement of the overlap exceeds
  :data:`MIN_SHIFT_M` and its chi-square against a covariance that treats every patch of ``merge_cell_m`` as
  one independent measurement (edges, flying pixels and shadows bias whole patches, not single points)
  exceeds :data:`SIGNIFICANCE_CHI2`, and the patch misfit drops by at least :data:`MIN_MISFIT_DROP`. With
  exact extrinsics nothing is applied; a miscalibration of 0.3-1 mm / 0.03-0.1 deg is taken out in the
  directions the overlap sees.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt
from scipy.spatial import cKDTree

from cell.errors import SensorError
from cell.geometry import FloatArray, axis_angle_to_matrix, invert, make_pose, readonly, transform_points
from cell.perception.merge import direction_classes, prioritised_merge, surface_normals
from cell.scenario import PerceptionSpec
from cell.types import Cloud, DepthImage

MOUNTS = ("fixed", "eye_in_hand")
MIN_SHIFT_M = 0.0001  # [m] a correction moving the overlap by less than this (RMS) is not applied
SIGNIFICANCE_CHI2 = 50.0  # a correction is applied only above this chi-square (patch-robust covariance)
MIN_MISFIT_DROP = 0.05  # ... and only if it lowers the patch misfit by at least this fraction
_PROBE_POINTS = 20_000  # source points a registration uses (an even stride)
_TARGET_POINTS = 150_000  # target points a registration searches (an even stride)
_NEIGHBOURS = 12  # target points whose median is a source point's local surface
_ACROSS_SHRINK = 0.2  # the normal coordinate's weight in the neighbour search (neighbours chosen in-plane)
_MIN_NEIGHBOURS = 4  # fewer target points within reach: the source point is not in the overlap
_MIN_OVERLAP = 200  # fewer source points in the overlap: no registration, the calibrated extrinsics stand
_WEAK_DIRECTION = 0.02  # a direction whose share of the constraint is below this is left as calibrated
_TUKEY_C = 4.685  # biweight cut-off [robust scales]
_CONVERGED_M = 2e-6  # [m] a step moving nothing by more than this ends the iteration
_CLASS_STRIDE_M = 1000.0  # classes are moved this far apart so one KD-tree only pairs points of one class


@dataclass(frozen=True)
class Registration:
    """One splice registration: the cloud of ``source`` onto the registered cloud of the ``target`` cameras.

    X_corr : (4, 4) correction applied to the source cloud in R (p_R' = X_corr p_R); identity if not accepted.
    X_estimated : (4, 4) the correction the registration found, applied or not.
    overlap : source probe points with target points of the same surface direction within reach.
    constrained : number of the six rigid degrees of freedom the overlap constrains (the others stay 0).
    shift_m : RMS displacement of the overlap by ``X_estimated`` [m].
    chi2 : its chi-square against the patch-robust covariance.
    misfit_before_m, misfit_m : RMS over patches of the mean point-to-surface residual [m], at the calibrated
        extrinsics and after ``X_estimated``.
    accepted : whether the correction was applied (see the module docstring).
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
class Surfaces:
    """Points with their surface-direction class: points (n, 3) [m] in R, cls (n,) (-1: none), dirs (k, 3)."""

    points: FloatArray
    cls: npt.NDArray[np.intp]
    dirs: FloatArray

    def search_coords(self, points: FloatArray, cls: npt.NDArray[np.intp]) -> FloatArray:
        """Coordinates for the same-class neighbour search: per class, two in-plane ones and the normal one
        shrunk by ``_ACROSS_SHRINK``, classes ``_CLASS_STRIDE_M`` apart."""
        d = self.dirs[cls]
        helper = np.where(np.abs(d[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
        e1 = np.cross(d, helper)
        e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
        e2 = np.cross(d, e1)
        out = np.empty((len(points), 3))
        out[:, 0] = np.einsum("ij,ij->i", points, e1) + cls * _CLASS_STRIDE_M
        out[:, 1] = np.einsum("ij,ij->i", points, e2)
        out[:, 2] = _ACROSS_SHRINK * np.einsum("ij,ij->i", points, d)
        return out


def _rigid(delta: FloatArray, centre: FloatArray) -> FloatArray:
    """(4, 4) small rigid motion: rotation by delta[:3] [rad] about ``centre`` (3,), then shift delta[3:] [m]."""
    angle = float(np.linalg.norm(delta[:3]))
    R = axis_angle_to_matrix(delta[:3], angle) if angle > 0.0 else np.eye(3)
    return make_pose(R, centre - R @ centre + delta[3:])


def _residuals(
    probe: FloatArray, cls: npt.NDArray[np.intp], target: Surfaces, tree: cKDTree, reach_m: float
) -> tuple[FloatArray, npt.NDArray[np.bool_]]:
    """Signed distance (n,) [m] of each probe point along its class direction from the median of its nearest
    same-class target points, and whether it has enough of them within reach (the overlap)."""
    q = target.search_coords(probe, cls)
    dist, idx = tree.query(q, k=_NEIGHBOURS, distance_upper_bound=reach_m)
    found = np.isfinite(dist)
    ok = found.sum(axis=1) >= _MIN_NEIGHBOURS
    idx = np.where(found, idx, 0)
    d = target.dirs[cls]
    w = np.einsum("ikj,ij->ik", target.points[idx], d)  # target points along the source point's direction
    w = np.where(found, w, np.nan)
    with np.errstate(all="ignore"):
        surface = np.nanmedian(np.where(ok[:, None], w, 0.0), axis=1)
    return np.einsum("ij,ij->i", probe, d) - surface, ok


def _patch_keys(points: FloatArray, cls: npt.NDArray[np.intp], patch_m: float) -> npt.NDArray[np.intp]:
    """(n,) patch index: points of one class in one cube of edge ``patch_m``."""
    ijk = np.floor(points / patch_m).astype(np.int64)
    ijk -= ijk.min(axis=0)
    dims = ijk.max(axis=0) + 1
    key = ((ijk[:, 0] * dims[1] + ijk[:, 1]) * dims[2] + ijk[:, 2]) * 64 + cls
    _, inverse = np.unique(key, return_inverse=True)
    return np.asarray(inverse.reshape(-1), np.intp)


def _patch_misfit(r: FloatArray, w: FloatArray, patch: npt.NDArray[np.intp]) -> float:
    """RMS over patches (weighted by their weight) of each patch's weighted mean residual [m]."""
    sw = np.bincount(patch, w)
    used = sw > 0.0
    mean = np.bincount(patch, w * r)[used] / sw[used]
    return float(np.sqrt(np.sum(sw[used] * mean**2) / np.sum(sw[used]))) if used.any() else math.inf


def register(
    source: FloatArray,
    source_cls: npt.NDArray[np.intp],
    target: Surfaces,
    spec: PerceptionSpec,
) -> tuple[FloatArray, dict[str, float]]:
    """Point-to-surface registration of ``source`` (n, 3) [m] in R (classes (n,)) onto ``target``.

    Returns the estimated correction X (4, 4) in R (p' = X p) and diagnostics: overlap, constrained, shift_m,
    chi2, misfit_before_m, misfit_m (see :class:`Registration`). X is the identity when the overlap is too
    small. Iterates at most ``spec.icp_iterations`` times; neighbours are searched within ``spec.voxel_m``.
    """
    use = source_cls >= 0
    probe, cls = source[use], source_cls[use]
    stride = max(1, math.ceil(len(probe) / _PROBE_POINTS))
    probe, cls = probe[::stride], cls[::stride]
    t_use = np.flatnonzero(target.cls >= 0)
    t_use = t_use[:: max(1, math.ceil(len(t_use) / _TARGET_POINTS))]
    sub = Surfaces(target.points[t_use], target.cls[t_use], target.dirs)
    info = {"overlap": 0.0, "constrained": 0.0, "shift_m": 0.0, "chi2": 0.0}
    info |= {"misfit_before_m": math.inf, "misfit_m": math.inf}
    if len(probe) < _MIN_OVERLAP or len(sub.points) < _MIN_OVERLAP:
        return np.eye(4), info
    tree = cKDTree(sub.search_coords(sub.points, sub.cls), balanced_tree=False, compact_nodes=False)
    reach = spec.voxel_m
    r0, ok0 = _residuals(probe, cls, sub, tree, reach)
    probe, cls, r0 = probe[ok0], cls[ok0], r0[ok0]
    info["overlap"] = float(len(probe))
    if len(probe) < _MIN_OVERLAP:
        return np.eye(4), info
    centre = probe.mean(axis=0)
    lever = float(np.sqrt(np.mean(np.sum((probe - centre) ** 2, axis=1))))  # rotation [rad] -> [m]
    normal = sub.dirs[cls]
    patch = _patch_keys(probe, cls, spec.merge_cell_m)
    X = np.eye(4)
    w = np.ones(len(probe))
    r = r0
    ok = np.ones(len(probe), bool)
    keep_dirs = np.zeros((6, 0))
    for it in range(spec.icp_iterations):
        if it:
            r, ok = _residuals(transform_points(X, probe), cls, sub, tree, reach)
            r = np.where(ok, r, 0.0)
        scale = max(1.4826 * float(np.median(np.abs(r[ok]))), 1e-5)
        u = r / (_TUKEY_C * scale)
        w = np.where(ok & (np.abs(u) < 1.0), (1.0 - u * u) ** 2, 0.0)
        p = transform_points(X, probe) - centre
        J = np.hstack([np.cross(p, normal) / lever, normal])  # rotation columns scaled to metres at the lever
        H = (J.T * w) @ J
        g = (J.T * w) @ r
        vals, vecs = np.linalg.eigh(H)
        keep_dirs = vecs[:, vals >= _WEAK_DIRECTION * max(float(vals.sum()), 1e-300)]
        step = -keep_dirs @ ((keep_dirs.T @ g) / vals[vals >= _WEAK_DIRECTION * max(float(vals.sum()), 1e-300)])
        delta = np.concatenate([step[:3] / lever, step[3:]])
        X = _rigid(delta, transform_points(X, centre[None])[0]) @ X
        if np.max(np.abs(step)) < _CONVERGED_M:
            break
    moved = transform_points(X, probe)
    shift = float(np.sqrt(np.mean(np.sum((moved - probe) ** 2, axis=1))))
    # Patch-robust covariance of the estimate in the constrained directions: each patch one measurement.
    p = moved - transform_points(X, centre[None])[0]
    J = np.hstack([np.cross(p, normal) / lever, normal]) @ keep_dirs
    n_patch = int(patch.max()) + 1
    score = np.stack([np.bincount(patch, w * r * J[:, j], n_patch) for j in range(J.shape[1])], axis=1)
    H = (J.T * w) @ J
    try:
        H_inv = np.linalg.inv(H)
        cov = H_inv @ (score.T @ score) @ H_inv
        # The estimate, in the same coordinates: the rigid motion's rotation vector (scaled) and shift.
        R = X[:3, :3]
        rotvec = 0.5 * np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
        c = transform_points(X, centre[None])[0]
        est = keep_dirs.T @ np.concatenate([rotvec * lever, c - centre])
        chi2 = float(est @ np.linalg.solve(cov, est))
    except np.linalg.LinAlgError:
        chi2 = 0.0
    info |= {"constrained": float(keep_dirs.shape[1]), "shift_m": shift, "chi2": chi2}
    info["misfit_before_m"] = _patch_misfit(r0, w, patch)
    info["misfit_m"] = _patch_misfit(r, w, patch)
    return X, info


def splice_order(images: Mapping[str, DepthImage], names: tuple[str, ...]) -> tuple[str, ...]:
    """Splicing order: 2nd fixed camera (the reference), 1st fixed, other fixed, then the eye-in-hand ones."""
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
    if len(order) > 1:
        cls, dirs = direction_classes(normals)
        for k, name in enumerate(order[1:], start=1):
            part = slice(bounds[k], bounds[k + 1])
            target = Surfaces(points[: bounds[k]], cls[: bounds[k]], dirs)
            X, info = register(points[part], cls[part], target, spec)
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
                )
            )
            if accepted:
                points[part] = transform_points(X_corr, points[part])
                X_RC[index[name]] = X_corr @ X_RC[index[name]]
    registered = Cloud(points, "R", camera, cameras)
    keep = prioritised_merge(points, camera, X_RC, fx, spec.merge_cell_m, spec.voxel_m, normals)
    kept = {n: int(np.count_nonzero(keep[bounds[k] : bounds[k + 1]])) for k, n in enumerate(order)}
    return Spliced(registered.select(keep), registered, tuple(registrations), kept)
