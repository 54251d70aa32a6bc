"""Which seams a locator built for boxes can take: a seam whose joint holds a polyhedral part (a mesh) is refused
with reason code ``not_supported`` and a one-line reason, while every other seam goes on."""

from __future__ import annotations

from dataclasses import replace

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


def boxes_only(scene: SeamScene, keep_cache: tuple[str, ...] = ()) -> SeamScene:
    """The scene with only the map's box parts (the same scene when every part is a box); ``keep_cache``: the
    cache entries that do not depend on the parts and may be shared."""
    if all(p.is_box for p in scene.weldmap.parts):
        return scene
    weldmap = replace(scene.weldmap, parts=tuple(p for p in scene.weldmap.parts if p.is_box))
    return replace(scene, weldmap=weldmap, cache={k: v for k, v in scene.cache.items() if k in keep_cache})
