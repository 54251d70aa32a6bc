"""Depth images to the clouds the seam locators read, in one call: the perception stage of the pipeline.

deproject + crop + robot frame (section 3.2) -> splice (3.3) -> Z passthrough and outlier removal (3.4) ->
voxel grid (3.4). A camera whose data cannot be trusted is *lost*, with the reason, before it can poison the
splice (:mod:`cell.perception.camera_health`): no valid pixel (dead, blinded), an implausible image (one value
everywhere, random depths, heavy interference), no point inside the workspace, or a cloud that agrees with no
other camera while the others agree (knocked out of calibration). The others go on without it; only when no
usable camera remains is it a :class:`SensorError`.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from cell.errors import SensorError
from cell.geometry import FloatArray, invert
from cell.perception.camera_health import HealthOptions, disagreeing_cameras, image_health
from cell.perception.deproject import clouds_in_robot_frame
from cell.perception.preprocess import downsample, preprocess
from cell.perception.splice import Spliced, splice
from cell.scenario import PerceptionSpec
from cell.types import Cloud, DepthImage, VoxelTable
from cell.voxels import voxel_order


@dataclass(frozen=True)
class Perceived:
    """What perception hands on, all in the robot frame R.

    dense : spliced, Z-passthrough and outlier filtered, full resolution (per-point camera index).
    downsampled : ``dense`` on the voxel grid of ``spec.voxel_m`` (what the paper's locator reads).
    clouds : camera name -> its own cropped cloud before splicing (empty for a lost camera).
    spliced : the splice result (unfiltered dense cloud and the ICP diagnostics).
    lost : cameras left out (their data cannot be trusted), in capture order; ``lost_reasons`` says why.
    lost_reasons : camera name -> one-line reason it was left out.
    timings : step name -> wall time [s] (``clouds``, ``splice``, ``preprocess``: both clouds' filters, side by
        side; ``downsample``: both voxel grids, side by side).
    registered : every camera registered, Z-passthrough and outlier filtered, *not* merged (per-point camera
        index), in voxel order: what a locator that weighs each camera by its own noise reads.
    registered_voxels : where ``registered``'s voxels (``spec.voxel_m``) lie in it (what such a locator's tube
        queries read).
    origins_R : camera name -> (3,) its optical centre in R as calibrated (how far a seam is from it).
    """

    dense: Cloud
    downsampled: Cloud
    clouds: dict[str, Cloud]
    spliced: Spliced
    lost: tuple[str, ...] = ()
    timings: dict[str, float] = field(default_factory=dict)
    lost_reasons: dict[str, str] = field(default_factory=dict)

    def lost_described(self) -> tuple[str, ...]:
        """``"name: reason"`` of every lost camera (for reports)."""
        return tuple(f"{n}: {self.lost_reasons.get(n, 'lost')}" for n in self.lost)

    registered: Cloud = field(default_factory=lambda: Cloud(np.zeros((0, 3)), "R"))
    registered_voxels: VoxelTable | None = None
    origins_R: dict[str, FloatArray] = field(default_factory=dict)

    def splice_corrections(self) -> dict[str, dict[str, Any]]:
        """Per registered camera, what the splice did to its calibration (for reports): ``applied`` (bool),
        ``applied_mm`` and ``estimated_mm`` (RMS displacement of the overlap by the applied / the estimated
        correction), ``directions`` (kept / constrained of the six), ``refused`` (``""`` or the test that refused
        it, :data:`cell.perception.splice.REFUSALS`), onto which cameras (``target``)."""
        return {
            r.source: {
                "target": list(r.target),
                "applied": r.accepted,
                "applied_mm": round(r.applied_shift_m * 1e3, 4),
                "estimated_mm": round(r.shift_m * 1e3, 4),
                "directions": f"{r.constrained}/{r.directions_constrained}",
                "refused": r.refused,
            }
            for r in self.spliced.registrations
        }


def perceive(
    images: Mapping[str, DepthImage], X_WR: FloatArray, spec: PerceptionSpec, health: HealthOptions | None = None
) -> Perceived:
    """Run the perception stage on one depth image per camera (see the module docstring).

    X_WR : (4, 4) pose of the robot base R in the world. health : thresholds of the camera checks (defaults
    when None). Raises :class:`SensorError` when there is no image, when no usable camera remains (naming
    each camera and why it was left out), or when filtering leaves no point.
    """
    if not images:
        raise SensorError("no depth images to perceive from (no camera delivered one)")
    timings: dict[str, float] = {}
    t = time.perf_counter()
    why: dict[str, str] = {}
    for name, image in images.items():
        verdict = image_health(image, health)
        if not verdict.ok:
            why[name] = verdict.reason
    clouds = clouds_in_robot_frame(images, X_WR, spec.workspace)
    for name, cloud in clouds.items():
        if name in why:
            clouds[name] = cloud.select(np.zeros(len(cloud), dtype=bool))
        elif len(cloud) == 0:
            ws = spec.workspace
            why[name] = f"no point inside the workspace {ws.min_m}..{ws.max_m} m (looking elsewhere, or covered)"
    why.update(disagreeing_cameras({n: c for n, c in clouds.items() if n not in why}, health))
    for name in why:
        clouds[name] = clouds[name].select(np.zeros(len(clouds[name]), dtype=bool))
    lost = tuple(name for name in clouds if name in why)
    timings["clouds"] = time.perf_counter() - t
    if len(lost) == len(clouds):
        raise SensorError("no usable camera: " + "; ".join(f"{n}: {why[n]}" for n in lost), lost=why)
    t = time.perf_counter()
    spliced = splice({n: c for n, c in clouds.items() if n not in lost}, images, X_WR, spec)
    timings["splice"] = time.perf_counter() - t
    # The merged cloud and the registered one are filtered and gridded apart, each on its own core: numpy's sorts
    # and arithmetic and scipy's searches let go of the interpreter lock, and each result is what it would be alone.
    with ThreadPoolExecutor(max_workers=1) as beside:
        t = time.perf_counter()
        filtered = beside.submit(preprocess, spliced.registered, spec.workspace, X_WR, spec)
        dense = preprocess(spliced.dense, spec.workspace, X_WR, spec)
        registered = filtered.result()
        timings["preprocess"] = time.perf_counter() - t
        if len(dense) == 0:
            raise SensorError(
                f"Z passthrough and outlier removal left no point of the {len(spliced.dense)} spliced ones"
            )
        t = time.perf_counter()
        ordered = beside.submit(voxel_order, registered, spec.voxel_m)
        downsampled = downsample(dense, spec.voxel_m)
        registered, registered_voxels = ordered.result()
        timings["downsample"] = time.perf_counter() - t
    X_RW = invert(np.asarray(X_WR, dtype=float))
    origins_R = {name: (X_RW @ np.asarray(image.X_WC, dtype=float))[:3, 3] for name, image in images.items()}
    return Perceived(
        dense,
        downsampled,
        clouds,
        spliced,
        lost,
        timings,
        {n: why[n] for n in lost},
        registered,
        registered_voxels,
        origins_R,
    )
