"""What every seam locator takes and returns: one signature for the paper's method, RANSAC and ours.

A locator is a value-in, value-out stage: it reads a :class:`SeamScene` (clouds and the aligned map, all in
the robot frame R) and one seam with its :class:`Joint`, and returns a :class:`~cell.types.SeamEstimate`. It never
calls the simulator and never reads globals; anything stochastic takes the ``rng`` it is given.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Protocol, runtime_checkable

import numpy as np

from cell.types import Cloud, MapSeam, SeamEstimate, WeldMap
from cell.voxels import VoxelTable


@dataclass(frozen=True)
class Joint:
    """How a seam of the map is made: the edge of one part's face meeting another part's face.

    abutting : name of the part whose end meets the other (part A); the seam runs along an edge of its end face.
    receiving : name of the part it meets (part B); the seam lies on one of B's faces.
    face_abutting : A's box face (``"+x"``...``"-z"``) that meets B at the seam (for a T fillet, the face the torch
        sees on A, e.g. its top ``"+z"``).
    face_receiving : B's box face the seam lies on (its outward normal points towards A).
    end_face : A's face that faces B across the gap (parallel to ``face_receiving``).
    """

    seam_id: str
    abutting: str
    receiving: str
    face_abutting: str
    face_receiving: str
    end_face: str


@dataclass(frozen=True)
class SeamScene:
    """Everything a locator may look at, all in the robot frame R.

    cloud : the spliced, filtered, voxel-downsampled cloud (what the paper's method uses).
    dense : every camera's registered, filtered points, not merged and not downsampled (full resolution, per-point
        camera index): what our locator and the map alignment read.
    weldmap : the welding map aligned to the cloud (frame ``"R"``).
    joints : seam id -> :class:`Joint`.
    table_z : height of the table top in R [m] (seams against it cannot be seen).
    dense_voxels : where the voxels of ``dense`` lie in it, when perception handed it on in voxel order (None:
        a locator that needs it orders ``dense`` itself).
    cache : per-scene scratch space a locator may fill once and reuse for every seam (e.g. a KD-tree);
        it is the one mutable member, and only ever holds values derived from the fields above.
    """

    cloud: Cloud
    dense: Cloud
    weldmap: WeldMap
    joints: Mapping[str, Joint]
    table_z: float
    dense_voxels: VoxelTable | None = None
    cache: dict[str, Any] = field(default_factory=dict, compare=False, repr=False)


class SeamLocator(Protocol):
    """A seam finder. ``name`` is what ``--method`` selects."""

    name: str

    def locate(self, scene: SeamScene, seam: MapSeam, rng: np.random.Generator) -> SeamEstimate:
        """Find ``seam`` (given in R, from the aligned map) in ``scene``; time is filled in by the caller."""
        ...


@runtime_checkable
class BatchSeamLocator(SeamLocator, Protocol):
    """A seam finder that finds several seams of a scene together (faster than one by one, same answers)."""

    def locate_many(self, scene: SeamScene, seams: Sequence[MapSeam], rng: np.random.Generator) -> list[SeamEstimate]:
        """:meth:`SeamLocator.locate` for each of ``seams``, in order."""
        ...
