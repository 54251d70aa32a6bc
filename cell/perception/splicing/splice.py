"""Splicing the camera clouds into one (paper section 3.3), for 1, 2 or more cameras: each camera registered onto
the cameras before it, a correction applied only where the overlap fixes the whole pose and lowers the misfit, a
camera beyond its stated calibration dropped as a fault, then the prioritised merge (docs/perception.md, "The
splice's order" and "The splice: an estimate with the stated calibration as its prior")."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
import numpy.typing as npt

from cell.errors import SensorError
from cell.geometry import FloatArray, invert, transform_points
from cell.perception.merge import prioritised_merge, surface_normals
from cell.perception.splicing.decision import Registration, refusal
from cell.perception.splicing.pose_prior import FAULT_SIGMAS, PoseUncertainty, relative_covariance
from cell.perception.splicing.registration import register
from cell.scenario import PerceptionSpec
from cell.types import Cloud, DepthImage

MOUNTS = ("fixed", "eye_in_hand")


@dataclass(frozen=True)
class Spliced:
    """The spliced clouds and how they were made, all in R, before Z passthrough and downsampling.

    registered : every camera registered, nothing merged away (per-point ``camera`` index), less the faults.
    registrations : the registrations in the order they were made.
    faults : camera name -> why it was dropped (its data disagree with the prior,
        :data:`cell.perception.splicing.decision.FAULT`).
    merge : makes the paper's merged cloud and its per-camera counts from the registration's result (the
        prioritised merge); run once, on the first read of ``dense`` or ``kept``. Only the paper's and RANSAC's
        locators and the pictures read the merged cloud, so a detection with ours never pays for it.
    """

    registered: Cloud
    registrations: tuple[Registration, ...]
    merge: Callable[[], tuple[Cloud, dict[str, int]]] = field(compare=False, repr=False)
    faults: Mapping[str, str] = field(default_factory=dict)

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
    priors: Mapping[str, PoseUncertainty] | None = None,
) -> Spliced:
    """Splice per-camera clouds (frame R, from :func:`clouds_in_robot_frame`) into one in R (module docstring).

    images : the captures the clouds came from (their mounts and calibrated poses X_WC, intrinsics fx).
    calibrated : :func:`stacked` of the same clouds when the caller has it (made here otherwise).
    on_correction : called with a camera's name as soon as the registered cloud will differ from ``calibrated``
        (its correction applied, or the camera dropped as a fault).
    priors : camera name -> its stated calibration (the prior on its pose); a camera not named is stated exact.
    Empty clouds are skipped; :class:`SensorError` if every cloud is empty.
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
    steps = _Steps(points, bounds, order, index, X_RC, dict(priors or {}))
    registrations = steps.run(spec, on_correction)
    faults = {r.source: _fault_reason(r) for r in registrations if r.fault}
    keep = ~np.isin(camera, [index[n] for n in faults]) if faults else None
    registered = Cloud(points, "R", camera, cameras) if any(r.accepted for r in registrations) else calibrated
    if keep is not None:
        registered, calibrated = registered.select(keep), calibrated.select(keep)
    X_RC_kept = {i: X for i, X in X_RC.items() if cameras[i] not in faults}

    def merge() -> tuple[Cloud, dict[str, int]]:
        normals = surface_normals(calibrated.points, calibrated.camera, eyes, 2.0 * spec.voxel_m, spec.merge_cell_m)
        kept_mask = prioritised_merge(
            registered.points, registered.camera, X_RC_kept, fx, spec.merge_cell_m, spec.voxel_m, normals
        )
        tags = registered.camera[kept_mask]
        kept = {n: int(np.count_nonzero(tags == index[n])) for n in order}
        return registered.select(kept_mask), kept

    return Spliced(registered, tuple(registrations), merge, faults)


def _fault_reason(r: Registration) -> str:
    """One line: why a camera whose data disagree with its stated calibration was dropped."""
    return (
        f"disagrees with {', '.join(r.target)} by {r.disagreement_sigmas:.1f} sigmas of its stated calibration along "
        f"a direction their overlap fixes (at most {FAULT_SIGMAS:.0f}): knocked out of calibration?"
    )


@dataclass
class _Steps:
    """The registrations in the splice order, each camera (``points[bounds[k]:bounds[k + 1]]``, cameras in
    ``order``) onto the cameras before it that are not faults. An accepted correction moves the camera's points
    and its pose in ``X_RC`` (both in place); ``tied`` follows which camera's calibration a corrected camera now
    rests on (its first target's)."""

    points: FloatArray
    bounds: npt.NDArray[np.intp]
    order: tuple[str, ...]
    index: Mapping[str, int]
    X_RC: dict[int, FloatArray]
    priors: dict[str, PoseUncertainty]
    tied: dict[str, str] = field(default_factory=dict)

    def run(self, spec: PerceptionSpec, on_correction: Callable[[str], None] | None) -> list[Registration]:
        out: list[Registration] = []
        faults: set[str] = set()
        for k, name in enumerate(self.order[1:], start=1):
            targets = tuple(n for n in self.order[:k] if n not in faults)
            r = self.one(k, name, targets, spec)
            out.append(r)
            if r.fault:
                faults.add(name)
            elif r.accepted:
                part = slice(self.bounds[k], self.bounds[k + 1])
                self.points[part] = transform_points(r.X_corr, self.points[part])
                i = self.index[name]
                self.X_RC[i] = r.X_corr @ self.X_RC[i]
                self.tied[name] = self.tied.get(targets[0], targets[0])
            if (r.fault or r.accepted) and on_correction is not None:
                on_correction(name)
        return out

    def one(self, k: int, name: str, targets: tuple[str, ...], spec: PerceptionSpec) -> Registration:
        """Camera ``order[k]`` registered onto ``targets`` with its prior (or not at all when stated exact)."""
        eye = np.eye(4)
        u = self.priors.get(name, PoseUncertainty())
        if u.zero or not targets:
            refused = "calibration_exact" if u.zero else "no_overlap"
            return Registration(name, targets, eye, eye, 0, 0, 0.0, 0.0, math.inf, math.inf, False, refused=refused)
        parts = [slice(self.bounds[j], self.bounds[j + 1]) for j, n in enumerate(self.order[:k]) if n in targets]
        counts = [p.stop - p.start for p in parts]
        shares: dict[str, float] = {}  # each target's share, summed per calibration it rests on
        for n, c in zip(targets, counts, strict=True):
            src = self.tied.get(n, n)
            shares[src] = shares.get(src, 0.0) + c / max(sum(counts), 1)
        origin = {n: self.X_RC[self.index[n]][:3, 3] for n in (name, *shares)}

        def prior(centre_R: FloatArray, lever_m: float) -> FloatArray:
            rest = [(self.priors.get(n, PoseUncertainty()), origin[n], w) for n, w in shares.items()]
            return relative_covariance((u, origin[name]), rest, centre_R, lever_m)

        target_points = np.concatenate([self.points[p] for p in parts])
        est = register(self.points[self.bounds[k] : self.bounds[k + 1]], target_points, spec, prior)
        refused = refusal(est)
        return Registration(
            name,
            targets,
            est.X_map if not refused else eye,
            est.X_estimated,
            est.overlap,
            est.informed,
            est.shift_m,
            est.map_shift_m,
            est.misfit_before_m,
            est.misfit_m,
            not refused,
            est.noise_m,
            est.disagreement_sigmas,
            refused,
            est.residual,
        )
