"""Why a seam's candidate failed while planning (:class:`SeamFailure`), and the words the report prints for it.

A failure carries its code (:class:`~cell.types.plan.PlanReason`), where it happened in words, the failing
point p_R (3,) in the robot base frame R [m] and its progress [m] along approach + seam + depart, by which the
planner keeps the most telling failure of all the candidates it tried (:func:`better`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from cell.errors import IKError
from cell.geometry import FloatArray
from cell.motion.ik import IKSolveError
from cell.types.plan import PlanReason

# The word a reason's text starts with, per code (the report's text is "<word>: <where>").
_WORD = {
    PlanReason.BEYOND_REACH: "unreachable",
    PlanReason.IK_FAILED: "unreachable",
    PlanReason.FLIP: "flip",
    PlanReason.SINGULAR: "singular",
    PlanReason.COLLISION: "collision",
    PlanReason.TRANSFER_COLLISION: "collision",
    PlanReason.TIMING: "timing",
    PlanReason.NO_PROCEDURE: "no procedure",
    PlanReason.HOSE_WINDOW: "hose window",
    PlanReason.ENTERS_BODY: "enters a body",
}


def reason_text(code: PlanReason, detail: str) -> str:
    """The one-line reason a report prints for a seam that failed with ``code``: "<word>: <detail>"."""
    return f"{_WORD[code]}: {detail}"


@dataclass(frozen=True)
class SeamFailure:
    """One candidate's failure: code, where (words), p_R (3,) [m] in R, progress [m] (how far along approach +
    seam + depart the candidate got; negative: not even tried); obstacle: the body the torch hit where it was
    placed at a weld end ("" when the failure is not that)."""

    code: PlanReason
    where: str
    p_R: FloatArray
    progress: float
    obstacle: str = ""

    def reason(self) -> str:
        return reason_text(self.code, self.where)


class LineError(Exception):
    """A straight line could not be solved (IK, or a joint flip); carries the :class:`SeamFailure`."""

    def __init__(self, failure: SeamFailure) -> None:
        super().__init__(failure.reason())
        self.failure = failure


def mm(p: npt.ArrayLike) -> list[float]:
    """A point [m] as a list of millimetres rounded to 0.1 mm, for messages."""
    return [float(v) for v in np.round(np.asarray(p, dtype=float) * 1000.0, 1)]


def where_on_path(s: float, length: float) -> str:
    """Words for path position s [m] (negative: on the approach; beyond ``length`` [m]: on the depart)."""
    if s < 0.0:
        return f"{-s * 1000:.1f} mm before the seam start (approach)"
    if s > length + 1e-9:
        return f"{(s - length) * 1000:.1f} mm after the seam end (depart)"
    return f"{s * 1000:.1f} mm along the seam"


def unreachable(exc: IKError, X: FloatArray, s: float, progress: float, what: str = "seam") -> SeamFailure:
    """The failure for IK that gave up at pose X (4, 4), s [m] along the ``what`` (seam, approach, depart, lift)."""
    where = f"IK did not converge at {s * 1000:.1f} mm along the {what}"
    beyond = isinstance(exc, IKSolveError) and exc.beyond_reach
    if beyond:
        where += " (beyond the arm's reach)"
    code = PlanReason.BEYOND_REACH if beyond else PlanReason.IK_FAILED
    return SeamFailure(code, where, X[:3, 3].copy(), progress)


def better(a: SeamFailure | None, b: SeamFailure) -> SeamFailure:
    """The failure that got further along (ties: the earlier one, i.e. the nearer to nominal angles)."""
    return b if a is None or b.progress > a.progress + 1e-9 else a
