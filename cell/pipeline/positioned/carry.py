"""A detection made at the positioner's home carried into a group's pose (docs/positioner.md, "Sensing"): the
located seams and the aligned map moved by the kinematics' nominal motion, their sigmas grown by the positioner's
repeatability; the truths are the station's where the part now lies. The clouds stay where they
were taken: nothing after location reads them."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import replace

import numpy as np

from cell.geometry import FloatArray, transform_points
from cell.pipeline.geometry import MotionScene
from cell.pipeline.records import Detection
from cell.pipeline.restrict import restricted
from cell.positioner.bodies import positioner_parts
from cell.types import Part, SeamEstimate, SeamStatus
from cell.types.positioner import TiltRotatePositioner

NO_TABLE_Z = -100.0  # [m] the clamping table tilts with the part: no horizontal table top bounds the seams
CLAMP_TABLE = "CLAMP_TABLE"  # the clamping table as an obstacle (not the planner's horizontal TABLE)


def carried_estimate(
    e: SeamEstimate, X_R: FloatArray, repeat_m: float, centre_R: FloatArray | None = None, radius_m: float = math.inf
) -> SeamEstimate:
    """One located seam moved by X_R (4, 4) in R, its sigma across and its ends' sigmas along grown by the
    positioner's repeatability (root sum of squares). The repeatability is a point's on the faceplate's rim
    (``radius_m`` from its centre ``centre_R`` (3,), after the move): a seam further out sees its turning part
    scaled by the lever, ``repeat_m`` times the farther end's distance over the radius (at least 1)."""
    if e.status is not SeamStatus.FOUND:
        return e
    ends = transform_points(X_R, np.stack([e.p_start, e.p_end]))
    if centre_R is not None:
        repeat_m *= max(1.0, float(np.max(np.linalg.norm(ends - np.asarray(centre_R), axis=1))) / radius_m)
    grow = lambda s: math.hypot(s, repeat_m) if math.isfinite(s) else s  # noqa: E731
    return replace(
        e,
        p_start=ends[0],
        p_end=ends[1],
        sigma_m=grow(e.sigma_m),
        end_sigma_m=(grow(e.end_sigma_m[0]), grow(e.end_sigma_m[1])),
    )


def carried(
    det: Detection,
    ids: list[str] | tuple[str, ...],
    X_R_nominal: FloatArray,
    truths: Mapping[str, tuple[FloatArray, FloatArray]],
    repeat: tuple[float, FloatArray, float],
) -> Detection:
    """The detection of the seams ``ids`` carried by the nominal motion X_R_nominal (4, 4) in R; ``truths`` the
    true seams where the part now lies (the station's, for measuring only); ``repeat``: the repeatability [m],
    the faceplate's centre (3,) in R after the move and its radius [m] (:func:`carried_estimate`)."""
    det = restricted(det, ids)
    X = np.asarray(X_R_nominal, dtype=float)
    estimates = tuple(carried_estimate(e, X, *repeat) for e in det.estimates)
    truths = {k: v for k, v in truths.items() if k in set(ids)}
    weldmap_R = det.weldmap_R.transformed(X, "R")
    scene = det.scene
    if scene is not None:
        seam_scene = replace(scene.seam_scene, weldmap=weldmap_R, table_z=NO_TABLE_Z, cache={})
        scene = replace(scene, seam_scene=seam_scene, X_RM=X @ scene.X_RM)
    return replace(det, estimates=estimates, truths=truths, weldmap_R=weldmap_R, scene=scene)


DRAWN_SIGMA_M = 0.005  # [m] a seam placed from the aligned map's drawing only: the build tolerance's order


def drawn_estimates(det: Detection, ids: list[str]) -> Detection:
    """The detection with the seams ``ids`` placed where the (carried) aligned map draws them: found, confidence
    0 and a sigma of the build tolerance's order, so the close-up re-scan locates them (never welded as drawn: the
    weld gate refuses such a sigma)."""
    keep = set(ids)
    drawn = {s.id: s for s in det.weldmap_R.seams if s.id in keep}
    estimates = tuple(
        SeamEstimate(
            e.id,
            SeamStatus.FOUND,
            "placed from the aligned map: to be located up close",
            drawn[e.id].p_start,
            drawn[e.id].p_end,
            confidence=0.0,
            sigma_m=DRAWN_SIGMA_M,
            end_sigma_m=(DRAWN_SIGMA_M, DRAWN_SIGMA_M),
        )
        if e.id in drawn
        else e
        for e in det.estimates
    )
    return replace(det, estimates=estimates)


def posed_obstacles(
    det: Detection, pos: TiltRotatePositioner, axes: tuple[float, float], X_R_nominal: FloatArray
) -> tuple[Part, ...]:
    """What the arm must miss at a group's pose, in R: the carried map's parts and fixtures, the clamping table
    (the scenario's table, on the faceplate) moved with them, and the positioner's own bodies."""
    from cell.geometry import invert, make_pose
    from cell.types import Box

    sc = det.scenario
    X_RW = invert(sc.X_WR)
    table = Box(np.asarray(X_R_nominal) @ X_RW @ make_pose(p=sc.table.center_m), np.asarray(sc.table.size_m))
    return (
        *det.weldmap_R.parts,
        *det.weldmap_R.fixtures,
        Part(CLAMP_TABLE, table),
        *positioner_parts(pos, *axes),
    )


def posed_motion(arm: object, det: Detection, obstacles: tuple[Part, ...]) -> MotionScene:
    """The collision checker on a pose's obstacles."""
    from cell.motion.collision import CollisionChecker

    return MotionScene(obstacles, CollisionChecker(arm.model, obstacles, det.scenario.motion.plan.collision))  # type: ignore[attr-defined]
