"""Locate a welding map's seams in a point cloud someone brings (a laser scan, a lidar sweep, any sensor's cloud): the
same stages as :func:`cell.pipeline.detect` from the map alignment on, without a station or a simulator (the steps:
docs/locate.md, "From the cloud to the seams"). Nothing here imports the simulator."""

from __future__ import annotations

import time
import zlib
from collections.abc import Mapping
from dataclasses import replace

import numpy as np

from cell.errors import AlignmentError, AlignmentFailure, CellError, SensorError
from cell.geometry import FloatArray, invert, make_pose, transform_points
from cell.perception.align.checks import check_alignment_unique, check_parts_seen
from cell.perception.align.fit import Alignment, align_map, sample_map, surface_fit
from cell.perception.align.placement import DISTINCT_DEG, DISTINCT_M, fpfh_candidates, height_candidates, on_table
from cell.perception.preprocess import downsample
from cell.perception.unorganised import TablePlane, find_table, levelling
from cell.perception.unorganised import sampling as spacing_of
from cell.pipeline.cloud_seams import locate_seams
from cell.pipeline.cloud_setup import FRAME as _FRAME
from cell.pipeline.cloud_setup import crop_mask, scenario_for
from cell.pipeline.evaluation import evaluate
from cell.pipeline.progress import Progress, quiet
from cell.pipeline.records import Detection
from cell.scenario import PerceptionSpec, Scenario
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

POOR_FITNESS = 0.6  # a fit from the nominal placement below this fitness is retried from a global registration
CHALLENGE_MARGIN = 1.05  # a fit elsewhere must explain this many times the placement's fit's points to replace it
PRESCORE, PRESCORE_BAND_M = 0.7, 0.01  # ... and before its ICP this share of them, within this band
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
    progress: Progress = quiet,
) -> Detection:
    """Locate ``weldmap``'s seams (frame M, as drawn) in ``cloud`` (unorganised, metres, frame F = ``cloud.frame``).

    X_FM_nominal : (4, 4) nominal pose of the drawing's origin in F, or None (global registration).
    method : the locator (None: ours). viewpoint_F : (3,) where the sensor was (orients the normals; None: the
    heuristic of :func:`~cell.perception.unorganised.orient_normals`). truth_F : seam id -> true ends (3,), (3,) in
    F [m]: the detection is measured against them (no truth, no error fields).

    Returns the usual :class:`Detection`, in F, with a scenario synthesised for the cloud. SensorError for a cloud
    with too few or non-finite points or no table; an alignment that fails is returned as the detection's
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
    table = find_table(P_F, rng)
    X_LF = levelling(table)
    X_FL = invert(X_LF)
    P_L = transform_points(X_LF, P_F)
    table_z = float(table.offset)  # the table's height in L
    along, between = spacing_of(P_L, _levelled(table, X_LF))
    noise = table.sigma_m
    progress(
        f"table tilted {np.degrees(table.tilt_rad):.2f} deg, noise {noise * 1e3:.2f} mm RMS, spacing "
        f"{along * 1e3:.1f} mm along / {between * 1e3:.1f} mm between lines"
    )
    above = P_L[:, 2] > table_z + max(0.005, 3.0 * noise)
    timings["table_s"] = time.perf_counter() - t

    t = time.perf_counter()
    joints = find_joints(weldmap)
    viewpoint_L = transform_points(X_LF, np.reshape(viewpoint_F, (1, 3)))[0] if viewpoint_F is not None else None
    X_LM0 = on_table(X_LF @ X_FM_nominal, weldmap, table_z) if X_FM_nominal is not None else None
    spec_scenario = scenario_for(
        name, weldmap, X_FL, X_LM0, P_L, above, table, viewpoint_L, (noise, along, between), method
    )
    spec = spec_scenario.perception
    alignment: Alignment | None = None
    error: CellError | None = None
    count = 0.0
    if X_LM0 is not None:
        crop = crop_mask(P_L, above, weldmap.transformed(X_LM0, _FRAME))
        try:
            alignment = align_map(weldmap.transformed(X_LM0, _FRAME), Cloud(P_L[crop], _FRAME), spec)
            count = alignment.fitness * int(crop.sum())
        except AlignmentError as e:
            error = e
    if alignment is not None and X_LM0 is not None and alignment.fitness >= POOR_FITNESS:
        # A placement turned far off settles on a wrong fit that the checks pass (the tee turned by 180 degrees
        # fits 0.78 of its points): the height image's best pose unlike it must not explain clearly more points.
        other = _challenger(P_L, above, weldmap, table_z, spec, alignment.X_RR_corr @ X_LM0)
        if other is not None and other[2] > CHALLENGE_MARGIN * count:
            progress(
                f"the placement was far off: a fit elsewhere explains {other[2] / max(count, 1.0):.0%} of its points"
            )
            X_LM0, alignment = other[0], other[1]
    elif alignment is None or alignment.fitness < POOR_FITNESS:
        progress("global registration of the map (height image, FPFH + RANSAC)")
        best = _global(P_L, above, weldmap, table_z, viewpoint_L, rng, spec)
        if best is not None and (alignment is None or best[2] > count):
            X_LM0, alignment, error = best[0], best[1], None
        elif alignment is None and error is None:
            error = AlignmentError(
                "no placement of the map fits the cloud (global registration: no candidate aligned)",
                code=AlignmentFailure.LOW_FITNESS,
            )
    timings["align_s"] = time.perf_counter() - t

    scenario = spec_scenario
    if alignment is None or X_LM0 is None:
        assert error is not None
        return _failed(scenario, weldmap, joints, X_FL, X_LM0, table_z, method, error, timings, t_all, cloud.frame)
    X_LM = alignment.X_RR_corr @ X_LM0
    if X_FM_nominal is not None:
        progress(_placement_error(X_FM_nominal, X_FL @ X_LM))
    map_L = weldmap.transformed(X_LM, _FRAME)
    crop = crop_mask(P_L, above, map_L)
    dense_L = Cloud(P_L[crop], _FRAME)
    scenario = scenario_for(name, weldmap, X_FL, X_LM, P_L, above, table, viewpoint_L, (noise, along, between), method)
    try:
        check_alignment_unique(map_L, dense_L, alignment, spec.symmetry)
        missing = check_parts_seen(map_L, dense_L, spec, spec.coverage)
    except AlignmentError as e:
        return _failed(scenario, weldmap, joints, X_FL, X_LM, table_z, method, e, timings, t_all, cloud.frame)

    t = time.perf_counter()
    progress(f"locating {len(map_L.seams)} seams ({method})")
    ordered, voxels = voxel_order(dense_L, spec.voxel_m)
    ss = SeamScene(downsample(dense_L, spec.voxel_m), ordered, map_L, joints, table_z, voxels)
    estimates = locate_seams(ss, scenario, method, _workspace_L(P_L, crop), missing)
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
    )


def _placement_error(X_FM_nominal: FloatArray, X_FM: FloatArray) -> str:
    """How far the part was found from the placement given (a line for the progress log)."""
    X_d = invert(X_FM_nominal) @ X_FM
    shift_mm = 1000.0 * float(np.linalg.norm(X_FM[:3, 3] - X_FM_nominal[:3, 3]))
    angle_deg = float(np.degrees(np.arccos(np.clip((np.trace(X_d[:3, :3]) - 1.0) / 2.0, -1.0, 1.0))))
    return f"the part lies {shift_mm:.1f} mm and {angle_deg:.1f} deg from the placement given"


def _levelled(table: TablePlane, X_LF: FloatArray) -> TablePlane:
    """The table plane expressed in L."""
    return replace(table, normal=X_LF[:3, :3] @ table.normal)


def _aligned(
    P_L: FloatArray, above: np.ndarray, weldmap: WeldMap, X0: FloatArray, spec: PerceptionSpec
) -> tuple[FloatArray, Alignment, float] | None:
    """(X0, its alignment, the points it explains: fitness times the points of its crop), or None when the staged
    ICP from X0 fails."""
    crop = crop_mask(P_L, above, weldmap.transformed(X0, _FRAME))
    try:
        fit = align_map(weldmap.transformed(X0, _FRAME), Cloud(P_L[crop], _FRAME), spec)
    except AlignmentError:
        return None
    return X0, fit, fit.fitness * int(crop.sum())


def _global(
    P_L: FloatArray,
    above: np.ndarray,
    weldmap: WeldMap,
    table_z: float,
    viewpoint_L: FloatArray | None,
    rng: np.random.Generator,
    spec: PerceptionSpec,
) -> tuple[FloatArray, Alignment, float] | None:
    """The best global candidate (:mod:`cell.perception.align.placement`) as aligned by the staged ICP: the one
    that explains the most points of the cloud (:func:`_aligned`); None when none aligns. The height-image search
    first; FPFH + RANSAC only when none of its candidates fits well (on the real scans FPFH proposed the part
    turned by 180 degrees and took 5 s; the height image 0.3 s, right every time)."""
    best: tuple[FloatArray, Alignment, float] | None = None
    searches = (
        lambda: height_candidates(P_L[above], weldmap, table_z),
        lambda: fpfh_candidates(P_L[above], weldmap, table_z, viewpoint_L, rng),
    )
    for search in searches:
        for X0 in search():
            fit = _aligned(P_L, above, weldmap, X0, spec)
            if fit is not None and (best is None or fit[2] > best[2]):
                best = fit
        if best is not None and best[1].fitness >= POOR_FITNESS:
            break  # the height image's fit is good: FPFH is not asked
    return best


def _challenger(
    P_L: FloatArray, above: np.ndarray, weldmap: WeldMap, table_z: float, spec: PerceptionSpec, X_LM: FloatArray
) -> tuple[FloatArray, Alignment, float] | None:
    """The height image's best candidate unlike the fit ``X_LM`` (turned by more than DISTINCT_DEG or its parts'
    centre moved by more than DISTINCT_M), aligned; None when there is none or it does not align."""
    centre_M = np.mean([p.center for p in weldmap.parts], axis=0)

    def where(X: FloatArray) -> tuple[float, FloatArray]:
        return float(np.arctan2(X[1, 0], X[0, 0])), X[:3, :3] @ centre_M + X[:3, 3]

    yaw, c = where(X_LM)
    for X0 in height_candidates(P_L[above], weldmap, table_z):
        yaw0, c0 = where(X0)
        turn = abs((yaw0 - yaw + np.pi) % (2.0 * np.pi) - np.pi)
        if turn > np.radians(DISTINCT_DEG) or float(np.linalg.norm((c0 - c)[:2])) > DISTINCT_M:
            # Only a candidate that already explains a fair share of what the fit does is worth an ICP.
            if _explained(P_L, above, weldmap, X0) < PRESCORE * _explained(P_L, above, weldmap, X_LM):
                return None
            return _aligned(P_L, above, weldmap, X0, spec)
    return None


def _explained(P_L: FloatArray, above: np.ndarray, weldmap: WeldMap, X: FloatArray) -> float:
    """How many points of the crop about the map at X lie within PRESCORE_BAND_M of its surfaces."""
    map_L = weldmap.transformed(X, _FRAME)
    crop = crop_mask(P_L, above, map_L)
    samples, normals = sample_map(map_L, PRESCORE_BAND_M / 2.0, PRESCORE_BAND_M / 2.0)
    fit, _ = surface_fit(P_L[crop], samples, normals, PRESCORE_BAND_M, PRESCORE_BAND_M / 2.0)
    return fit * int(crop.sum())


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
    )


__all__ = ["POOR_FITNESS", "locate_cloud"]
