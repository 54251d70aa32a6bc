"""Locate a welding map's seams in a point cloud someone brings (a laser scan, a lidar sweep, any sensor's cloud): the
same stages as :func:`cell.pipeline.detect` from the map alignment on, without a station or a simulator (the steps:
docs/locate.md, "From the cloud to the seams"). Nothing here imports the simulator."""

from __future__ import annotations

import time
import zlib
from collections.abc import Mapping
from dataclasses import replace

import numpy as np

from cell.errors import AlignmentError, CellError, SensorError
from cell.geometry import FloatArray, invert, make_pose, transform_points
from cell.perception.align.checks import check_alignment_unique, check_parts_seen, cloud_tree_of
from cell.perception.align.cloud import FRAME as _FRAME
from cell.perception.align.cloud import POOR_FITNESS, crop_mask, place_map
from cell.perception.align.fit import Alignment
from cell.perception.align.placement import flatten_to_yaw, on_table
from cell.perception.align.sight import places_in_evidence
from cell.perception.ground import Ground, TableSource, find_ground, floor_height
from cell.perception.preprocess import downsample
from cell.perception.unorganised import TablePlane, levelling
from cell.perception.unorganised import sampling as spacing_of
from cell.pipeline.cloud.seams import locate_seams
from cell.pipeline.cloud.setup import scenario_for
from cell.pipeline.evaluation import evaluate
from cell.pipeline.progress import Progress, quiet
from cell.pipeline.records import Detection
from cell.scenario import Scenario
from cell.seams.curved import locate_curves
from cell.seams.curved.results import carried, not_searched
from cell.seams.joint import find_joints
from cell.seams.visibility import visibility
from cell.types import (
    Box,
    Cloud,
    Joint,
    Reason,
    SeamEstimate,
    SeamScene,
    SeamStatus,
    WeldMap,
)
from cell.voxels import voxel_order

MIN_POINTS = 200  # fewer points than this: no cloud to locate anything in


def locate_cloud(
    cloud: Cloud,
    weldmap: WeldMap,
    X_FM_nominal: FloatArray | None,
    *,
    name: str = "cloud",
    method: str | None = None,
    viewpoint_F: FloatArray | None = None,
    truth_F: Mapping[str, tuple[FloatArray, FloatArray]] | None = None,
    table_z_m: float | None = None,
    no_table: bool = False,
    progress: Progress = quiet,
) -> Detection:
    """Locate ``weldmap``'s seams (frame M, as drawn) in ``cloud`` (unorganised, metres, frame F = ``cloud.frame``).

    X_FM_nominal : (4, 4) nominal pose of the drawing's origin in F, or None (global registration).
    method : the locator (None: ours). viewpoint_F : (3,) where the sensor was (orients the normals; None: the
    heuristic of :func:`~cell.perception.unorganised.orient_normals`). truth_F : seam id -> true ends (3,), (3,) in
    F [m]: the detection is measured against them (no truth, no error fields). table_z_m : the table's height in F
    [m] when known (F's z up); no_table : there is no table in the cloud (else both are read from the data:
    :func:`~cell.perception.ground.find_ground`).

    Returns the usual :class:`Detection`, in F, with a scenario synthesised for the cloud. SensorError for a cloud
    with too few or non-finite points or no upward face at all; an alignment that fails is returned as the detection's
    ``error`` with every seam NOT_FOUND (or NOT_VISIBLE), as :func:`cell.pipeline.detect` does.
    """
    t_all = time.perf_counter()
    timings: dict[str, float] = {}
    method = method or "ours"
    P_F = np.asarray(cloud.points, dtype=np.float64)
    if len(P_F) < MIN_POINTS:
        raise SensorError(f"cloud {name!r} has {len(P_F)} points; at least {MIN_POINTS} are needed")
    if not np.all(np.isfinite(P_F)):
        raise SensorError(f"cloud {name!r} has {int(np.sum(~np.isfinite(P_F).all(axis=1)))} non-finite points")
    rng = np.random.default_rng([0, zlib.crc32(f"cloud/{name}".encode())])

    t = time.perf_counter()
    progress(f"finding the table plane in {len(P_F)} points")
    ground = find_ground(P_F, rng, table_z_m=table_z_m, no_table=no_table)
    table = ground.plane
    X_LF = np.eye(4) if ground.source is TableSource.GIVEN else levelling(table)  # given: F's z is up
    X_FL = invert(X_LF)
    P_L = transform_points(X_LF, P_F)
    along, between = spacing_of(P_L, _levelled(table, X_LF))
    noise = table.sigma_m
    # The table's height in L and the points above it (no table: where the parts' bottoms are, and every point).
    table_z, above = _ground_in_L(ground, P_L, noise)
    progress(_ground_line(ground, noise, along, between))
    timings["table_s"] = time.perf_counter() - t

    t = time.perf_counter()
    joints = find_joints(weldmap)
    viewpoint_L = transform_points(X_LF, np.reshape(viewpoint_F, (1, 3)))[0] if viewpoint_F is not None else None
    X_LM0 = on_table(X_LF @ X_FM_nominal, weldmap, table_z) if X_FM_nominal is not None else None
    spec_scenario = scenario_for(
        name, weldmap, X_FL, X_LM0, P_L, above, (table, table_z), viewpoint_L, (noise, along, between), method
    )
    spec = spec_scenario.perception
    placed = place_map(P_L, above, weldmap, table_z, X_LM0, spec, viewpoint_L, rng, progress)
    X_LM0, alignment, error = placed.X_LM0, placed.alignment, placed.error
    timings["align_s"] = time.perf_counter() - t

    scenario = spec_scenario
    if alignment is None or X_LM0 is None:
        assert error is not None
        return _failed(scenario, weldmap, joints, X_FL, X_LM0, table_z, method, error, timings, t_all, cloud.frame)
    if ground.source is not TableSource.FOUND:  # the part lies flat: the fit turned about z only
        alignment, low = _flat(alignment, X_LM0, weldmap)
        table_z = low if ground.given_z_m is None else table_z  # no table: the parts' bottom stands for it
    X_LM = alignment.X_RR_corr @ X_LM0
    if X_FM_nominal is not None:
        progress(_placement_error(X_FM_nominal, X_FL @ X_LM))
    map_L = weldmap.transformed(X_LM, _FRAME)
    crop = crop_mask(P_L, above, map_L)
    dense_L = Cloud(P_L[crop], _FRAME)
    measured = (noise, along, between)
    scenario = scenario_for(name, weldmap, X_FL, X_LM, P_L, above, (table, table_z), viewpoint_L, measured, method)
    try:
        tree = cloud_tree_of(dense_L)
        check_alignment_unique(map_L, dense_L, alignment, spec.symmetry, tree)
        eyes_L = viewpoint_L[None, :] if viewpoint_L is not None else places_in_evidence(map_L, tree)
        missing = check_parts_seen(map_L, dense_L, spec, spec.coverage, tree, eyes_L)
    except AlignmentError as e:
        return _failed(scenario, weldmap, joints, X_FL, X_LM, table_z, method, e, timings, t_all, cloud.frame)

    t = time.perf_counter()
    progress(f"locating {len(map_L.seams)} seams ({method})")
    ordered, voxels = voxel_order(dense_L, spec.voxel_m)
    ss = SeamScene(downsample(dense_L, spec.voxel_m), ordered, map_L, joints, table_z, voxels)
    estimates = locate_seams(ss, scenario, method, _workspace_L(P_L, crop), missing)
    curves = tuple(carried(e, X_FL) for e in locate_curves(method, ss))
    timings["locate_s"] = time.perf_counter() - t
    estimates_F = tuple(_carried(e, X_FL) for e in estimates)
    truth = dict(truth_F) if truth_F is not None else {}
    metrics, summary = evaluate(estimates_F, truth)
    timings["total_s"] = time.perf_counter() - t_all
    return Detection(
        scenario=scenario,
        method=method,
        weldmap_R=weldmap.transformed(X_FL @ X_LM, cloud.frame),
        estimates=estimates_F,
        truths=truth,
        metrics=metrics,
        summary=summary,
        timings=timings,
        joints=joints,
        source="cloud",
        curve_estimates=curves,
    )


def _placement_error(X_FM_nominal: FloatArray, X_FM: FloatArray) -> str:
    """How far the part was found from the placement given (a line for the progress log)."""
    X_d = invert(X_FM_nominal) @ X_FM
    shift_mm = 1000.0 * float(np.linalg.norm(X_FM[:3, 3] - X_FM_nominal[:3, 3]))
    angle_deg = float(np.degrees(np.arccos(np.clip((np.trace(X_d[:3, :3]) - 1.0) / 2.0, -1.0, 1.0))))
    return f"the part lies {shift_mm:.1f} mm and {angle_deg:.1f} deg from the placement given"


def _ground_in_L(ground: Ground, P_L: FloatArray, noise_m: float) -> tuple[float, np.ndarray]:
    """(table_z, above): the table's height in L [m] and the points above it (n,); with no table, where the parts'
    bottoms are (:func:`~cell.perception.ground.floor_height`, a start the alignment corrects) and every point."""
    if ground.source is TableSource.ABSENT:
        return floor_height(P_L[:, 2]), np.ones(len(P_L), dtype=bool)
    table_z = float(ground.given_z_m) if ground.given_z_m is not None else float(ground.plane.offset)
    return table_z, P_L[:, 2] > table_z + max(0.005, 3.0 * noise_m)


def _ground_line(ground: Ground, noise_m: float, along_m: float, between_m: float) -> str:
    """The progress line about the ground and the cloud's noise and spacing."""
    tilt = np.degrees(ground.plane.tilt_rad)
    spacing = f"{along_m * 1e3:.1f} mm along / {between_m * 1e3:.1f} mm between lines"
    data = f"noise {noise_m * 1e3:.2f} mm RMS, spacing {spacing}"
    if ground.source is TableSource.FOUND:
        return f"table tilted {tilt:.2f} deg, {data}"
    if ground.given_z_m is not None:
        return f"table at z = {ground.given_z_m * 1e3:.1f} mm (given), {data} on the largest upward face"
    return (
        f"no table in the cloud ({ground.below_share:.0%} of the points lie under its largest upward plane, tilted "
        f"{tilt:.2f} deg: a part's face): aligning on the parts' own faces, {data} on that face"
    )


def _flat(alignment: Alignment, X_LM0: FloatArray, weldmap: WeldMap) -> tuple[Alignment, float]:
    """With no table found in the data: the fit reduced to a turn about z (about the parts' centre: L is levelled by
    the parts' own largest upward face, or F's z is up with a stated table; a part lying flat has no roll or pitch)
    and the height [m] of the parts' lowest corner, where whatever holds them is (with no table stated, what the
    stages take for the table: the seams' ends there, the underside)."""
    centre = np.mean([p.center for p in weldmap.parts], axis=0)
    X_LM = flatten_to_yaw(alignment.X_RR_corr @ X_LM0, centre)
    low = min(float(transform_points(X_LM, p.vertices())[:, 2].min()) for p in weldmap.parts)
    return replace(alignment, X_RR_corr=X_LM @ invert(X_LM0)), low


def _levelled(table: TablePlane, X_LF: FloatArray) -> TablePlane:
    """The table plane expressed in L."""
    return replace(table, normal=X_LF[:3, :3] @ table.normal)


def _workspace_L(P_L: FloatArray, crop: np.ndarray) -> Box:
    """The crop's box (frame L): where our locator must not take the cloud's end for the part's end."""
    lo, hi = P_L[crop].min(axis=0), P_L[crop].max(axis=0)
    return Box(make_pose(p=(lo + hi) / 2.0), hi - lo)


def _carried(est: SeamEstimate, X_FL: FloatArray) -> SeamEstimate:
    """The estimate with its ends carried from L into F."""
    if est.status is not SeamStatus.FOUND:
        return est
    ends = transform_points(X_FL, np.vstack([est.p_start, est.p_end]))
    return replace(est, p_start=ends[0], p_end=ends[1])


def _failed(
    scenario: Scenario,
    weldmap: WeldMap,
    joints: Mapping[str, Joint],
    X_FL: FloatArray,
    X_LM: FloatArray | None,
    table_z: float,
    method: str,
    error: CellError,
    timings: dict[str, float],
    t_all: float,
    frame: str,
) -> Detection:
    """No seam searched (the map could not be aligned): every seam NOT_FOUND with the reason (NOT_VISIBLE when the
    drawing alone says it lies against the table)."""
    # With no placement the drawing still tells which seams lie against the table: as drawn, on the table.
    X = X_LM if X_LM is not None else on_table(np.eye(4), weldmap, table_z)
    map_L = weldmap.transformed(X, _FRAME)
    estimates = []
    for seam in map_L.seams:
        visible, why = visibility(map_L, joints[seam.id], table_z)
        if visible:
            msg = f"no seam search: {error.message}"
            estimates.append(SeamEstimate(seam.id, SeamStatus.NOT_FOUND, msg, code=Reason.NO_SEARCH))
        else:
            estimates.append(SeamEstimate(seam.id, SeamStatus.NOT_VISIBLE, why, code=Reason.UNDERSIDE))
    metrics, summary = evaluate(estimates, {})
    timings["total_s"] = time.perf_counter() - t_all
    return Detection(
        scenario=scenario,
        method=method,
        weldmap_R=weldmap.transformed(X_FL @ X, frame),
        estimates=tuple(estimates),
        truths={},
        metrics=metrics,
        summary=summary,
        timings=timings,
        error=error,
        joints=joints,
        source="cloud",
        curve_estimates=not_searched(map_L, error.message),
    )


__all__ = ["POOR_FITNESS", "locate_cloud"]
