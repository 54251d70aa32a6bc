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
PATCH_M = 0.010  # residuals within a cube of this side share their error (a facet, a tack, a bias): one cluster [m]


@dataclass(frozen=True)
class SurfaceFit:
    """A fitted surface: its model and parameters ``theta`` (k,), their covariance ``cov`` (k, k), the robust
    scale of the inliers' residuals ``scale_m`` [m] and how many points held it (``inliers``)."""

    model: SurfaceModel
    theta: FloatArray
    cov: FloatArray
    scale_m: float
    inliers: int

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
    pooled = max(_mad_scale(r), 1e-6)
    out = np.full(len(r), pooled)
    for g in np.unique(groups):
        mine = groups == g
        if mine.sum() >= MIN_GROUP:
            out[mine] = max(_mad_scale(r[mine]), 1e-6)
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
    robust = inv @ _cluster_meat(J[: len(keep)], res, keep) @ inv
    return SurfaceFit(model, final.x, robust if np.trace(robust) > np.trace(cov) else cov, pooled, len(keep))


def _cluster_meat(J: FloatArray, res: FloatArray, p: FloatArray) -> FloatArray:
    """(k, k) the middle of the cluster-robust (sandwich) covariance: sum over the patches of :data:`PATCH_M` of
    (J_g^T r_g)(J_g^T r_g)^T, for the points' weighted Jacobian J (n, k) and residuals ``res`` (n,): residuals that
    share a sign over a patch (the surface is not the model there) count as one error, not as many."""
    cells = np.floor(p / PATCH_M).astype(np.int64)
    _, label = np.unique(cells, axis=0, return_inverse=True)
    score = np.zeros((int(label.max()) + 1, J.shape[1]))
    np.add.at(score, label.ravel(), J * res[:, None])
    n, k = len(res), J.shape[1]
    g = len(score)
    scale = g / max(g - 1, 1) * (n - 1) / max(n - k, 1)  # the usual small-sample correction
    return np.asarray(scale * score.T @ score)
