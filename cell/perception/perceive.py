"""Depth images to the clouds the seam locators read, in one call: the perception stage of the pipeline.

deproject + crop + robot frame (section 3.2) -> splice (3.3) -> Z passthrough and outlier removal (3.4) ->
voxel grid (3.4). A camera whose image gives no point inside the workspace is *lost*: the others go on without
it, and only when every camera is lost is it a :class:`SensorError`.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from dataclasses import dataclass, field

from cell.errors import SensorError
from cell.geometry import FloatArray
from cell.perception.deproject import clouds_in_robot_frame
from cell.perception.preprocess import downsample, preprocess
from cell.perception.splice import Spliced, splice
from cell.scenario import PerceptionSpec
from cell.types import Cloud, DepthImage


@dataclass(frozen=True)
class Perceived:
    """What perception hands on, all in the robot frame R.

    dense : spliced, Z-passthrough and outlier filtered, full resolution (per-point camera index).
    downsampled : ``dense`` on the voxel grid of ``spec.voxel_m`` (what the paper's locator reads).
    clouds : camera name -> its own cropped cloud before splicing (empty for a lost camera).
    spliced : the splice result (unfiltered dense cloud and the ICP diagnostics).
    lost : cameras whose image gave no point inside the workspace.
    timings : step name -> wall time [s] (``clouds``, ``splice``, ``preprocess``, ``downsample``).
    """

    dense: Cloud
    downsampled: Cloud
    clouds: dict[str, Cloud]
    spliced: Spliced
    lost: tuple[str, ...] = ()
    timings: dict[str, float] = field(default_factory=dict)


def perceive(images: Mapping[str, DepthImage], X_WR: FloatArray, spec: PerceptionSpec) -> Perceived:
    """Run the perception stage on one depth image per camera (see the module docstring).

    X_WR : (4, 4) pose of the robot base R in the world. Raises :class:`SensorError` when there is no image or
    no camera sees anything inside ``spec.workspace``, or when filtering leaves no point.
    """
    if not images:
        raise SensorError("no depth images to perceive from (no camera delivered one)")
    timings: dict[str, float] = {}
    t = time.perf_counter()
    clouds = clouds_in_robot_frame(images, X_WR, spec.workspace)
    timings["clouds"] = time.perf_counter() - t
    lost = tuple(name for name, cloud in clouds.items() if len(cloud) == 0)
    if len(lost) == len(clouds):
        ws = spec.workspace
        raise SensorError(
            f"no camera sees a point inside the workspace {ws.min_m}..{ws.max_m} m (lost: {', '.join(lost)})"
        )
    t = time.perf_counter()
    spliced = splice({n: c for n, c in clouds.items() if n not in lost}, images, X_WR, spec)
    timings["splice"] = time.perf_counter() - t
    t = time.perf_counter()
    dense = preprocess(spliced.dense, spec.workspace, X_WR, spec)
    timings["preprocess"] = time.perf_counter() - t
    if len(dense) == 0:
        raise SensorError(f"Z passthrough and outlier removal left no point of the {len(spliced.dense)} spliced ones")
    t = time.perf_counter()
    downsampled = downsample(dense, spec.voxel_m)
    timings["downsample"] = time.perf_counter() - t
    return Perceived(dense, downsampled, clouds, spliced, lost, timings)
