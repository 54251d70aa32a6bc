"""Depth images to the clouds the seam locators read, in one call: deproject, crop and robot frame (paper section 3.2),
splice (3.3), Z passthrough and outlier removal, voxel grid (3.4). A camera that cannot be trusted is lost with its
reason before it poisons the splice, and the others go on; no usable camera left is a :class:`SensorError`."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Mapping
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any, Generic, NamedTuple, TypeVar

import numpy as np

from cell.errors import SensorError
from cell.geometry import FloatArray, invert
from cell.perception.camera_health import HealthOptions, disagreeing_cameras, image_health
from cell.perception.deproject import clouds_in_robot_frame
from cell.perception.preprocess import downsample, preprocess
from cell.perception.splicing.pose_prior import PoseUncertainty
from cell.perception.splicing.splice import Spliced, splice, stacked
from cell.perception.table_check import SensorCheck
from cell.scenario import PerceptionSpec
from cell.types import Cloud, DepthImage, VoxelTable
from cell.voxels import voxel_order

T = TypeVar("T")


@dataclass(frozen=True)
class Perceived:
    """What perception hands on, all in the robot frame R.

    clouds : camera name -> its own cropped cloud before splicing (empty for a lost camera).
    spliced : the splice result (the registered cloud, the ICP diagnostics, the merge when asked for).
    lost : cameras left out (their data cannot be trusted), in capture order; ``lost_reasons`` says why.
    lost_reasons : camera name -> one-line reason it was left out.
    timings : step name -> wall time [s] (``clouds``, ``splice``, ``preprocess``: the registered cloud's filters,
        ``downsample``: its voxel order; ``merge``: the paper's cloud, once it has been asked for).
    registered : every camera registered, Z-passthrough and outlier filtered, *not* merged (per-point camera
        index), in voxel order: what the map alignment and a locator that weighs each camera by its own noise read.
    registered_voxels : where ``registered``'s voxels (``spec.voxel_m``) lie in it (what such a locator's tube
        queries read).
    origins_R : camera name -> (3,) its optical centre in R as calibrated (how far a seam is from it).
    sensor_checks : camera name -> its depth scale and focal length checked on the table
        (:mod:`cell.perception.table_check`; a camera it flags is lost unless already lost for another reason).
    filter_merged : the paper's cloud made from ``spliced.dense`` (filtered as ``registered``, then on the voxel
        grid): run once, on the first read of ``dense`` or ``downsampled``.
    """

    clouds: dict[str, Cloud]
    spliced: Spliced
    registered: Cloud
    filter_merged: Callable[[], tuple[Cloud, Cloud]] = field(compare=False, repr=False)
    registered_voxels: VoxelTable | None = None
    lost: tuple[str, ...] = ()
    timings: dict[str, float] = field(default_factory=dict)
    lost_reasons: dict[str, str] = field(default_factory=dict)
    origins_R: dict[str, FloatArray] = field(default_factory=dict)
    sensor_checks: dict[str, SensorCheck] = field(default_factory=dict)

    @cached_property
    def _merged(self) -> tuple[Cloud, Cloud]:
        t = time.perf_counter()
        out = self.filter_merged()
        self.timings["merge"] = time.perf_counter() - t
        return out

    @property
    def dense(self) -> Cloud:
        """The paper's cloud: spliced (the prioritised merge), Z-passthrough and outlier filtered, full resolution
        (per-point camera index)."""
        return self._merged[0]

    @property
    def downsampled(self) -> Cloud:
        """``dense`` on the voxel grid of ``spec.voxel_m`` (what the paper's locator reads)."""
        return self._merged[1]

    def lost_described(self) -> tuple[str, ...]:
        """``"name: reason"`` of every lost camera (for reports)."""
        return tuple(f"{n}: {self.lost_reasons.get(n, 'lost')}" for n in self.lost)

    def splice_corrections(self) -> dict[str, dict[str, Any]]:
        """Per registered camera, what the splice did to its calibration (for reports): ``applied`` (bool),
        ``applied_mm`` and ``estimated_mm`` (RMS displacement of the overlap by the applied MAP correction / by
        the data's estimate along the informed directions), ``directions`` (informed of the six),
        ``disagreement_sigmas`` (the data against the stated calibration, in its sigmas), ``refused`` (``""`` or
        why not, :data:`cell.perception.splicing.REFUSALS`; ``beyond_prior``: the camera was dropped), onto which
        cameras (``target``)."""
        return {
            r.source: {
                "target": list(r.target),
                "applied": r.accepted,
                "applied_mm": round(r.applied_shift_m * 1e3, 4),
                "estimated_mm": round(r.shift_m * 1e3, 4),
                "directions": f"{r.informed}/6",
                "disagreement_sigmas": round(r.disagreement_sigmas, 2),
                "refused": r.refused,
            }
            for r in self.spliced.registrations
        }


def perceive(
    images: Mapping[str, DepthImage],
    X_WR: FloatArray,
    spec: PerceptionSpec,
    health: HealthOptions | None = None,
    priors: Mapping[str, PoseUncertainty] | None = None,
) -> Perceived:
    """Run the perception stage on one depth image per camera (see the module docstring).

    X_WR : (4, 4) pose of the robot base R in the world. health : thresholds of the camera checks (defaults
    when None). priors : camera name -> its stated calibration (the splice's prior; a camera not named is stated
    exact). Raises :class:`SensorError` when there is no image, when no usable camera remains (naming
    each camera and why it was left out), or when filtering leaves no point.
    """
    return perceive_then(images, X_WR, spec, health, lambda cloud, proceed: None, priors).perceived


def perceive_then(
    images: Mapping[str, DepthImage],
    X_WR: FloatArray,
    spec: PerceptionSpec,
    health: HealthOptions | None,
    then: Callable[[Cloud, Callable[[], None]], T],
    priors: Mapping[str, PoseUncertainty] | None = None,
    checks: Mapping[str, SensorCheck] | None = None,
) -> PerceivedThen[T]:
    """:func:`perceive`, and ``then`` of its registered cloud (the caller's next stage: the map alignment).

    The registered cloud is the calibrated cloud of the healthy cameras, point for point, unless a camera
    disagrees with the others or the splice applies a correction or drops a camera (in a calibrated cell none of
    these happens). So its
    filters and ``then`` start on that guess, on the other core, beside the agreement check and the splice's
    registrations, and are kept when the guess holds; else they run again on the registered cloud (an answer
    never depends on the speculation, only the wall time does). ``then(cloud, proceed)`` must not depend on
    anything but its cloud; it calls ``proceed()`` between its steps, which stops a moot speculation (by raising).
    priors : as :func:`perceive`. checks : each camera's sensor check; a flagged camera is lost with its reason
    (after the agreement check, whose reason comes first).
    """
    if not images:
        raise SensorError("no depth images to perceive from (no camera delivered one)")
    timings: dict[str, float] = {}
    t0 = t = time.perf_counter()
    clouds, why = _camera_clouds(images, X_WR, spec, health)
    if len(why) == len(clouds):
        raise SensorError("no usable camera: " + "; ".join(f"{n}: {why[n]}" for n in clouds), lost=why)
    # The guess: no camera disagrees with the others (the check below runs beside the work that starts on it).
    guessed = tuple(n for n in clouds if n not in why)
    guess = stacked({n: clouds[n] for n in guessed}, images)
    moot = threading.Event()  # set when the guess cannot be the registered cloud

    def onward(cloud: Cloud) -> tuple[Cloud, VoxelTable, T, dict[str, float], dict[str, float]]:
        """The registered cloud's filters and voxel order, then ``then`` (unless the guess turned out moot)."""
        timings: dict[str, float] = {}
        stamps: dict[str, float] = {}
        t = time.perf_counter()
        filtered = preprocess(cloud, spec.workspace, X_WR, spec)
        timings["preprocess"] = time.perf_counter() - t
        if len(filtered) == 0:
            raise SensorError(f"Z passthrough and outlier removal left no point of the {len(cloud)} registered ones")
        t = time.perf_counter()
        ordered, voxels = voxel_order(filtered, spec.voxel_m)
        timings["downsample"] = time.perf_counter() - t
        stamps["filtered"] = time.perf_counter()

        def proceed() -> None:
            if cloud is guess and moot.is_set():
                raise _SupersededError

        proceed()
        t = time.perf_counter()
        answer = then(ordered, proceed)
        stamps["answered"] = time.perf_counter()
        stamps["then_s"] = stamps["answered"] - t
        return ordered, voxels, answer, timings, stamps

    beside = ThreadPoolExecutor(max_workers=1)
    try:
        ahead = beside.submit(onward, guess)
        why.update(disagreeing_cameras({n: c for n, c in clouds.items() if n not in why}, health, (images, X_WR)))
        for name, check in (checks or {}).items():
            if check.flags and name in clouds:
                why.setdefault(name, check.reason())
        for name in why:
            clouds[name] = clouds[name].select(np.zeros(len(clouds[name]), dtype=bool))
        lost = tuple(name for name in clouds if name in why)
        timings["clouds"] = time.perf_counter() - t
        if len(lost) == len(clouds):
            raise SensorError("no usable camera: " + "; ".join(f"{n}: {why[n]}" for n in lost), lost=why)
        usable = {n: c for n, c in clouds.items() if n not in lost}
        calibrated = guess if set(usable) == set(guessed) else stacked(usable, images)
        if calibrated is not guess:
            moot.set()
        t = time.perf_counter()
        spliced = splice(usable, images, X_WR, spec, calibrated, lambda name: moot.set(), priors)
        timings["splice"] = time.perf_counter() - t
        why.update(spliced.faults)  # data beyond the camera's stated calibration: dropped as a disagreeing camera
        for name in spliced.faults:
            clouds[name] = clouds[name].select(np.zeros(len(clouds[name]), dtype=bool))
        lost = tuple(name for name in clouds if name in why)
        spliced_at = time.perf_counter()
        if spliced.registered is guess:
            registered, registered_voxels, answer, onward_timings, stamps = ahead.result()
        else:
            registered, registered_voxels, answer, onward_timings, stamps = onward(spliced.registered)
    finally:
        moot.set()  # whatever the speculation still does, nobody reads it now (an error, or it is done)
        beside.shutdown(wait=False, cancel_futures=True)  # it stops at its next step or ends on its own
    timings |= onward_timings
    X_RW = invert(np.asarray(X_WR, dtype=float))
    origins_R = {name: (X_RW @ np.asarray(image.X_WC, dtype=float))[:3, 3] for name, image in images.items()}

    def filter_merged() -> tuple[Cloud, Cloud]:
        dense = preprocess(spliced.dense, spec.workspace, X_WR, spec)
        if len(dense) == 0:
            raise SensorError(
                f"Z passthrough and outlier removal left no point of the {len(spliced.dense)} spliced ones"
            )
        return dense, downsample(dense, spec.voxel_m)

    perceived = Perceived(
        clouds,
        spliced,
        registered,
        filter_merged,
        registered_voxels,
        lost,
        timings,
        {n: why[n] for n in lost},
        origins_R,
        dict(checks or {}),
    )
    cloud_s = max(spliced_at, stamps["filtered"]) - t0
    return PerceivedThen(perceived, answer, cloud_s, max(spliced_at, stamps["answered"]) - t0, stamps["then_s"])


def _camera_clouds(
    images: Mapping[str, DepthImage], X_WR: FloatArray, spec: PerceptionSpec, health: HealthOptions | None
) -> tuple[dict[str, Cloud], dict[str, str]]:
    """Each camera's cropped cloud in R, and the cameras lost so far (name -> reason): an implausible image, or
    no point inside the workspace. A lost camera's cloud is empty."""
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
    return clouds, why


class PerceivedThen(NamedTuple, Generic[T]):
    """What :func:`perceive_then` returns: the perception, ``then``'s answer, and when each was ready.

    cloud_s : wall time [s] from the call until the registered cloud was ready (spliced and filtered).
    answer_s : wall time [s] from the call until ``then``'s answer was ready and known to be of the registered
        cloud (the splice done); it may have started beside the splice, so ``answer_s - cloud_s`` is what it
        added to the wall, not its own time.
    then_s : ``then``'s own wall time [s].
    """

    perceived: Perceived
    answer: T
    cloud_s: float
    answer_s: float
    then_s: float


class _SupersededError(Exception):
    """A speculation on the guess after a camera was lost or a correction applied (nobody reads its answer)."""
