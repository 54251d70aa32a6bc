"""What one splice registration decides: the correction applied, or why not, or a camera fault (:func:`refusal`, in
the order of its tests), and the :class:`Registration` record the report and the seams' calibration term read
(docs/perception.md, the splice)."""

from __future__ import annotations

from dataclasses import dataclass

from cell.geometry import FloatArray, readonly
from cell.perception.splicing.pose_prior import FAULT_SIGMAS, PoseResidual
from cell.perception.splicing.registration import MIN_OVERLAP, Estimate

MIN_SHIFT_M = 0.0001  # [m] a MAP correction moving the overlap by less than this (RMS) is not applied
MIN_SHIFT_NOISE = 0.5  # ... nor by less than this many times the overlap's noise (what its biases reach)
MIN_MISFIT_DROP = 0.10  # ... nor one that lowers the patch misfit by less than this fraction (nor is it a fault)
FAULT_MISFIT_DROP = 0.80  # a partly informed overlap shows a fault only if the move explains this much of the misfit
REFUSALS = (
    "calibration_exact",
    "no_overlap",
    "not_informed",
    "partly_informed",
    "too_small",
    "no_misfit_gain",
    "beyond_prior",
)
FAULT = "beyond_prior"  # the refusal that makes the camera a fault (dropped), not merely left as calibrated


@dataclass(frozen=True)
class Registration:
    """One splice registration: the cloud of ``source`` onto the registered cloud of the ``target`` cameras.

    X_corr : (4, 4) correction applied to the source cloud in R (p_R' = X_corr p_R): the MAP estimate when
        accepted, else the identity.
    X_estimated : (4, 4) the data's estimate along the informed directions (identity along the others).
    overlap : source probe points with a target point within reach (``voxel_m``) at the calibrated extrinsics
        (0: not registered).
    informed : directions (of six) where the overlap's information outweighs the prior.
    shift_m, map_shift_m : RMS displacement of the overlap by ``X_estimated`` / by the MAP estimate [m].
    misfit_before_m, misfit_m : RMS over patches of the mean point-to-plane residual [m], at the calibrated
        extrinsics and after the MAP estimate.
    accepted : whether the correction was applied.
    noise_m : robust standard deviation of the point-to-plane residuals in the overlap [m] (calibrated).
    disagreement_sigmas : the data's largest disagreement with the prior along an informed direction, in prior
        sigmas (beyond :data:`cell.perception.splicing.pose_prior.FAULT_SIGMAS`: a camera fault).
    refused : ``""`` when applied, else why not (one of :data:`REFUSALS`; :data:`FAULT` drops the camera).
    residual : what is left unknown of the camera's pose relative to its targets once the correction is applied
        (the posterior; None when nothing was estimated).
    """

    source: str
    target: tuple[str, ...]
    X_corr: FloatArray
    X_estimated: FloatArray
    overlap: int
    informed: int
    shift_m: float
    map_shift_m: float
    misfit_before_m: float
    misfit_m: float
    accepted: bool
    noise_m: float = 0.0
    disagreement_sigmas: float = 0.0
    refused: str = ""
    residual: PoseResidual | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "X_corr", readonly(self.X_corr))
        object.__setattr__(self, "X_estimated", readonly(self.X_estimated))

    @property
    def applied_shift_m(self) -> float:
        """RMS displacement of the overlap by the applied correction [m] (0 when refused)."""
        return self.map_shift_m if self.accepted else 0.0

    @property
    def fault(self) -> bool:
        """The camera disagrees with its targets beyond its stated calibration (dropped from the splice)."""
        return self.refused == FAULT


def refusal(est: Estimate) -> str:
    """``""`` if a registration's estimate (:func:`cell.perception.splicing.registration.register`) may be applied, else
    why not (one of :data:`REFUSALS`, in this order): too few points overlap, no direction is informed, not all
    six are (the overlap does not fix the whole pose: no correction, and a fault only if the move also lowers the
    patch misfit by :data:`FAULT_MISFIT_DROP`, or by :data:`MIN_MISFIT_DROP` with the disagreement along a
    strongly informed direction), the MAP correction
    moves the overlap by less than :data:`MIN_SHIFT_M` or :data:`MIN_SHIFT_NOISE` times its noise, or lowers
    the patch misfit by less than :data:`MIN_MISFIT_DROP` (it explains nothing), or the data disagree with the
    prior beyond :data:`cell.perception.splicing.pose_prior.FAULT_SIGMAS` (a fault)."""
    if est.overlap < MIN_OVERLAP:
        return "no_overlap"
    if est.informed == 0:
        return "not_informed"
    if est.informed < 6:
        gross = est.misfit_m <= (1.0 - FAULT_MISFIT_DROP) * est.misfit_before_m
        gain = est.misfit_m <= (1.0 - MIN_MISFIT_DROP) * est.misfit_before_m
        strong = est.strong_sigmas > FAULT_SIGMAS and gain
        return FAULT if (est.disagreement_sigmas > FAULT_SIGMAS and gross) or strong else "partly_informed"
    if est.map_shift_m < max(MIN_SHIFT_M, MIN_SHIFT_NOISE * est.noise_m):
        return "too_small"
    if not est.misfit_m <= (1.0 - MIN_MISFIT_DROP) * est.misfit_before_m:
        return "no_misfit_gain"
    if est.disagreement_sigmas > FAULT_SIGMAS:
        return FAULT
    return ""
