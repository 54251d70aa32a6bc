"""The close-up re-scan's views planned without moving the arm: the views :func:`cell.pipeline.rescan.rescan_seams`
would take (the same planner, :func:`cell.rescan.viewpoint.plan_view`, with the same options, in the same order,
each from where the last one leaves the arm, a close-up serving the seams near it that it sees), nothing captured.
``cell preview`` plans them from its detection, ``cell scenario check`` from the map at its nominal place. Frame R."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from cell.errors import CellError
from cell.geometry import invert
from cell.pipeline.detect import table_z_R
from cell.pipeline.geometry import MotionScene
from cell.pipeline.records import Detection
from cell.pipeline.rescan import _SHARE_RADIUS, RescanMode
from cell.rescan.sight import occluders, seam_target
from cell.rescan.view_grid import ViewOptions, ViewTarget, sees, torch_axis_in_camera
from cell.rescan.viewpoint import plan_view
from cell.scenario import Scenario
from cell.station import Arm, Station
from cell.types import CameraIntrinsics, Joint, SeamEstimate, SeamStatus, WeldMap
from cell.types.rescan import PlannedCloseup
from cell.types.run import SeamWeld

if TYPE_CHECKING:
    from cell.motion.collision import CollisionChecker


def plan_closeups(
    arm: Arm,
    checker: CollisionChecker,
    weldmap_R: WeldMap,
    joints: Mapping[str, Joint],
    table_z: float,
    seam_ids: Sequence[str],
    intrinsics: CameraIntrinsics,
    view: ViewOptions,
    rng: np.random.Generator,
    *,
    estimates: Mapping[str, SeamEstimate] | None = None,
) -> tuple[PlannedCloseup, ...]:
    """One :class:`PlannedCloseup` per seam of ``seam_ids``, in that order: its view from where the last view left
    the arm (the scan configuration first), or why none works, or the earlier seam whose view sees it as well as a
    view of its own must.

    weldmap_R, joints, table_z : the map in R, its joints, the table top in R [m]. estimates : the fixed cameras'
    estimate of each seam (its found line is looked at; a seam not found gets the grazing fallback grid too, as
    in ``cell weld``); absent: the map's line, as a seam not found.
    """
    torch_C = torch_axis_in_camera(arm.model, view)
    targets: dict[str, ViewTarget] = {}
    found: dict[str, bool] = {}
    for sid in seam_ids:
        est = (estimates or {}).get(sid)
        found[sid] = est is not None and est.status is SeamStatus.FOUND
        t = seam_target(weldmap_R, joints[sid])
        targets[sid] = replace(t, p_start=est.p_start, p_end=est.p_end) if est is not None and found[sid] else t
    q = np.asarray(arm.q_scan, dtype=float)
    done: dict[str, PlannedCloseup] = {}
    for k, sid in enumerate(seam_ids):
        if sid in done:
            continue
        o = view if not found[sid] else replace(view, fallback_tilts_deg=())
        parts = occluders(weldmap_R, joints[sid])
        try:
            vp = plan_view(
                arm.model, checker, targets[sid], q, intrinsics, parts, table_z, rng=rng, q_via=arm.q_scan, options=o
            )
        except CellError as exc:
            done[sid] = PlannedCloseup(sid, reason=f"unreachable view: {exc.message}")
            continue
        done[sid] = PlannedCloseup(sid, vp)
        q = np.asarray(vp.q, dtype=float)
        for other in seam_ids[k + 1 :]:
            if other in done or float(np.linalg.norm(targets[other].mid - targets[sid].mid)) > _SHARE_RADIUS:
                continue
            seen = sees(
                vp.X_RC, targets[other], intrinsics, torch_C, occluders(weldmap_R, joints[other]), table_z, view
            )
            if seen is not None:
                done[other] = PlannedCloseup(other, served_by=sid)
    return tuple(done[s] for s in seam_ids)


def nominal_closeups(scenario: Scenario, weldmap_M: WeldMap, seam_ids: Sequence[str]) -> tuple[PlannedCloseup, ...]:
    """:func:`plan_closeups` of ``seam_ids`` on the map at its nominal place (``map.X_WM``), before any capture:
    what the close-up re-scan of ``cell weld`` would do for seams the fixed cameras do not find. ScenarioError
    without a robot or an eye-in-hand camera; IKError when the scan pose is out of reach."""
    from cell.motion.collision import CollisionChecker
    from cell.motion.collision.scene import cell_obstacles
    from cell.pipeline.geometry import robot_arm
    from cell.rescan.fusion import eye_in_hand_camera
    from cell.rescan.sight import camera_lens
    from cell.seams.joint import find_joints

    sc = scenario
    arm = robot_arm(sc)
    if arm is None:
        from cell.errors import ScenarioError

        raise ScenarioError(f"scenario {sc.name!r} has no robot to carry the camera: set robot.urdf")
    o = sc.rescan.closeup
    camera = eye_in_hand_camera(sc, o.camera)
    X_RM = invert(sc.X_WR) @ sc.X_WM
    weldmap_R = weldmap_M.transformed(X_RM, "R")
    obstacles = (*cell_obstacles(weldmap_R, sc.X_WR, sc.table.center_m, sc.table.size_m), *weldmap_R.fixtures)
    checker = CollisionChecker(arm.model, obstacles, sc.motion.plan.collision)
    table_z = table_z_R(sc)
    K = camera_lens(camera, sc.cameras[camera], o.view).intrinsics
    rng = sc.rng("rescan/view")
    return plan_closeups(arm, checker, weldmap_R, find_joints(weldmap_M), table_z, seam_ids, K, o.view, rng)


def preview_closeups(
    station: Station, det: Detection, mode: RescanMode, motion: MotionScene
) -> tuple[PlannedCloseup, ...]:
    """The close-ups ``cell weld`` would take after this detection, planned (``cell preview``): the seams
    :func:`cell.pipeline.rescan.rescan_chosen` would choose in ``mode`` (but those no torch can be placed on, as
    :func:`cell.pipeline.placeable.rescan_weldable` leaves out), their views from the scan configuration on. An
    escalation (a close-up that moves its seam) cannot be foreseen: it is not planned."""
    from cell.pipeline.placeable import unweldable
    from cell.rescan.fusion import eye_in_hand_camera, seams_to_rescan

    sc, arm = det.scenario, station.arm
    if arm is None or det.scene is None:
        return ()
    threshold = math.inf if mode == "all" else sc.rescan.confidence_threshold
    ids = seams_to_rescan(det.estimates, threshold, sc.rescan.max_sigma_m, sc.rescan.max_end_sigma_m)
    hopeless = unweldable(arm, det, ids, motion)
    ids = [i for i in ids if i not in hopeless]
    if not ids:
        return ()
    o = sc.rescan.closeup
    K = station.intrinsics(eye_in_hand_camera(sc, o.camera))
    ss = det.scene.seam_scene
    by_id = {e.id: e for e in det.estimates}
    rng = sc.rng("rescan/view")
    return plan_closeups(arm, motion.checker, ss.weldmap, ss.joints, ss.table_z, ids, K, o.view, rng, estimates=by_id)


def closeup_words(p: PlannedCloseup) -> str:
    """What the close-up re-scan would do for a seam, in words (for its reason)."""
    if p.served_by:
        return f"cell weld would locate it in the close-up of {p.served_by}"
    if p.viewpoint is None:
        return f"cell weld could not re-scan it: {p.reason}"
    vp = p.viewpoint
    x, y, z = (round(float(v) * 1000.0) for v in vp.X_RC[:3, 3])
    return (
        f"cell weld would re-scan it up close from ({x:.0f}, {y:.0f}, {z:.0f}) mm in R, {vp.distance_m * 1000:.0f} mm"
        f" away at {vp.incidence_deg[0]:.0f}/{vp.incidence_deg[1]:.0f} deg"
    )


def with_closeups(seams: Sequence[SeamWeld], planned: Sequence[PlannedCloseup]) -> tuple[SeamWeld, ...]:
    """The preview's seams with what the close-up would do added to the reason of each seam it would re-scan."""
    by_id = {p.seam_id: p for p in planned}
    return tuple(replace(w, reason=f"{w.reason}; {closeup_words(by_id[w.id])}") if w.id in by_id else w for w in seams)
