"""Which seams a locator built for boxes can take (the paper's method): a seam whose joint holds a polyhedral part
(a mesh) is refused with reason code ``not_supported`` and a one-line reason, while every other seam goes on."""

from __future__ import annotations

from cell.types import MapSeam, Reason, SeamEstimate, SeamScene, SeamStatus


def mesh_part(scene: SeamScene, seam: MapSeam) -> str | None:
    """The name of the first part of ``seam``'s joint that is not a box (None: both are boxes, or no joint)."""
    joint = scene.joints.get(seam.id)
    if joint is None:
        return None
    for name in (joint.abutting, joint.receiving):
        if not scene.weldmap.part(name).is_box:
            return name
    return None


def not_supported(seam: MapSeam, method: str, part: str, why: str) -> SeamEstimate:
    """The refusal of one seam: ``<method>: part <part> is a mesh; <why>``."""
    return SeamEstimate(
        seam.id, SeamStatus.NOT_FOUND, f"{method}: part {part} is a mesh; {why}", code=Reason.NOT_SUPPORTED
    )
