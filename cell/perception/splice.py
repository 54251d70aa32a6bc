"""Splicing the camera clouds into one (paper section 3.3), generalised to 1, 2 or more cameras.

The paper: (1) ICP of camera 1's cloud onto camera 2's, (2) merge the two with priority (each side from the
camera nearer to it), (3) ICP of the eye-in-hand cloud onto that, (4) merge again. Here: the eye-in-hand camera
(calibrated to the robot) is the reference when there is one, else the second fixed camera; then the fixed
cameras in the paper's order are each registered onto all the cameras registered before them; the prioritised
merge (:func:`cell.perception.merge.prioritised_merge`) then makes the paper's cloud, ``Spliced.dense``. The
cloud of all cameras registered but *not* merged is kept as well (``Spliced.registered``): a locator that
weighs each camera by its own noise loses nothing to the merge.

Each camera is registered onto the cameras before it by :func:`cell.perception.registration.register` (open3d's
ICP, the paper's or a robust one, as ``PerceptionSpec.splice_icp`` says); its motion along directions the
overlap does not constrain is dropped there. Whichever ICP, the correction is *applied* only when it is
significant (a test, not a solver): at least one direction lowers the misfit on its own (the registration keeps
only those), its displacement of the overlap exceeds :data:`MIN_SHIFT_M`, its chi-square against a covariance
that treats every patch of ``merge_cell_m`` as one independent measurement (edges, flying pixels and shadows
bias whole patches, not single points) exceeds :data:`SIGNIFICANCE_CHI2`, and the patch misfit (point-to-plane)
drops by at least :data:`MIN_MISFIT_DROP`. (A z score per kept direction, ``Registration.z_min``, is reported but
not tested: a real miscalibration can have a component near zero along one direction.) With
exact extrinsics nothing is applied, also for long parts seen along their length (``scenarios/long-*.yaml``);
a miscalibration of 1 mm / 0.1 deg is taken out. ``Registration.refused`` says which test refused a correction.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
import numpy.typing as npt

from cell.errors import SensorError
from cell.geometry import FloatArray, invert, readonly, transform_points
from cell.perception.merge import prioritised_merge, surface_normals
from cell.perception.registration import register
from cell.scenario import PerceptionSpec
from cell.types import Cloud, DepthImage

MOUNTS = ("fixed", "eye_in_hand")
MIN_SHIFT_M = 0.0001  # [m] a correction moving the overlap by less than this (RMS) is not applied
SIGNIFICANCE_CHI2 = 50.0  # a correction is applied only above this chi-square (patch-robust covariance)
MIN_MISFIT_DROP = 0.05  # ... and only if it lowers the patch misfit by at least this fraction
REFUSALS = ("no_overlap", "no_supported_direction", "too_small", "not_significant", "no_misfit_gain")


@dataclass(frozen=True)
class Registration:
    """One splice registration: the cloud of ``source`` onto the registered cloud of the ``target`` cameras.

    X_corr : (4, 4) correction applied to the source cloud in R (p_R' = X_corr p_R); identity if not accepted.
    X_estimated : (4, 4) the correction the registration found, applied or not: open3d's ICP result without
        its motion along directions the overlap does not constrain.
    overlap : source probe points with a target point within reach (``voxel_m``) at the calibrated extrinsics.
    constrained : number of the six rigid degrees of freedom the overlap constrains (the chi-square's).
    shift_m : RMS displacement of the overlap by ``X_estimated`` [m].
    chi2 : its chi-square against the patch-robust covariance.
    misfit_before_m, misfit_m : RMS over patches of the mean point-to-plane residual [m], at the calibrated
        extrinsics and after ``X_estimated``.
    accepted : whether the correction was applied (see the module docstring).
    noise_m : robust standard deviation of the point-to-plane residuals in the overlap [m] (calibrated).
    directions_constrained : directions the overlap constrains, of which ``constrained`` lower the misfit on
        their own and are kept in ``X_estimated`` (the others stay as calibrated).
    z_min : the smallest z score of ``X_estimated``'s motion along a kept direction (patch-robust).
    refused : ``""`` when applied, else the first test that refused it (one of :data:`REFUSALS`).
    """

    source: str
    target: tuple[str, ...]
    X_corr: FloatArray
    X_estimated: FloatArray
    overlap: int
    constrained: int
    shift_m: float
    chi2: float
    misfit_before_m: float
    misfit_m: float
    accepted: bool
    noise_m: float = 0.0
    directions_constrained: int = 0
    z_min: float = 0.0
    refused: str = ""

    def __post_init__(self) -> None:
        object.__setattr__(self, "X_corr", readonly(self.X_corr))
        object.__setattr__(self, "X_estimated", readonly(self.X_estimated))

    @property
    def applied_shift_m(self) -> float:
        """RMS displacement of the overlap by the applied correction [m] (0 when refused)."""
        return self.shift_m if self.accepted else 0.0


def refusal(info: Mapping[str, float]) -> str:
    """``""`` if a registration's diagnostics (:func:`cell.perception.registration.register`) pass every test of
    the module docstring, else the first that fails (one of :data:`REFUSALS`)."""
    if info["overlap"] <= 0.0 or info["directions_constrained"] <= 0.0:
        return "no_overlap"
    if info["constrained"] <= 0.0:
        return "no_supported_direction"
    if info["shift_m"] < MIN_SHIFT_M:
        return "too_small"
    if info["chi2"] < SIGNIFICANCE_CHI2:
        return "not_significant"
    if not info["misfit_m"] <= (1.0 - MIN_MISFIT_DROP) * info["misfit_before_m"]:
        return "no_misfit_gain"
    return ""


@dataclass(frozen=True)
class Spliced:
    """The spliced clouds and how they were made, all in R, before Z passthrough and downsampling.

    registered : every camera registered, nothing merged away (per-point ``camera`` index).
    registrations : the registrations in the order they were made.
    merge : makes the paper's merged cloud and its per-camera counts from the registration's result (the
        prioritised merge); run once, on the first read of ``dense`` or ``kept``. Only the paper's and RANSAC's
        locators and the pictures read the merged cloud, so a detection with ours never pays for it.
    """

    registered: Cloud
    registrations: tuple[Registration, ...]
    merge: Callable[[], tuple[Cloud, dict[str, int]]] = field(compare=False, repr=False)

    @cached_property
    def _merged(self) -> tuple[Cloud, dict[str, int]]:
        return self.merge()

    @property
    def dense(self) -> Cloud:
        """The paper's cloud: every camera registered, then the prioritised merge; ``camera`` tags each point."""
        return self._merged[0]

    @property
    def kept(self) -> dict[str, int]:
        """Camera name -> number of its points that survived the prioritised merge."""
        return self._merged[1]


def splice_order(images: Mapping[str, DepthImage], names: tuple[str, ...]) -> tuple[str, ...]:
    """Splicing order: the eye-in-hand cameras (the first is the reference), then the 2nd fixed camera, the 1st
    fixed and the other fixed ones (the paper registers camera 1 onto camera 2)."""
    for name in names:
        if name not in images:
            raise ValueError(f"splice: no depth image for camera {name!r}; images: {', '.join(images)}")
        if images[name].mount not in MOUNTS:
            raise ValueError(f"camera {name!r} has mount {images[name].mount!r}; valid: {', '.join(MOUNTS)}")
    fixed = [n for n in names if images[n].mount == "fixed"]
    moving = [n for n in names if images[n].mount != "fixed"]
    if len(fixed) >= 2:
        fixed = [fixed[1], fixed[0], *fixed[2:]]
    return (*moving, *fixed)


def _stack_order(
    clouds: Mapping[str, Cloud], images: Mapping[str, DepthImage]
) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """(the non-empty clouds' names in the splice order, the camera tuple their points are indexed by): the
    clouds' shared tuple when they have one (indices stay valid), else the names. :class:`SensorError` if every
    cloud is empty."""
    names = tuple(n for n in clouds if len(clouds[n]) > 0)
    if not names:
        raise SensorError(f"nothing to splice: every camera cloud is empty ({', '.join(clouds) or 'none given'})")
    for n in names:
        if clouds[n].frame != "R":
            raise ValueError(f"splice: cloud of {n!r} is in frame {clouds[n].frame!r}; expected 'R'")
    shared = {clouds[n].cameras for n in names}
    cameras = shared.pop() if len(shared) == 1 else names
    return splice_order(images, names), cameras if set(names) <= set(cameras) else names


def stacked(clouds: Mapping[str, Cloud], images: Mapping[str, DepthImage]) -> Cloud:
    """Every non-empty camera cloud (frame R) concatenated in the splice order (:func:`splice_order`), as
    calibrated: the cloud :func:`splice` registers, and its ``registered`` cloud when no correction is applied
    (the same object then). :class:`SensorError` if every cloud is empty."""
    order, cameras = _stack_order(clouds, images)
    points = np.concatenate([np.asarray(clouds[n].points) for n in order])
    camera = np.concatenate([np.full(len(clouds[n]), cameras.index(n), np.int16) for n in order])
    return Cloud(points, "R", camera, cameras)


def splice(
    clouds: Mapping[str, Cloud],
    images: Mapping[str, DepthImage],
    X_WR: FloatArray,
    spec: PerceptionSpec,
    calibrated: Cloud | None = None,
    on_correction: Callable[[str], None] | None = None,
) -> Spliced:
    """Splice per-camera clouds (frame R, from :func:`clouds_in_robot_frame`) into one in R (module docstring).

    images : the captures the clouds came from (their mounts and calibrated poses X_WC, intrinsics fx).
    calibrated : :func:`stacked` of the same clouds when the caller has it (made here otherwise).
    on_correction : called with a camera's name as soon as its correction is applied (the registered cloud will
    differ from ``calibrated``). Empty clouds are skipped; :class:`SensorError` if every cloud is empty.
    """
    order, cameras = _stack_order(clouds, images)
    calibrated = stacked(clouds, images) if calibrated is None else calibrated
    index = {n: cameras.index(n) for n in order}
    X_RW = invert(np.asarray(X_WR, dtype=np.float64))
    X_RC = {index[n]: X_RW @ images[n].X_WC for n in order}
    fx = {index[n]: images[n].intrinsics.fx for n in order}
    camera = calibrated.camera
    bounds = np.cumsum([0] + [len(clouds[n]) for n in order])
    eyes = {i: X[:3, 3] for i, X in X_RC.items()}
    # The registrations move a copy; the merge's normals are plane fits twice the voxel wide (a voxel-wide fit of
    # 2-3 mm noise is as noisy as the depth) of the points as calibrated.
    points = np.array(calibrated.points)
    registrations = _register_in_order(points, bounds, order, index, X_RC, spec, on_correction)
    registered = Cloud(points, "R", camera, cameras) if any(r.accepted for r in registrations) else calibrated

    def merge() -> tuple[Cloud, dict[str, int]]:
        normals = surface_normals(calibrated.points, camera, eyes, 2.0 * spec.voxel_m, spec.merge_cell_m)
        keep = prioritised_merge(registered.points, camera, X_RC, fx, spec.merge_cell_m, spec.voxel_m, normals)
        kept = {n: int(np.count_nonzero(keep[bounds[k] : bounds[k + 1]])) for k, n in enumerate(order)}
        return registered.select(keep), kept

    return Spliced(registered, tuple(registrations), merge)


def _register_in_order(
    points: FloatArray,
    bounds: npt.NDArray[np.intp],
    order: tuple[str, ...],
    index: Mapping[str, int],
    X_RC: dict[int, FloatArray],
    spec: PerceptionSpec,
    on_correction: Callable[[str], None] | None = None,
) -> list[Registration]:
    """Register each camera's points (``points[bounds[k]:bounds[k + 1]]``, cameras in ``order``) onto those of the
    cameras before it; an accepted correction moves its points and its pose in ``X_RC`` (both in place) and is
    announced to ``on_correction``."""
    registrations = []
    for k, name in enumerate(order[1:], start=1):
        part = slice(bounds[k], bounds[k + 1])
        X, info = register(points[part], points[: bounds[k]], spec)
        refused = refusal(info)
        accepted = not refused
        X_corr = X if accepted else np.eye(4)
        registrations.append(
            Registration(
                name,
                order[:k],
                X_corr,
                X,
                int(info["overlap"]),
                int(info["constrained"]),
                info["shift_m"],
                info["chi2"],
                info["misfit_before_m"],
                info["misfit_m"],
                accepted,
                info["noise_m"],
                int(info["directions_constrained"]),
                info["z_min"],
                refused,
            )
        )
        if accepted:
            if on_correction is not None:
                on_correction(name)
            points[part] = transform_points(X_corr, points[part])
            X_RC[index[name]] = X_corr @ X_RC[index[name]]
    return registrations
