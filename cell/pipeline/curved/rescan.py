"""The close-up re-scan of the located curves too uncertain to weld, on the straight seams' loop
(:mod:`cell.pipeline.rescan`: its run, views, moves and way back): the stretch with the largest sigma looked at
first (:func:`cell.rescan.curve_views.worst_first`), the curve re-located from every close-up so far and fused
with the fixed cameras' (:mod:`cell.rescan.curve_fusion`), until it passes or the budget is spent
(docs/curves.md section 6). Frames: R; metres, seconds."""

from __future__ import annotations

import time
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from cell.geometry import FloatArray, invert, readonly
from cell.perception.calibration import PoseUncertainty
from cell.pipeline.curved.choice import chosen_curves, doubtful_curves
from cell.pipeline.curved.views import Carriage, planned_view
from cell.pipeline.detect import Progress, pose_uncertainties, quiet
from cell.pipeline.geometry import MotionScene
from cell.pipeline.records import Detection
from cell.pipeline.rescan import RescanMode, _Run, back_to_scan
from cell.types import DepthImage, SeamStatus
from cell.types.curve_estimate import CurveEstimate
from cell.types.rescan import CurveRescan, Rescan, Viewpoint

if TYPE_CHECKING:
    from collections.abc import Sequence

    from cell.rescan.view_grid import ViewTarget
    from cell.station import Station
    from cell.types import CurvedSeam, Part, SeamScene
    from cell.types.rescan import PlannedCloseup

MAX_VIEWS = 4  # close-ups taken of one curve at most (each a move, a capture and a re-location)
MAX_TRIES = 6  # stretches tried at most (a stretch no view reaches costs the planner's search, not a move)
MIN_GAIN = 0.1  # a close-up that lowers the worst sample's sigma by less than this share ends the curve's re-scan
TRIED_M = 0.02  # [m] a stretch whose middle lies this near one tried already (or half its chord) is not tried again


def rescan_curves(
    station: Station,
    det: Detection,
    *,
    motion: MotionScene,
    progress: Progress = quiet,
    curves: Sequence[CurveEstimate] | None = None,
) -> tuple[Rescan | None, Detection]:
    """Every curve of ``curves`` (None: :func:`doubtful_curves`) re-scanned up close with the eye-in-hand camera and
    re-located (see the module docstring); the re-scan (its moves, a :class:`CurveRescan` per curve; None when there
    was no such curve, or no arm, scene or eye-in-hand camera) and the detection with the fused curves and their
    errors measured again. A curve whose close-ups leave it over the tolerance keeps the better estimate and is
    refused at the gate as before; one already within it (``cell rescan --all``) is looked at once, worst stretch
    first. On a linear track the carriage may move for a view (:mod:`cell.pipeline.curved.views`) and is back at
    E1 = 0 at the end (PlanError if it cannot be)."""
    from cell.rescan.fusion import eye_in_hand_camera
    from cell.seams.registry import make_locator

    sc, arm = det.scenario, station.arm
    curves = doubtful_curves(det) if curves is None else list(curves)
    eye = [n for n, c in sc.cameras.items() if c.mount == "eye_in_hand"]
    if not curves or arm is None or det.scene is None or not eye:
        return None, det
    o = sc.rescan.closeup
    t0 = time.perf_counter()
    run = _Run(
        station, arm, det, o, eye_in_hand_camera(sc, o.camera), motion.checker, make_locator(det.method, sc),
        station.joint_state(),
    )  # fmt: skip
    run.stops.append(run.q)
    rng = sc.rng("rescan/curve-view")
    carriage = Carriage(sc.robot.track.track(sc.X_WR)) if sc.robot.track is not None else None
    done = [_rescan_curve(run, c, rng, progress, carriage) for c in curves]
    if carriage is not None:
        carriage.home(run)
    returned, note = back_to_scan(run)
    fused = {r.id: r.after for r in done}
    estimates = tuple(fused.get(c.id, c) for c in det.curve_estimates)
    metrics = dict(det.curve_metrics)
    from cell.seams.curved.metrics import curve_error

    for c in estimates:
        if c.id in fused and c.status is SeamStatus.FOUND and c.id in det.curve_truths:
            metrics[c.id] = curve_error(c, np.asarray(det.curve_truths[c.id]))
    timings = {"rescan_s": time.perf_counter() - t0}
    rs = Rescan(
        (), det.estimates, tuple(run.moves), tuple(run.executions), readonly(run.q), returned, note, timings,
        curves=tuple(done),
    )  # fmt: skip
    return rs, replace(det, curve_estimates=estimates, curve_metrics=metrics)


def curves_rescanned(
    station: Station,
    det: Detection,
    rs: Rescan | None,
    *,
    mode: RescanMode,
    motion: MotionScene,
    progress: Progress = quiet,
) -> tuple[Rescan | None, Detection]:
    """:func:`rescan_curves` after the straight seams' re-scan ``rs`` on the curves ``mode`` chooses (``low``:
    :func:`doubtful_curves`; ``all``: every located curve too, as ``cell rescan --all``): one re-scan record of
    both (the arm where the curves' close-ups left it) and the detection after both."""
    from cell.pipeline.last_check import joined

    curves = chosen_curves(det, mode)[0] if mode == "all" else None
    more, after = rescan_curves(station, det, motion=motion, progress=progress, curves=curves)
    return joined(rs, more), after


def preview_curve_closeups(
    station: Station,
    det: Detection,
    motion: MotionScene,
    straight: Sequence[PlannedCloseup] = (),
    mode: RescanMode = "low",
) -> tuple[PlannedCloseup, ...]:
    """The first close-up ``cell weld`` would take of each curve ``mode`` chooses (:func:`curves_rescanned`),
    planned and not taken (``cell preview``): the view of its worst stretch (for a curve no fixed camera sees, where
    the aligned map draws it) from where the last view leaves the arm (the scan configuration, or the last of the
    straight seams' planned close-ups ``straight`` where the re-scan does not return), as :func:`rescan_curves`
    plans it; or why none works. The close-ups after the first depend on what it sees: not planned."""
    from cell.rescan.curve_views import worst_first
    from cell.rescan.fusion import eye_in_hand_camera
    from cell.types.rescan import PlannedCloseup

    sc, arm = det.scenario, station.arm
    curves = chosen_curves(det, mode)[0] if mode == "all" else doubtful_curves(det)
    if not curves or arm is None or det.scene is None or not any(c.mount == "eye_in_hand" for c in sc.cameras.values()):
        return ()
    o, base, limit = sc.rescan.closeup, det.scene.seam_scene, sc.rescan.max_sigma_m
    K = station.intrinsics(eye_in_hand_camera(sc, o.camera))
    views = [p.viewpoint for p in straight if p.viewpoint is not None and not o.return_to_scan]
    rng, q = sc.rng("rescan/curve-view"), np.asarray(views[-1].q if views else arm.q_scan, dtype=float)
    carriage = Carriage(sc.robot.track.track(sc.X_WR)) if sc.robot.track is not None else None
    out: list[PlannedCloseup] = []
    for c in curves:
        start = _start(base, c)
        if start is None:
            continue
        _, first, parts, shared = start
        if float(shared.max()) > limit:
            out.append(PlannedCloseup(c.id, reason=_facets_over(float(shared.max()), limit)))
            continue
        vp, why = None, "no stretch over the tolerance to look at"
        tried: list[FloatArray] = []
        for target in worst_first(first, limit):
            if len(tried) == MAX_TRIES:
                break
            if _near_tried(target, tried):
                continue
            tried.append(target.mid)
            vp, why = planned_view(arm, motion.checker, target, q, K, parts, base.table_z, rng, o, carriage)
            if vp is not None:
                break
        out.append(PlannedCloseup(c.id, vp, reason="" if vp is not None else f"unreachable view: {why}"))
        q = np.asarray(vp.q, dtype=float) if vp is not None else q
        if vp is not None and carriage is not None:  # the weld's carriage stays there for the next curve
            carriage.e1 = vp.e1_m
    return tuple(out)


def _rescan_curve(
    run: _Run, found: CurveEstimate, rng: np.random.Generator, progress: Progress, carriage: Carriage | None = None
) -> CurveRescan:
    """One curve's close-ups (see the module docstring): the fused curve, its reason saying what the re-scan did. A
    curve not found (``found`` NOT_FOUND) is looked at where the aligned map draws it and located from the close-ups
    alone, or stays not found. A curve within the tolerance already is looked at along its whole length."""
    from cell.perception.lens import undistort
    from cell.rescan.curve_fusion import closeup_curve_scene, fuse_curve, relocate
    from cell.rescan.curve_views import worst_first

    det, o = run.detection, run.options
    assert det.scene is not None
    base = det.scene.seam_scene
    start = _start(base, found)
    if start is None:
        return CurveRescan(found.id, found, found, reason=NOTHING_TO_START)
    seam, first, parts, shared = start
    unseen = found.status is not SeamStatus.FOUND
    limit = det.scenario.rescan.max_sigma_m
    look = limit if unseen or first.sigma_max_m > limit else 0.0  # the stretches over it; within it: every one
    K = run.station.intrinsics(run.camera)
    u = pose_uncertainties(det.scenario).get(run.camera, PoseUncertainty())
    if float(shared.max()) > limit:
        why = _facets_over(float(shared.max()), limit)
        return CurveRescan(found.id, found, replace(found, reason=why), reason=why)
    images: list[DepthImage] = []
    views: list[Viewpoint] = []
    moves_before = len(run.moves)
    tried: list[FloatArray] = []
    cal = 0.0
    best, weight, why = first, 0.0, ""
    while len(images) < MAX_VIEWS and len(tried) < MAX_TRIES:
        targets = [t for t in worst_first(best, look) if not _near_tried(t, tried)]
        if not targets:
            break
        target = targets[0]
        tried.append(target.mid)
        progress(f"re-scan curve {first.id}: close-up {len(images) + 1} of the stretch at sigma "
                 f"{_worst_mm(best, target):.2f} mm")  # fmt: skip
        vp, why_not = planned_view(run.arm, run.checker, target, run.q, K, parts, base.table_z, rng, o, carriage)
        if vp is not None and carriage is not None and vp.e1_m != carriage.e1:  # the carriage abreast of the stretch
            moved = carriage.to(run, vp.e1_m)
            vp, why_not = (vp, "") if not moved else (None, f"from E1 = {vp.e1_m * 1000:.0f} mm on the track: {moved}")
        if vp is None:
            why = why_not
            continue
        run.play(vp.move)
        run.stops += [run.arm.q_scan, vp.q] if vp.via else [vp.q]
        views.append(vp)
        images.append(undistort(run.station.capture_eye_in_hand(run.camera)))
        X_RC = invert(det.scenario.X_WR) @ images[-1].X_WC
        cal = max(cal, float(np.sqrt(2.0)) * u.sigma_at(float(np.linalg.norm(target.mid - X_RC[:3, 3]))))
        scene = closeup_curve_scene(images, det.scenario.X_WR, np.asarray(first.p_RS), base, o.crop_margin_m)
        closeup = relocate(scene, seam, cal)
        if closeup.status is not SeamStatus.FOUND:
            why = f"close-ups: {closeup.reason}"
            continue
        before = best.sigma_max_m
        best, weight = (closeup, 1.0) if unseen else fuse_curve(first, closeup, shared)
        if best.sigma_max_m <= limit:
            break
        if best.sigma_max_m > (1.0 - MIN_GAIN) * before:
            why = f"a close-up lowered its worst sigma by less than {MIN_GAIN:.0%}: no more"
            break
    motion_s = sum(m.duration for m in run.moves[moves_before:])  # its views', the carriage's and the ways back
    done = f"re-scanned up close ({len(images)} close-ups, weight {weight:.2f}; sigma up to "
    done += f"{first.sigma_max_m * 1000:.2f} -> {best.sigma_max_m * 1000:.2f} mm)"
    if unseen:
        if weight == 0.0:  # no close-up located it: it stays not found, the reason says what was tried
            why = f"looked for up close: {why or 'no stretch to look at'}"
            after = replace(found, reason="; ".join(r for r in (found.reason, why) if r))
            return CurveRescan(found.id, found, after, tuple(views), 0.0, motion_s, reason=why)
        done = f"located from {len(images)} close-ups alone (sigma up to {best.sigma_max_m * 1000:.2f} mm)"
    why = why if best.sigma_max_m > limit or not images else ""  # within it: why no close-up was taken, if none
    after = replace(best, reason="; ".join(r for r in (done, why, found.reason) if r))
    return CurveRescan(found.id, found, after, tuple(views), weight, motion_s, reason=why)


NOTHING_TO_START = "not re-scanned: no two parts hold it, or the map draws no curve to look at"


def _start(
    base: SeamScene, found: CurveEstimate
) -> tuple[CurvedSeam, CurveEstimate, tuple[Part, ...], FloatArray] | None:
    """What a curve's close-ups start from: its seam in the map, the estimate they improve (a curve not found:
    where the aligned map draws it), the other parts (that may stand in a view's way) and each sample's sigma no
    close-up takes away (half the facets' sagitta, :func:`cell.rescan.curve_fusion.shared_sigma`); None: nothing
    to start from."""
    from cell.rescan.curve_fusion import facet_floor_m, shared_sigma
    from cell.seams.curved.drawn import drawn_estimate

    seam = next(s for s in base.weldmap.curved if s.id == found.id)
    first = drawn_estimate(base.weldmap, seam) if found.status is not SeamStatus.FOUND else found
    if first is None or seam.joint is None:
        return None
    own = (seam.joint.abutting, seam.joint.receiving)
    parts = tuple(p for p in base.weldmap.parts if p.name not in own)
    return seam, first, parts, shared_sigma(first, facet_floor_m(seam, base.weldmap))


def _facets_over(floor_m: float, limit_m: float) -> str:
    """Why a curve is not re-scanned: its facets alone put a sample's sigma ``floor_m`` over ``limit_m`` [m]."""
    why = f"not re-scanned: its round is drawn with flat facets, half their sagitta ({floor_m * 1000:.2f} mm here) is"
    return f"{why} over the tolerance's sigma ({limit_m * 1000:.2f} mm) whatever a close-up sees"


def _near_tried(target: ViewTarget, tried: Sequence[FloatArray]) -> bool:
    """Whether the stretch ``target``'s middle lies near one tried already: within :data:`TRIED_M`, or half its
    chord where that is shorter (round a thin tube every stretch's middle lies within 20 mm of every other's)."""
    near = min(TRIED_M, 0.5 * float(np.linalg.norm(target.p_end - target.p_start)))
    return any(float(np.linalg.norm(target.mid - m)) <= near for m in tried)


def _worst_mm(est: CurveEstimate, target: ViewTarget) -> float:
    """The largest sigma [mm] of ``est``'s samples within the stretch ``target`` looks at (its chord's box)."""
    p = np.asarray(est.p_RS)
    a, b = np.asarray(target.p_start), np.asarray(target.p_end)
    lo, hi = np.minimum(a, b) - 1e-3, np.maximum(a, b) + 1e-3
    inside = np.all((p >= lo) & (p <= hi), axis=1)
    s = np.asarray(est.sigma_m)[inside] if inside.any() else np.asarray(est.sigma_m)
    return float(s.max()) * 1000.0
