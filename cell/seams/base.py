"""What every seam locator takes and returns: one signature for the paper's method, RANSAC and ours.

A locator is a value-in, value-out stage: it reads a :class:`SeamScene` (clouds and the aligned map, all in
the robot frame R) and one seam with its :class:`Joint`, and returns a :class:`~cell.types.SeamEstimate`. It never
calls the simulator and never reads globals; anything stochastic takes the ``rng`` it is given.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import replace
from typing import Protocol, runtime_checkable

import numpy as np

from cell.types import MapSeam, Reason, SeamEstimate, SeamStatus
from cell.types.seams import SeamScene


class SeamLocator(Protocol):
    """A seam finder. ``name`` is what ``--method`` selects; ``reads_voxel_cloud`` says whether it reads the
    scene's voxel cloud (``SeamScene.cloud``: perception's merge, made on first read, before the locator is timed)."""

    name: str
    reads_voxel_cloud: bool

    def locate(self, scene: SeamScene, seam: MapSeam, rng: np.random.Generator) -> SeamEstimate:
        """Find ``seam`` (given in R, from the aligned map) in ``scene``; time is filled in by the caller."""
        ...


@runtime_checkable
class BatchSeamLocator(SeamLocator, Protocol):
    """A seam finder that finds several seams of a scene together (faster than one by one, same answers)."""

    def locate_many(self, scene: SeamScene, seams: Sequence[MapSeam], rng: np.random.Generator) -> list[SeamEstimate]:
        """:meth:`SeamLocator.locate` for each of ``seams``, in order."""
        ...


def locate_all(locator: SeamLocator, scene: SeamScene, rng: np.random.Generator) -> tuple[SeamEstimate, ...]:
    """Every seam of ``scene``'s map by ``locator``, in the map's order: a seam against the table is NOT_VISIBLE
    (``underside``), never searched; each found one carries its time (a batch's time shared equally), perception's
    merge made before the clock starts."""
    from cell.seams.visibility import visibility

    hidden: dict[str, SeamEstimate] = {}
    for seam in scene.weldmap.seams:
        visible, reason = visibility(scene.weldmap, scene.joints[seam.id], scene.table_z)
        if not visible:
            hidden[seam.id] = SeamEstimate(seam.id, SeamStatus.NOT_VISIBLE, reason, code=Reason.UNDERSIDE)
    seams = [seam for seam in scene.weldmap.seams if seam.id not in hidden]
    timed: dict[str, SeamEstimate] = {}
    if locator.reads_voxel_cloud and seams:
        _ = scene.cloud  # perception's work (the merge), made before the locator's clock starts
    if isinstance(locator, BatchSeamLocator) and seams:
        t = time.perf_counter()
        found = locator.locate_many(scene, seams, rng)
        dt = (time.perf_counter() - t) / len(seams)
        timed = {est.id: replace(est, time_s=dt) for est in found}
    else:
        for seam in seams:
            t = time.perf_counter()
            est = locator.locate(scene, seam, rng)
            timed[seam.id] = replace(est, time_s=time.perf_counter() - t)
    return tuple(hidden[seam.id] if seam.id in hidden else timed[seam.id] for seam in scene.weldmap.seams)
