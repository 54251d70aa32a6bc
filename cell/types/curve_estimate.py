"""What a locator answers for a curved seam: the located curve as samples in the robot frame ``R``, the two faces'
normals at each sample (for the torch's work angle), and a calibrated uncertainty across the seam at every sample
and along it at each end of an open curve. Metres."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray, readonly
from cell.types.seams import Reason, SeamStatus

__all__ = ["CurveEstimate", "CurveMetrics"]


def _empty() -> FloatArray:
    return np.zeros((0, 3))


@dataclass(frozen=True)
class CurveEstimate:
    """A locator's answer for one curved seam of the map (``WeldMap.curved``), in frame ``R``.

    p_RS : (n, 3) [m] samples along the located curve, start to end (a closed curve repeats no point).
    n_abutting_R, n_receiving_R : (n, 3) unit outward normals of the abutting and the receiving part's surface at
        each sample (the torch's work angle lies on their bisector).
    closed : the curve is a full loop (a tube all round a plate); it has no ends.
    sigma_m : (n,) the calibrated standard deviation across the seam at each sample [m].
    end_sigma_m : (start, end) the standard deviation of each end along the curve [m]; (0, 0) for a closed curve.
    reason, code, confidence, time_s : as in :class:`cell.types.seams.SeamEstimate`.
    """

    id: str
    status: SeamStatus
    reason: str = ""
    code: Reason | None = None
    p_RS: FloatArray = field(default_factory=_empty)
    n_abutting_R: FloatArray = field(default_factory=_empty)
    n_receiving_R: FloatArray = field(default_factory=_empty)
    closed: bool = False
    sigma_m: FloatArray = field(default_factory=lambda: np.zeros(0))
    end_sigma_m: tuple[float, float] = (math.inf, math.inf)
    confidence: float = 0.0
    time_s: float = 0.0

    def __post_init__(self) -> None:
        for name in ("p_RS", "n_abutting_R", "n_receiving_R", "sigma_m"):
            object.__setattr__(self, name, readonly(np.asarray(getattr(self, name), dtype=float)))
        n = len(self.p_RS)
        if self.status is SeamStatus.FOUND and (
            n < 2
            or self.p_RS.shape != (n, 3)
            or self.n_abutting_R.shape != (n, 3)
            or self.n_receiving_R.shape != (n, 3)
            or self.sigma_m.shape != (n,)
        ):
            raise ValueError(f"curved seam {self.id}: a found curve needs n >= 2 samples with normals and sigmas")

    @property
    def tangent_R(self) -> FloatArray:
        """(n, 3) unit tangents along the curve (central differences; a closed curve wraps round)."""
        p = np.asarray(self.p_RS)
        d = np.roll(p, -1, axis=0) - np.roll(p, 1, axis=0) if self.closed else np.gradient(p, axis=0)
        return np.asarray(d / np.linalg.norm(d, axis=1, keepdims=True))

    @property
    def length_m(self) -> float:
        """The located curve's length [m] (a closed curve's includes the last sample back to the first)."""
        p = np.asarray(self.p_RS)
        if self.closed and len(p):
            p = np.vstack([p, p[:1]])
        return float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum()) if len(p) > 1 else 0.0

    def points_at(self, s_m: npt.ArrayLike) -> FloatArray:
        """(k, 3) [m] the located curve's points ``s_m`` (k,) [m] along it from its first sample, in R: a closed
        curve's taken round its start, an open one's clipped to its ends (the planner's lengths along it)."""
        p = np.asarray(self.p_RS)
        if self.closed:
            p = np.vstack([p, p[:1]])
        s_k = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))])
        s = np.asarray(s_m, dtype=float).reshape(-1)
        s = np.mod(s, s_k[-1]) if self.closed else np.clip(s, 0.0, s_k[-1])
        return np.column_stack([np.interp(s, s_k, p[:, j]) for j in range(3)])

    @property
    def sigma_max_m(self) -> float:
        """The largest across-seam sigma over the curve [m] (inf when not found)."""
        return float(self.sigma_m.max()) if len(self.sigma_m) else math.inf


@dataclass(frozen=True)
class CurveMetrics:
    """A located curve against its true one (simulation): the located samples' distances to the true curve, their
    RMS and largest over its length [mm]; ``within_2sigma``: the share of the samples whose distance is at most twice
    their sigma; ``samples``: how many were measured."""

    rms_mm: float
    max_mm: float
    within_2sigma: float
    samples: int
