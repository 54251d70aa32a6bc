"""The close-up re-scan loop, once for ``cell weld`` and ``cell rescan``: plan a view, move, capture, locate, fuse,
escalate; the only place that drives the arm and its camera for it. One close-up serves every seam still waiting
that it sees as well as a view of its own would. Frames: R for every estimate and pose; metres, radians, seconds."""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Literal

import numpy as np

from cell.config.rescan import RescanOptions
from cell.errors import CellError, ScenarioError
from cell.geometry import FloatArray, invert, readonly
from cell.perception.calibration import PoseUncertainty, closeup_sigma
from cell.perception.lens import undistort
from cell.pipeline.detect import Progress, evaluate, pose_uncertainties, quiet
from cell.pipeline.geometry import MotionScene, motion_scene
from cell.pipeline.records import Detection, Scene
from cell.rescan.escalation import escalated, largest_shift_mm
from cell.rescan.fusion import (
    closeup_scenario,
    closeup_scene,
    estimate_sigma,
    eye_in_hand_camera,
    fuse,
    occluders,
    seams_to_rescan,
    view_target,
)
from cell.seams.base import SeamLocator
from cell.seams.checks import check_ends
from cell.seams.registry import part_tolerance_m
from cell.station import Arm, Station
from cell.types import DepthImage, SeamStatus
from cell.types.rescan import Rescan, SeamRescan, Viewpoint

if TYPE_CHECKING:
    from cell.motion.collision import CollisionChecker
    from cell.planning.failures import SeamFailure
    from cell.types.execution import Execution
    from cell.types.trajectory import Trajectory

RescanMode = Literal["low", "all"]


@dataclass
class _Run:
    """What every seam of one re-scan shares: the station, its arm, the checker, the locator, where the arm is."""

    station: Station
    arm: Arm
    detection: Detection
    options: RescanOptions
    camera: str
    checker: CollisionChecker
    locator: SeamLocator
    q: FloatArray
    moves: list[Trajectory] = field(default_factory=list)
    executions: list[Execution] = field(default_factory=list)
    stops: list[FloatArray] = field(default_factory=list)  # where the arm stopped, reached by ptp legs in turn

    def play(self, move: Trajectory) -> None:
        """Drive the arm (and a linear track's carriage, where ``move`` has E1) along ``move`` with the arc off,
        and record it."""
        arc = np.zeros(len(move.times), bool)
        self.executions.append(self.station.execute(move.times, move.q, arc, record_dt=0.02, bead=False, e1=move.e1))
        self.moves.append(move)
        self.q = np.asarray(move.q[-1], dtype=float)


def _rescan_one(run: _Run, seam_id: str, rng: np.random.Generator, pending: Sequence[str]) -> list[SeamRescan]:
    """Plan the view, move, capture, locate and fuse one seam (see :mod:`cell.rescan.fusion`), and every seam of
    ``pending`` the same close-up sees as well as a view of its own must (:func:`shared_by`): one image each."""
    from cell.rescan.viewpoint import plan_view

    t0 = time.perf_counter()
    o, det = run.options, run.detection
    base = _scene_of(det).seam_scene
    first = next(e for e in det.estimates if e.id == seam_id)
    seam = base.weldmap.seam(seam_id)
    # The grazing fallback grid only for a seam the fixed cameras did not find: a close-up is its only chance.
    view = o.view if first.status is not SeamStatus.FOUND else replace(o.view, fallback_tilts_deg=())
    try:
        vp = plan_view(
            run.arm.model,
            run.checker,
            view_target(base, seam, first),
            run.q,
            run.station.intrinsics(run.camera),
            occluders(base, seam_id),
            base.table_z,
            rng=rng,
            q_via=run.arm.q_scan,
            options=view,
        )
    except CellError as exc:
        reason = f"unreachable view: {exc.message}"
        return [SeamRescan(seam_id, first, None, first, 0.0, None, 0.0, time.perf_counter() - t0, reason)]
    run.play(vp.move)
    run.stops += [run.arm.q_scan, vp.q] if vp.via else [vp.q]
    image = undistort(run.station.capture_eye_in_hand(run.camera))  # a pinhole's image from here on
    out = [_closeup(run, seam_id, image, vp, vp.move.duration, t0)]
    for other, seen in shared_by(run, vp, pending):
        out.append(_closeup(run, other, image, seen, 0.0, time.perf_counter()))
    return out


def shared_by(run: _Run, vp: Viewpoint, pending: Sequence[str]) -> list[tuple[str, Viewpoint]]:
    """The seams of ``pending`` (with a first estimate or the map's line) that the close-up from ``vp`` sees as
    a view candidate of their own must (:func:`cell.rescan.view_grid.sees`: in the image with its margin,
    clear of the torch, at the incidence allowed, no part in the way), each with the view as it is for that seam
    (its distance and incidence; no move, tried 0). Only seams within ``_SHARE_RADIUS`` of the viewed one are
    tested."""
    from cell.rescan.view_grid import sees, torch_axis_in_camera

    det, o = run.detection, run.options
    base = _scene_of(det).seam_scene
    by_id = {e.id: e for e in det.estimates}
    K = run.station.intrinsics(run.camera)
    torch_C = torch_axis_in_camera(run.arm.model, o.view)
    here = view_target(base, base.weldmap.seam(vp.seam_id), by_id[vp.seam_id]).mid
    out = []
    for sid in pending:
        target = view_target(base, base.weldmap.seam(sid), by_id[sid])
        if float(np.linalg.norm(target.mid - here)) > _SHARE_RADIUS:
            continue
        inc = sees(vp.X_RC, target, K, torch_C, occluders(base, sid), base.table_z, o.view)
        if inc is not None:
            dist = float(np.linalg.norm(vp.X_RC[:3, 3] - target.mid))
            out.append((sid, replace(vp, seam_id=sid, distance_m=dist, incidence_deg=inc, tried=0)))
    return out


_SHARE_RADIUS = 0.25  # [m] seams whose midpoints lie farther from the viewed seam's are not looked for in its image


def _closeup(run: _Run, seam_id: str, image: DepthImage, vp: Viewpoint, motion_s: float, t0: float) -> SeamRescan:
    """Locate ``seam_id`` in the close-up ``image`` taken from ``vp`` and fuse it with its first estimate."""
    o, det = run.options, run.detection
    base = _scene_of(det).seam_scene
    first = next(e for e in det.estimates if e.id == seam_id)
    seam = base.weldmap.seam(seam_id)
    scene = closeup_scene(image, det.scenario.X_WR, seam, base, o, det.scenario.perception.voxel_m)
    n = len(scene.dense)
    if n < o.min_points:
        reason = f"nothing seen: {n} points near the seam in the close-up (needs {o.min_points})"
        return SeamRescan(seam_id, first, None, first, 0.0, vp, motion_s, time.perf_counter() - t0, reason, n)
    t = time.perf_counter()
    est = run.locator.locate(scene, seam, det.scenario.rng(f"rescan/{det.method}/{seam_id}"))
    est = replace(est, time_s=time.perf_counter() - t)
    est = check_ends(scene.weldmap, scene.joints, [est], part_tolerance_m(det.scenario, det.method))[0]
    X_RC = invert(det.scenario.X_WR) @ image.X_WC
    est = closeup_sigma(est, X_RC[:3, 3], pose_uncertainties(det.scenario).get(run.camera, PoseUncertainty()))
    fused, w = fuse(first, est, estimate_sigma(first), estimate_sigma(est), o.first_scale_m)
    reason = "" if w > 0.0 else f"close-up not used: {est.reason or est.status.value}"
    return SeamRescan(seam_id, first, est, fused, w, vp, motion_s, time.perf_counter() - t0, reason, n)


def _scene_of(det: Detection) -> Scene:
    if det.scene is None:
        raise ValueError("a re-scan needs a detection that kept its scene (pipeline.detect does)")
    return det.scene


def rescan_seams(
    station: Station,
    detection: Detection,
    seam_ids: Sequence[str],
    *,
    options: RescanOptions | None = None,
    motion: MotionScene | None = None,
    progress: Progress = quiet,
) -> Rescan:
    """Re-scan ``seam_ids`` up close with the eye-in-hand camera, in that order, and fuse (:mod:`cell.rescan.fusion`). A
    seam the close-up of an earlier one sees (:func:`shared_by`) is located in that image, with no view of its own
    (its record's ``motion_s`` is 0); the result lists every seam in the order asked.

    station : the running cell the detection came from. Its arm moves from where it is to each view (arc off)
    and, with ``options.return_to_scan``, back to the scan configuration when that move is free; the result says
    where it was left. A seam whose view is unreachable, or whose close-up sees nothing or finds no seam, keeps
    its first estimate and says why. Raises ScenarioError without an arm or an eye-in-hand camera, KeyError for
    a seam id the detection does not have, ValueError for a detection without its scene. motion : the run's
    obstacles and checker (built here when not given).
    """
    from cell.seams.registry import make_locator

    sc = detection.scenario
    o = options or sc.rescan.closeup
    arm = station.arm
    if arm is None:
        raise ScenarioError(f"scenario {sc.name!r} has no robot to carry the camera: set robot.urdf")
    camera = eye_in_hand_camera(sc, o.camera)
    _scene_of(detection)  # ValueError now, not after the arm has moved
    known = {e.id for e in detection.estimates}
    unknown = [s for s in seam_ids if s not in known]
    if unknown:
        raise KeyError(f"no seam {', '.join(unknown)} in the detection; seams: {', '.join(sorted(known))}")
    t_all = time.perf_counter()
    checker = (motion or motion_scene(arm, detection)).checker
    locator = make_locator(detection.method, closeup_scenario(sc, detection.method, o))
    run = _Run(station, arm, detection, o, camera, checker, locator, station.joint_state())
    run.stops.append(run.q)
    rng = sc.rng("rescan/view")
    done: dict[str, SeamRescan] = {}
    for k, sid in enumerate(seam_ids):
        if sid in done:  # seen in an earlier seam's close-up
            continue
        pending = [i for i in seam_ids[k + 1 :] if i not in done]
        progress(f"re-scan {k + 1}/{len(seam_ids)}: {sid}")
        got = _rescan_one(run, sid, rng, pending)
        if len(got) > 1:
            progress(f"the same close-up sees {', '.join(r.id for r in got[1:])}: located there too")
        done.update((r.id, r) for r in got)
    results = [done[sid] for sid in seam_ids]
    returned, note = back_to_scan(run)
    fused_by_id = {r.id: r.fused for r in results}
    estimates = tuple(fused_by_id.get(e.id, e) for e in detection.estimates)
    timings = {"rescan_s": time.perf_counter() - t_all}
    return Rescan(
        tuple(results), estimates, tuple(run.moves), tuple(run.executions), readonly(run.q), returned, note, timings
    )


def back_to_scan(run: _Run) -> tuple[bool, str]:
    """Take the arm back to the scan configuration after the close-ups (``options.return_to_scan``): straight when
    that is free, else back the way it came to the last view it can go straight from. Whether it is there, and
    why not."""
    from cell.motion.timing import ptp
    from cell.rescan.viewpoint import way_back

    arm, o = run.arm, run.options
    returned, note = bool(np.allclose(run.q, arm.q_scan)), ""
    if o.return_to_scan and not returned:
        back = way_back(arm.model, run.checker, run.stops, np.asarray(arm.q_scan, dtype=float), o.view.dt)
        if back is not None:
            run.play(back)
            returned = True
        else:
            direct = ptp(run.q, arm.q_scan, arm.model.limits, dt=o.view.dt)
            hit = run.checker.check_path(direct.q, direct.times)
            note = f"left at the last view: no way back to the scan pose is free ({hit.describe() if hit else ''})"
    elif not returned:
        note = "left at the last view (return_to_scan is off)"
    return returned, note


def rescanned(detection: Detection, rescan: Rescan) -> Detection:
    """The detection with the fused estimates in place and its metrics measured again against the truths."""
    metrics, summary = evaluate(rescan.estimates, detection.truths)
    timings = {**detection.timings, **rescan.timings}
    return replace(detection, estimates=rescan.estimates, metrics=metrics, summary=summary, timings=timings)


def rescan_detection(
    station: Station,
    det: Detection,
    mode: RescanMode,
    *,
    seam_ids: Sequence[str] | None = None,
    motion: MotionScene | None = None,
    progress: Progress = quiet,
) -> tuple[Rescan, Detection]:
    """Re-scan the seams worth a closer look with the eye-in-hand camera and return the detection with the fused
    estimates (:func:`rescan_chosen` leaving no seam out): ``cell rescan``'s re-scan.

    mode : ``low``: the seams below ``rescan.confidence_threshold``, those whose bound (``rescan.bound_sigmas``
    sigma) exceeds ``rescan.weld_tolerance_mm`` or whose end bound exceeds ``rescan.end_tolerance_mm``, and those
    not found, escalated (:mod:`cell.rescan.escalation`); ``all``: every visible seam.
    seam_ids : these seams instead of the mode's choice (``cell rescan --seams``).
    """
    rs, after, _ = rescan_chosen(station, det, mode, seam_ids=seam_ids, motion=motion, progress=progress)
    assert rs is not None  # None only when a seam was left out
    return rs, after


LeaveOut = Callable[[Detection, Sequence[str]], "dict[str, SeamFailure]"]  # of these seams, those not to re-scan -> why


def rescan_chosen(
    station: Station,
    det: Detection,
    mode: RescanMode,
    *,
    seam_ids: Sequence[str] | None = None,
    leave_out: LeaveOut | None = None,
    motion: MotionScene | None = None,
    progress: Progress = quiet,
) -> tuple[Rescan | None, Detection, dict[str, SeamFailure]]:
    """The one re-scan path of ``cell weld`` and ``cell rescan``: the mode's seams (or ``seam_ids``) but those
    ``leave_out`` names, re-scanned up close; then, in mode ``low``, the escalation: a close-up that moved its seam
    by more than ``rescan.escalate_mm`` (:func:`cell.rescan.escalation.largest_shift_mm`) re-scans every other
    visible seam too, but those left out (when any seam was left out of the choice, ``leave_out`` is asked about
    the others as well).

    Returns the re-scan (None when ``low`` chose only seams left out), the detection after it and the seams left
    out (id -> why). mode, seam_ids: as :func:`rescan_detection`.
    """
    sc = det.scenario
    if seam_ids is not None:
        ids = list(seam_ids)
    else:
        threshold = math.inf if mode == "all" else sc.rescan.confidence_threshold
        ids = seams_to_rescan(det.estimates, threshold, sc.rescan.max_sigma_m, sc.rescan.max_end_sigma_m)
    left = leave_out(det, ids) if leave_out is not None else {}
    ids = [i for i in ids if i not in left]
    if left and not ids and mode != "all":
        return None, det, left
    progress(f"re-scanning {len(ids)} seams up close with the eye-in-hand camera")
    rs = rescan_seams(station, det, ids, motion=motion, progress=progress)
    after = rescanned(det, rs)
    shift_mm = largest_shift_mm(rs)
    rest = [i for i in seams_to_rescan(after.estimates, math.inf) if i not in ids and i not in left]
    if mode == "all" or shift_mm <= sc.rescan.escalate_mm or not rest:
        return rs, after, left
    if left and leave_out is not None:
        left = {**left, **leave_out(after, rest)}
        rest = [i for i in rest if i not in left]
        if not rest:
            return rs, after, left
    progress(
        f"a close-up moved its seam {shift_mm:.2f} mm from the fixed cameras' estimate: re-scanning the other"
        f" {len(rest)} seams too"
    )
    more = rescan_seams(station, after, rest, motion=motion, progress=progress)
    return escalated(rs, more, shift_mm), rescanned(after, more), left
