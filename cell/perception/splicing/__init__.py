"""Splicing the cameras' clouds into one in the robot frame: each camera registered onto the ones before it
(:mod:`.registration`), the estimate weighed against the camera's stated calibration (:mod:`.pose_prior`), what
that decides (a correction, nothing, or a camera fault: :mod:`.decision`) and the splice itself (:mod:`.splice`)."""

from cell.perception.splicing.decision import FAULT, REFUSALS, Registration, refusal
from cell.perception.splicing.pose_prior import PoseResidual, PoseUncertainty
from cell.perception.splicing.splice import Spliced, splice, splice_order, stacked

__all__ = [
    "FAULT",
    "REFUSALS",
    "PoseResidual",
    "PoseUncertainty",
    "Registration",
    "Spliced",
    "refusal",
    "splice",
    "splice_order",
    "stacked",
]
