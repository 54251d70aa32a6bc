"""A camera's stated calibration as the prior on its pose, and the splice's MAP estimate that weighs the overlap's
data against it along the directions the data inform (docs/perception.md, "The splice: an estimate with the stated
calibration as its prior")."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from cell.geometry import FloatArray, readonly

INFORMED_RATIO = 10.0  # a direction moves only where the prior's variance is this many times the data's
FAULT_SIGMAS = 3.0  # a disagreement beyond this many prior sigmas along an informed direction is a camera fault
STRONG_RATIO = 100.0  # a direction the data inform this many times better than the prior is strongly informed
_RELATIVE_EPS = 1e-12  # prior eigenvalues below this share of the largest are exact (the direction is fixed)


@dataclass(frozen=True)
class PoseUncertainty:
    """How well one camera's pose is known: RMS translation [m] and rotation [rad] of its calibration residual."""

    translation_m: float = 0.0
    rotation_rad: float = 0.0

    def sigma_at(self, range_m: float) -> float:
        """Per-axis standard deviation [m] of a point at ``range_m`` from the camera (an RMS over three axes)."""
        return math.hypot(self.translation_m, range_m * self.rotation_rad) / math.sqrt(3.0)

    @property
    def zero(self) -> bool:
        return self.translation_m == 0.0 and self.rotation_rad == 0.0


@dataclass(frozen=True)
class PoseResidual:
    """What is left unknown of a camera's pose once the splice applied its correction: the covariance (6, 6)
    [m^2] of the disagreement left (:attr:`Posterior.covariance`) in the registration's coordinates about the
    overlap's centroid ``centre_R`` (3,) [m] with ``lever_m`` [m] (:mod:`cell.perception.splicing.registration`)."""

    covariance: FloatArray
    centre_R: FloatArray
    lever_m: float
    misfit_m: float = 0.0  # RMS over patches of the overlap's mean point-to-plane residual after the correction [m]

    def __post_init__(self) -> None:
        object.__setattr__(self, "covariance", readonly(self.covariance))
        object.__setattr__(self, "centre_R", readonly(self.centre_R))

    def sigma_at(self, p_R: FloatArray) -> float:
        """Per-axis standard deviation [m] of a point at ``p_R`` (3,) moved by that error (an RMS over three axes,
        as :meth:`PoseUncertainty.sigma_at`): a rotation ``w`` (the first three coordinates over the lever) about
        the centroid and a shift ``s`` move it by ``s + w x (p - centre)``; never less than the misfit the overlap
        still shows after the correction (the surfaces of the camera and of its targets still that far apart: what
        the data's information, which assumes the model right, cannot see)."""
        d = np.asarray(p_R, dtype=float) - self.centre_R
        skew = np.array([[0.0, -d[2], d[1]], [d[2], 0.0, -d[0]], [-d[1], d[0], 0.0]])
        J = np.hstack([-skew / self.lever_m, np.eye(3)])
        spread = math.sqrt(max(float(np.trace(J @ self.covariance @ J.T)), 0.0) / 3.0)
        return math.hypot(spread, self.misfit_m if math.isfinite(self.misfit_m) else 0.0)


def camera_covariance(u: PoseUncertainty, origin_R: FloatArray, centre_R: FloatArray, lever_m: float) -> FloatArray:
    """(6, 6) prior covariance [m^2] of a camera's pose error in the registration's coordinates about the
    overlap's centroid ``centre_R`` (3,) with ``lever_m``; the camera's optical centre is ``origin_R`` (3,)."""
    d = np.asarray(centre_R, dtype=float) - np.asarray(origin_R, dtype=float)
    skew = np.array([[0.0, -d[2], d[1]], [d[2], 0.0, -d[0]], [-d[1], d[0], 0.0]])
    A = np.zeros((6, 6))
    A[:3, :3] = lever_m * np.eye(3)
    A[3:, :3] = -skew
    A[3:, 3:] = np.eye(3)
    spread = np.repeat([u.rotation_rad**2 / 3.0, u.translation_m**2 / 3.0], 3)
    return np.asarray((A * spread) @ A.T)


def relative_covariance(
    source: tuple[PoseUncertainty, FloatArray],
    targets: Sequence[tuple[PoseUncertainty, FloatArray, float]],
    centre_R: FloatArray,
    lever_m: float,
) -> FloatArray:
    """(6, 6) prior covariance of the disagreement between the ``source`` camera (uncertainty, origin) and the
    cloud of ``targets`` (uncertainty, origin, share of the target's points), in the coordinates of
    :func:`camera_covariance`: independent errors add, a target camera's weighted by the square of its share."""
    P = camera_covariance(source[0], source[1], centre_R, lever_m)
    for u, origin, share in targets:
        P = P + share**2 * camera_covariance(u, origin, centre_R, lever_m)
    return P


@dataclass(frozen=True)
class Posterior:
    """The splice's estimate of one camera's correction, in the registration's coordinates (6,) [m].

    x_map : the MAP correction along the informed directions (zero along the others): what may be applied.
    x_informed : the data's estimate along the informed directions, unshrunk (what the overlap says there).
    informed : number of informed directions (0-6).
    disagreement_sigmas : the largest disagreement along an informed direction, in prior sigmas.
    covariance : (6, 6) [m^2] of the disagreement left once ``x_map`` is applied (:func:`residual_covariance`):
        the prior's along every direction that was not moved, less along those the data fixed.
    strong_sigmas : the same along the strongly informed directions only (:data:`STRONG_RATIO`; 0 when none).
    """

    x_map: FloatArray
    x_informed: FloatArray
    informed: int
    disagreement_sigmas: float
    covariance: FloatArray = field(default_factory=lambda: np.zeros((6, 6)))
    strong_sigmas: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "x_map", readonly(self.x_map))
        object.__setattr__(self, "x_informed", readonly(self.x_informed))
        object.__setattr__(self, "covariance", readonly(self.covariance))

    @property
    def fault(self) -> bool:
        """The data disagree with the prior beyond :data:`FAULT_SIGMAS` along an informed direction."""
        return self.disagreement_sigmas > FAULT_SIGMAS


def posterior(x_data: FloatArray, information: FloatArray, prior: FloatArray) -> Posterior:
    """The MAP correction from the data's estimate ``x_data`` (6,), its information (6, 6) [1/m^2] and the prior
    covariance (6, 6) [m^2] (module docstring). A prior of zero gives zero and no informed direction."""
    x_data = np.asarray(x_data, dtype=float)
    zero = np.zeros(6)
    vals, vecs = np.linalg.eigh(0.5 * (prior + prior.T))
    top = float(vals.max()) if vals.size else 0.0
    free = vals > _RELATIVE_EPS * top if top > 0.0 else np.zeros(6, dtype=bool)
    if not free.any():
        return Posterior(zero, zero, 0, 0.0, np.zeros((6, 6)))
    L = vecs[:, free] * np.sqrt(vals[free])  # (6, k): x = L y, y ~ N(0, I) under the prior
    L_pinv = (vecs[:, free] / np.sqrt(vals[free])).T  # (k, 6)
    info_w = L.T @ (0.5 * (information + information.T)) @ L  # whitened information: prior / data variance
    mu, U = np.linalg.eigh(info_w)
    informed = mu >= INFORMED_RATIO
    if not informed.any():
        return Posterior(zero, zero, 0, 0.0, L @ L.T)
    a = U[:, informed].T @ (L_pinv @ x_data)  # the data's estimate along each informed direction [prior sigmas]
    b = mu[informed] / (1.0 + mu[informed]) * a
    seen = _seen(information, prior)
    x_informed = seen @ (L @ (U[:, informed] @ a))
    x_map = seen @ (L @ (U[:, informed] @ b))
    covariance = residual_covariance(L, U[:, informed], mu[informed], seen)
    strong = float(np.max(np.abs(a[mu[informed] >= STRONG_RATIO]), initial=0.0))
    return Posterior(x_map, x_informed, int(informed.sum()), float(np.max(np.abs(a))), covariance, strong)


def residual_covariance(L: FloatArray, U_in: FloatArray, mu_in: FloatArray, seen: FloatArray) -> FloatArray:
    """(6, 6) [m^2] covariance of the disagreement e left after the correction of :func:`posterior` is applied.

    In the prior's whitened coordinates (``e = L y``, ``y ~ N(0, I)``) the data read ``y + v`` with ``v`` of
    covariance ``U diag(1 / mu) U^T``; the correction is ``x = S L K (y + v)`` with ``K = U_in diag(mu / (1 + mu))
    U_in^T`` (the informed directions ``U_in`` (k, m), their ratios ``mu_in`` (m,)) and ``S`` the projector
    ``seen`` (6, 6). What is left, ``e - x = (L - S L K) y - S L K v``, has the covariance

        (L - S L K)(L - S L K)^T + S L U_in diag(mu / (1 + mu)^2) U_in^T L^T S^T

    (the prior itself along every direction not moved, the posterior's along those the data fixed)."""
    K = (U_in * (mu_in / (1.0 + mu_in))) @ U_in.T
    M = L - seen @ L @ K
    N = seen @ L @ U_in * np.sqrt(mu_in) / (1.0 + mu_in)
    return np.asarray(M @ M.T + N @ N.T)


def _seen(information: FloatArray, prior: FloatArray) -> FloatArray:
    """(6, 6) projector onto the directions of the registration's own coordinates that the data inform on their
    own: eigenvectors v of the information whose data variance ``1 / (v^T I v)`` is at most the prior's
    ``v^T P v`` over :data:`INFORMED_RATIO`. The prior couples a camera's turn with a shift of the overlap (the
    turn is about the camera, metres away), so a MAP move along a direction the data inform would carry a shift
    the data never saw (a tilt of a pipe's axis dragging a slide along it): that part is left as calibrated."""
    lam, V = np.linalg.eigh(0.5 * (information + information.T))
    prior_var = np.einsum("ij,jk,ki->i", V.T, prior, V)
    keep = lam * prior_var >= INFORMED_RATIO
    return np.asarray(V[:, keep] @ V[:, keep].T)
