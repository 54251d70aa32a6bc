"""What every seam locator takes and returns: one signature for the paper's method, RANSAC and ours.

A locator is a value-in, value-out stage: it reads a :class:`SeamScene` (clouds and the aligned map, all in
the robot frame R) and one seam with its :class:`Joint`, and returns a :class:`~cell.types.SeamEstimate`. It never
calls the simulator and never reads globals; anything stochastic takes the ``rng`` it is given.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol, runtime_checkable

import numpy as np

from cell.types import MapSeam, SeamEstimate
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
