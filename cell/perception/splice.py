"""Splicing the camera clouds into one (paper section 3.3), generalised to 1, 2 or more cameras.

The paper: (1) ICP point-to-point (max correspondence 1 mm, 50 iterations) of camera 1's cloud onto camera
2's, (2) merge the two with priority (each side from the camera nearer to it), (3) ICP of the eye-in-hand
cloud onto that, (4) merge again. Here: the second fixed camera is the reference, the first fixed camera is
registered onto it and merged, then every further fixed camera and then every eye-in-hand camera is registered
onto the merged cloud and merged with the same rule (:func:`cell.perception.merge.prioritised_merge`).

An ICP correction is applied only if it brings the source closer to the target's *surfaces* (mean
point-to-plane distance over the overlap, :func:`plane_misfit`). With the paper's 1 mm correspondence
distance and camera point spacings of 1.5-4 mm, point-to-point ICP can latch onto chance near-coincidences of
points and drift; the check then keeps the calibrated extrinsics (recorded as ``accepted=False``).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
from scipy.spatial import cKDTree

from cell.errors import SensorError
from cell.geometry import FloatArray, invert, readonly, transform_points
from cell.perception import _open3d
from cell.perception.merge import prioritised_merge, surface_normals
from cell.scenario import PerceptionSpec
from cell.types import Cloud, DepthImage

MOUNTS = ("fixed", "eye_in_hand")
_ICP_MAX_SOURCE = 20_000  # source points a splice ICP uses (every k-th one); the target keeps all of its own
_ICP_MIN_POINTS = 10  # fewer points on either side: no ICP, the calibrated extrinsics stand


@dataclass(frozen=True)
class Registration:
    """One splice ICP: the cloud of ``source`` registered onto the merged cloud of ``target`` cameras.

    X_corr : (4, 4) correction applied to the source cloud in R (p_R' = X_corr p_R); identity if not accepted.
    fitness, rmse_m : ICP fitness and inlier RMSE [m] at the end (point-to-point, within max correspondence).
    fitness_before : fitness of the calibrated extrinsics (identity), for comparison.
    misfit_before_m, misfit_m : median point-to-plane distance [m] of the overlap before and after ICP.
    accepted : whether the correction was applied (only if it lowers the misfit).
    """

    source: str
    target: tuple[str, ...]
    X_corr: FloatArray
    fitness: float
    rmse_m: float
    fitness_before: float
    misfit_before_m: float
    misfit_m: float
    accepted: bool

    def __post_init__(self) -> None:
        object.__setattr__(self, "X_corr", readonly(self.X_corr))


@dataclass(frozen=True)
class Spliced:
    """The spliced cloud and how it was made.

    dense : all cameras merged, in R, before Z passthrough and downsampling; ``camera`` tags each point's
    capture. registrations : the ICP runs in the order they were made.
    kept : camera name -> number of its points that survived the prioritised merge.
    """

    dense: Cloud
    registrations: tuple[Registration, ...] = ()
    kept: dict[str, int] = field(default_factory=dict)


def register(
    source: FloatArray, target: FloatArray, max_correspondence_m: float, iterations: int
) -> tuple[FloatArray, float, float, float]:
    """Point-to-point ICP of ``source`` (n, 3) onto ``target`` (m, 3), from identity.

    Returns (X_TS (4, 4), fitness, rmse_m, fitness at identity). Uses at most 20 000 evenly strided source
    points.
    """
    stride = max(1, int(np.ceil(len(source) / _ICP_MAX_SOURCE)))
    src = source[::stride]
    fitness_before, _ = _open3d.evaluate(src, target, max_correspondence_m)
    result = _open3d.icp(src, target, max_correspondence_m, iterations)
    return result.X_TS, result.fitness, result.rmse_m, fitness_before


def plane_misfit(
    source: FloatArray, target: FloatArray, target_normals: FloatArray, radius_m: float
) -> tuple[float, int]:
    """Mean distance [m] of source points (n, 3) to the tangent plane of their nearest target point, over the
    source points that have a target point within ``radius_m`` (the overlap), and how many those are.

    The largest tenth of the distances (pairs across an edge, stray points) is left out of the mean. Returns
    (inf, 0) when nothing overlaps.
    """
    dist, idx = cKDTree(target).query(source, distance_upper_bound=radius_m)
    near = np.isfinite(dist)
    if not near.any():
        return math.inf, 0
    d = np.abs(np.einsum("ij,ij->i", source[near] - target[idx[near]], target_normals[idx[near]]))
    d = np.sort(d)[: max(1, math.ceil(0.9 * len(d)))]
    return float(np.mean(d)), int(near.sum())


def splice_order(images: Mapping[str, DepthImage], names: tuple[str, ...]) -> tuple[str, ...]:
    """Splicing order: 2nd fixed camera (the reference), 1st fixed, other fixed, then the eye-in-hand ones."""
    for name in names:
        if name not in images:
            raise ValueError(f"splice: no depth image for camera {name!r}; images: {', '.join(images)}")
        if images[name].mount not in MOUNTS:
            raise ValueError(f"camera {name!r} has mount {images[name].mount!r}; valid: {', '.join(MOUNTS)}")
    fixed = [n for n in names if images[n].mount == "fixed"]
    moving = [n for n in names if images[n].mount != "fixed"]
    if len(fixed) >= 2:
        fixed = [fixed[1], fixed[0], *fixed[2:]]
    return (*fixed, *moving)


def splice(
    clouds: Mapping[str, Cloud], images: Mapping[str, DepthImage], X_WR: FloatArray, spec: PerceptionSpec
) -> Spliced:
    """Splice per-camera clouds (frame R, from :func:`clouds_in_robot_frame`) into one dense cloud in R.

    images : the captures the clouds came from (their mounts and calibrated poses X_WC, intrinsics fx).
    Empty clouds are skipped; :class:`SensorError` if every cloud is empty.
    """
    names = tuple(n for n in clouds if len(clouds[n]) > 0)
    if not names:
        raise SensorError(f"nothing to splice: every camera cloud is empty ({', '.join(clouds) or 'none given'})")
    for n in names:
        if clouds[n].frame != "R":
            raise ValueError(f"splice: cloud of {n!r} is in frame {clouds[n].frame!r}; expected 'R'")
    order = splice_order(images, names)
    # Keep the clouds' shared camera tuple when they have one (indices stay valid), else index by name order.
    shared = {clouds[n].cameras for n in names}
    cameras = shared.pop() if len(shared) == 1 else names
    if not set(names) <= set(cameras):
        cameras = names
    index = {n: cameras.index(n) for n in names}

    def eyes() -> dict[int, FloatArray]:
        return {i: X[:3, 3] for i, X in X_RC.items()}

    X_RW = invert(np.asarray(X_WR, dtype=np.float64))
    X_RC = {index[n]: X_RW @ images[n].X_WC for n in names}
    fx = {index[n]: images[n].intrinsics.fx for n in names}
    merged_points = np.asarray(clouds[order[0]].points)
    merged_camera = np.full(len(merged_points), index[order[0]], np.int16)
    done = [order[0]]
    registrations = []
    for name in order[1:]:
        p = np.asarray(clouds[name].points)
        X_corr = np.eye(4)
        if len(p) >= _ICP_MIN_POINTS and len(merged_points) >= _ICP_MIN_POINTS:
            X, fit, rmse, fit0 = register(p, merged_points, spec.icp_max_correspondence_m, spec.icp_iterations)
            normals = surface_normals(merged_points, merged_camera, eyes(), spec.voxel_m, spec.merge_cell_m)
            probe = p[:: max(1, len(p) // _ICP_MAX_SOURCE)]
            misfit0, _ = plane_misfit(probe, merged_points, normals, spec.voxel_m)
            misfit, _ = plane_misfit(transform_points(X, probe), merged_points, normals, spec.voxel_m)
            accepted = misfit < misfit0
            if accepted:
                X_corr = X
            registrations.append(Registration(name, tuple(done), X_corr, fit, rmse, fit0, misfit0, misfit, accepted))
        p = transform_points(X_corr, p)
        X_RC[index[name]] = X_corr @ X_RC[index[name]]
        points = np.concatenate([merged_points, p])
        camera = np.concatenate([merged_camera, np.full(len(p), index[name], np.int16)])
        keep = prioritised_merge(points, camera, X_RC, fx, spec.merge_cell_m, spec.voxel_m)
        merged_points, merged_camera = points[keep], camera[keep]
        done.append(name)
    kept = {n: int(np.count_nonzero(merged_camera == index[n])) for n in names}
    return Spliced(Cloud(merged_points, "R", merged_camera, cameras), tuple(registrations), kept)
