"""A surface fitted to points robustly, with the covariance of its parameters: a Huber fit from the map's surface
(the start), the points beyond three robust scales of their camera dropped, then a least-squares refinement on the
rest weighted by their camera's scale (scipy), whose Jacobian gives the covariance (docs/curves.md section 2).
Metres, radians."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from scipy.optimize import least_squares

from cell.geometry import FloatArray, readonly
from cell.seams.curved.surfaces import SurfaceModel

MAD_TO_SIGMA = 1.4826
HUBER_SCALE_M = 0.0005  # where the start's Huber loss turns linear [m]: about a depth camera's noise at 1 m
START_POINTS = 600  # the robust start runs on this many of the points at most (evenly thinned)
TRIM_SCALES = 3.0  # points beyond this many robust scales of the start's residuals are not the surface
MIN_GROUP = 30  # a camera with fewer points on the surface takes the pooled scale
SCALE_FLOOR_M = 0.0001  # no camera's points scatter less than this about a surface [m] (a depth camera's best)
PATCH_M = 0.010  # residuals within a cube of this side share their error (a facet, a tack, a bias): one cluster [m]


@dataclass(frozen=True)
class SurfaceFit:
    """A fitted surface: its model and parameters ``theta`` (k,), their covariance ``cov`` (k, k), the robust
    scale of the inliers' residuals ``scale_m`` [m], how many points held it (``inliers``) and ``lack_m`` [m]: the
    RMS of the residuals' means over patches of :data:`PATCH_M` beyond what the noise explains (0: the model
    explains its points; a faceted round, a plate bent near a tack or stray points make it grow) and
    ``cameras_m`` [m]: the spread of the cameras' mean residuals (each camera's pose error moves its points: the
    fit is a mix of them, off by about as much; 0 with one camera)."""

    model: SurfaceModel
    theta: FloatArray
    cov: FloatArray
    scale_m: float
    inliers: int
    lack_m: float = 0.0
    cameras_m: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "theta", readonly(np.asarray(self.theta, dtype=float)))
        object.__setattr__(self, "cov", readonly(np.asarray(self.cov, dtype=float)))

    @property
    def ok(self) -> bool:
        """The fit holds: enough points and a finite covariance."""
        return self.inliers > 0 and bool(np.isfinite(self.cov).all())


def _mad_scale(r: FloatArray) -> float:
    return MAD_TO_SIGMA * float(np.median(np.abs(r - np.median(r)))) if len(r) else math.inf


def _group_scales(r: FloatArray, groups: npt.NDArray[np.intp]) -> FloatArray:
    """(n,) the robust scale of the residuals r (n,) of each point's group (a camera: each has its own noise); the
    pooled scale for a group of fewer than :data:`MIN_GROUP` points."""
    pooled = max(_mad_scale(r), SCALE_FLOOR_M)
    out = np.full(len(r), pooled)
    for g in np.unique(groups):
        mine = groups == g
        if mine.sum() >= MIN_GROUP:
            out[mine] = max(_mad_scale(r[mine]), SCALE_FLOOR_M)
    return out


def fit_surface(
    model: SurfaceModel,
    p: FloatArray,
    min_points: int,
    prior: FloatArray | None = None,
    groups: npt.NDArray[np.intp] | None = None,
) -> SurfaceFit:
    """``model`` fitted to the points p (n, 3) [m], each weighted by the robust scale of its group's residuals
    (``groups`` (n,): its camera; None: one group); not held (``ok`` False, infinite covariance) when fewer than
    ``min_points`` points or the fit leaves a direction of its parameters unpinned. ``prior`` (k,): a standard
    deviation of each parameter about the reference (inf: none; a tube's radius known to its tolerance)."""
    k = model.size
    w = np.zeros(k) if prior is None else 1.0 / np.asarray(prior, dtype=float)
    bad = SurfaceFit(model, np.zeros(k), np.full((k, k), np.inf), math.inf, 0)
    if len(p) < max(min_points, k + 1):
        return bad
    step = math.ceil(len(p) / START_POINTS) if len(p) > START_POINTS else 1
    q = p[::step]
    start = least_squares(
        lambda t: np.concatenate([model.value(q, t), HUBER_SCALE_M * w * t]),
        np.zeros(k),
        jac=lambda t: np.vstack([model.jac(q, t), HUBER_SCALE_M * np.diag(w)]),
        loss="huber",
        f_scale=HUBER_SCALE_M,
        method="trf",
        x_scale=1e-3,
    )
    r = model.value(p, start.x)
    scale = _group_scales(r - np.median(r), np.zeros(len(p), np.intp) if groups is None else groups)
    inlier = np.abs(r - np.median(r)) <= TRIM_SCALES * scale
    keep, wk = p[inlier], 1.0 / scale[inlier]
    if len(keep) < max(min_points, k + 1):
        return bad
    final = least_squares(
        lambda t: np.concatenate([wk * model.value(keep, t), w * t]),
        start.x,
        jac=lambda t: np.vstack([wk[:, None] * model.jac(keep, t), np.diag(w)]),
        method="lm",
        x_scale=1e-3,
    )
    J = np.asarray(final.jac)
    res = np.asarray(final.fun)[: len(keep)]
    s2 = float(res @ res) / max(len(keep) - k, 1)  # about 1: the residuals are in their groups' scales
    pooled = float(np.sqrt(np.mean((res / wk) ** 2)))
    JtJ = J.T @ J
    if np.linalg.cond(JtJ) > 1e14:
        return SurfaceFit(model, final.x, np.full((k, k), np.inf), pooled, len(keep))
    inv = np.linalg.inv(JtJ)
    cov = s2 * inv
    v, g = model.implicit(final.x)(keep)
    label = _patches(keep - v[:, None] * g)  # the patches on the surface: a point's noise must not pick its patch
    robust = inv @ _cluster_meat(J[: len(keep)], res, label) @ inv
    cov = robust if np.trace(robust) > np.trace(cov) else cov
    r_m = res / wk
    kept_groups = np.zeros(len(keep), np.intp) if groups is None else groups[inlier]
    lack = _lack_of_fit(r_m, label)
    return SurfaceFit(model, final.x, cov, pooled, len(keep), lack, _camera_spread(r_m, kept_groups))


def _camera_spread(r: FloatArray, groups: npt.NDArray[np.intp]) -> float:
    """[m] the standard deviation of the mean residual r (n,) [m] of each group (camera) of at least
    :data:`MIN_GROUP` points (0 with fewer than two such groups)."""
    means = [float(r[groups == g].mean()) for g in np.unique(groups) if int((groups == g).sum()) >= MIN_GROUP]
    return float(np.std(means, ddof=1)) if len(means) >= 2 else 0.0


def _patches(p: FloatArray) -> npt.NDArray[np.intp]:
    """(n,) the patch of :data:`PATCH_M` each point p (n, 3) lies in (labels 0..)."""
    _, label = np.unique(np.floor(p / PATCH_M).astype(np.int64), axis=0, return_inverse=True)
    return np.asarray(label.ravel(), dtype=np.intp)


def _lack_of_fit(r: FloatArray, label: npt.NDArray[np.intp]) -> float:
    """[m] how far the residuals' means r (n,) [m] over the patches (``label`` (n,)) scatter beyond what the
    scatter within the patches explains (one-way analysis of variance: the between-patch variance component)."""
    g = int(label.max()) + 1
    count = np.bincount(label, minlength=g).astype(float)
    mean = np.bincount(label, r, minlength=g) / np.maximum(count, 1.0)
    used = int((count > 0).sum())
    within = float(((r - mean[label]) ** 2).sum()) / max(len(r) - used, 1)
    between = float((count * mean**2).sum()) - used * within
    return math.sqrt(max(between / max(len(r), 1), 0.0))


def _cluster_meat(J: FloatArray, res: FloatArray, label: npt.NDArray[np.intp]) -> FloatArray:
    """(k, k) the middle of the cluster-robust (sandwich) covariance: sum over the patches (``label`` (n,)) of
    (J_g^T r_g)(J_g^T r_g)^T, for the points' weighted Jacobian J (n, k) and residuals ``res`` (n,): residuals that
    share a sign over a patch (the surface is not the model there) count as one error, not as many."""
    score = np.zeros((int(label.max()) + 1, J.shape[1]))
    np.add.at(score, label.ravel(), J * res[:, None])
    n, k = len(res), J.shape[1]
    g = len(score)
    scale = g / max(g - 1, 1) * (n - 1) / max(n - k, 1)  # the usual small-sample correction
    return np.asarray(scale * score.T @ score)
