"""Simulated faults of the cell, numpy only: broken cameras, objects the map does not know, parts not built, applied
by the simulated cell from the scenario's ``faults:`` (docs/cell.md, "Faults the simulator plays").
Depth images are (H, W) [m] along the optical axis, 0 = invalid."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from cell.errors import ScenarioError
from cell.scenario import CameraFaultSpec, FaultsSpec
from cell.types import Box, Part

OCCLUDER_PREFIX = "occluder:"  # body names of occluders in the simulator: ``occluder:<name>``


def corrupt_depth(
    depth_m: npt.ArrayLike, fault: CameraFaultSpec, near_m: float, far_m: float, rng: np.random.Generator
) -> npt.NDArray[np.float32]:
    """What a faulty camera delivers instead of ``depth_m`` (H, W) [m]; float32 (H, W), 0 = invalid.

    near_m, far_m : the camera's working range [m] (random depths are drawn in it).
    rng : the fault's own random stream (deterministic for a given state).
    """
    z = np.asarray(depth_m, dtype=np.float64)
    if z.ndim != 2:
        raise ValueError(f"corrupt_depth: depth must be (H, W), got {z.shape}")
    if not 0.0 < near_m < far_m:
        raise ValueError(f"corrupt_depth: need 0 < near_m < far_m, got {near_m}, {far_m}")
    if fault.mode == "dead":
        out = np.zeros_like(z)
    elif fault.mode == "random":
        out = rng.uniform(near_m, far_m, size=z.shape)
    elif fault.mode == "constant":
        out = np.full_like(z, fault.depth_m)
    elif fault.mode == "salt":
        out = z.copy()
        hit = rng.random(z.shape) < fault.fraction
        out[hit] = rng.uniform(near_m, far_m, size=int(hit.sum()))
    else:  # pragma: no cover - the scenario's Literal admits no other mode
        raise ValueError(f"unknown camera fault mode {fault.mode!r}; valid: dead, random, constant, salt")
    return out.astype(np.float32)


def built_parts(parts_W: Sequence[Part], faults: FaultsSpec) -> tuple[Part, ...]:
    """The parts really put on the table: ``parts_W`` without ``faults.missing_parts``.

    ScenarioError when a missing part is not a part of the map (the names are the map's, upper case).
    """
    names = [p.name for p in parts_W]
    unknown = sorted(set(faults.missing_parts) - set(names))
    if unknown:
        raise ScenarioError(
            f"faults.missing_parts names unknown part(s) {', '.join(unknown)}; parts of the map: {', '.join(names)}"
        )
    return tuple(p for p in parts_W if p.name not in faults.missing_parts)


def occluder_boxes(faults: FaultsSpec) -> tuple[tuple[str, Box], ...]:
    """(body name, box in W) of every occluder, named ``occluder:<name>``."""
    return tuple(
        (OCCLUDER_PREFIX + name, Box(spec.X_WO, np.asarray(spec.size_m, dtype=float)))
        for name, spec in faults.occluders.items()
    )
