"""The part on a positioner welded (docs/positioner.md): capture and locate at home, the close-ups and the last
check there, the poses chosen for the located seams (closed form, grouped), then per pose: the positioner turns, the
located seams are carried by its kinematics, planned, gated and welded. No operator turn."""

from __future__ import annotations

import itertools
import time
from dataclasses import replace

import numpy as np

from cell.errors import CellError, ScenarioError
from cell.geometry import FloatArray, invert
from cell.pipeline.detect import Progress, detect, quiet, read_weldmap
from cell.pipeline.geometry import open_cell
from cell.pipeline.job import WeldJob
from cell.pipeline.positioned.carry import carried, drawn_estimates, posed_motion, posed_obstacles
from cell.pipeline.positioned.frames import axes_move_s, drawn_frames, seam_frames, truths_at
from cell.pipeline.positioned.run import GroupRun, PositionerRun
from cell.pipeline.positioned.sweep import clamped, clear_route
from cell.pipeline.records import Detection
from cell.positioner.payload import check_load, part_load
from cell.positioner.poses import PositionerPose
from cell.scenario import Scenario
from cell.station import SimStation
from cell.types import SeamStatus, WeldMap, WeldReason
from cell.types.positioner import TiltRotatePositioner

NOT_LOCATED = "not located at home"
SWEPT = "the positioner's move to its pose sweeps the part into the arm"
ROUNDS = 4  # poses chosen again at most this often for the seams refused at theirs (PB, then PA's two branches)


def weld_on_positioner(scenario: Scenario, job: WeldJob | None = None, *, progress: Progress = quiet) -> PositionerRun:
    """The whole part on ``robot.positioner`` (``job``: locator, noise, re-scan mode, gui as for ``cell weld``;
    ``job.execute`` False plans the poses and moves nothing)."""
    from cell.pipeline.curved.rescan import curves_rescanned
    from cell.pipeline.last_check import last_checked
    from cell.pipeline.outcomes import doubt
    from cell.pipeline.placeable import rescan_weldable
    from cell.positioner.poses import plan_poses, shoulder_reach

    t_all = time.perf_counter()
    job = job or WeldJob()
    sc = scenario.with_noise(job.noise) if job.noise else scenario
    if sc.robot.positioner is None:
        raise ScenarioError(f"scenario {sc.name!r} has no robot.positioner; valid: cell weld without one")
    pos = sc.robot.positioner.positioner(sc.X_WR)
    weldmap = read_weldmap(sc)
    density = sc.robot.positioner.part_density_kg_m3
    check_load(part_load(weldmap.transformed(X_F_M(sc, pos), "F").parts, pos, density), pos)
    with open_cell(sc, weldmap, gui=job.gui) as station:
        arm = station.arm
        if arm is None:
            raise ScenarioError(f"scenario {sc.name!r} has no robot to weld with: set robot.urdf and robot.X_WR")
        det = detect(sc, job.method, progress=progress, station=station, weldmap=weldmap)
        if det.error is not None:
            return PositionerRun(det, error=det.error)
        home = posed_motion(arm, det, posed_obstacles(det, pos, pos.home, np.eye(4)))
        mode = job.rescan or sc.rescan.mode
        rescan_s, q_now = 0.0, arm.q_scan
        if mode != "none" and job.execute:
            rs, det, _ = rescan_weldable(station, det, mode, motion=home, progress=progress)
            # the curves the mode chooses up close too, the positioner at home (the part where it was scanned)
            rs, det = curves_rescanned(station, det, rs, mode=mode, motion=home, progress=progress)
            if rs is not None:
                rescan_s, q_now = rs.motion_s, rs.q_end
        checked: dict[str, str] = {}
        if job.execute:
            det, more, fails = last_checked(station, det, motion=home, progress=progress)
            checked = {i: f"last check: {f}" for i, f in fails.items()}
            if more is not None:
                rescan_s += more.motion_s
                q_now = more.q_end
        # A seam against the clamping table at home is located up close at its pose (below); any other not found
        # is not welded.
        hidden = [e.id for e in det.estimates if e.status is SeamStatus.NOT_VISIBLE]
        unheld = {e.id: f"{NOT_LOCATED}: {e.reason or e.status.value}" for e in det.estimates
                  if e.status is not SeamStatus.FOUND and e.id not in hidden}  # fmt: skip
        unheld |= {e.id: "low_confidence" for e in det.estimates
                   if e.id not in unheld and e.id not in hidden and doubt(e, sc) is not None}  # fmt: skip
        unheld |= checked
        codes = {i: WeldReason.LAST_CHECK if i in checked else WeldReason.LOW_CONFIDENCE if r == "low_confidence"
                 else WeldReason.NOT_LOCATED for i, r in unheld.items()}  # fmt: skip
        located = [e.id for e in det.estimates if e.id not in unheld and e.id not in hidden]
        frames = seam_frames(det, pos, located) + drawn_frames(det, pos, hidden)
        centre, radius = arm.model.reach_bound("torch_tcp")
        reach = shoulder_reach(centre, radius)
        groups: list[GroupRun] = []
        axes, choose_s = pos.home, 0.0
        excluded: set[tuple[str, tuple[float, float]]] = set()
        on_plate, collision, sweep_s = clamped(det, pos), sc.motion.plan.collision, 0.0
        swept: dict[str, str] = {}  # seam id -> the move to its pose that sweeps the part into the arm
        choose_cpu_s = 0.0
        for _ in range(ROUNDS if job.execute else 1):
            t, t_cpu = time.perf_counter(), time.process_time()
            poses, why = plan_poses(pos, frames, reach, excluded, start=axes)
            choose_s += time.perf_counter() - t
            choose_cpu_s += time.process_time() - t_cpu
            unheld |= why
            progress(f"positioner: {len(poses)} poses for {sum(len(p.seams) for p in poses)} seams")
            refused: set[str] = set()
            for pose in poses:
                t = time.perf_counter()
                route, hit = clear_route(arm.model, q_now, on_plate, pos, axes, (pose.tilt, pose.rotate), collision)
                sweep_s += time.perf_counter() - t
                if hit is not None:  # the part swept into the arm: this pose is not taken, its seams try others
                    swept |= {i: f"{SWEPT}: {hit.describe()}" for i in pose.seams}
                    excluded |= {(i, (pose.tilt, pose.rotate)) for i in pose.seams}
                    refused |= set(pose.seams)
                    continue
                move_s = sum(axes_move_s(pos, s, e) for s, e in itertools.pairwise((axes, *route)))
                axes = (pose.tilt, pose.rotate)
                if not job.execute:
                    groups.append(GroupRun(pose, move_s, None, None, None, (), 0.0, via=route[:-1]))
                    continue
                g = replace(_weld_pose(station, det, weldmap, pos, pose, move_s, q_now, progress), via=route[:-1])
                groups.append(g)
                q_now = station.joint_state()
                # A seam the planner refused at this pose (a collision, out of reach) tries its other poses.
                for w in g.seams:
                    # Refused by the planner, or left doubtful by the close-up here (no view, a bound still over
                    # the tolerance): another pose may serve.
                    if w.code in (WeldReason.NOT_PLANNED, WeldReason.LOW_CONFIDENCE):
                        excluded.add((w.id, axes))
                        refused.add(w.id)
            # A seam hidden at home and refused in PB is asked in PA next: its bead faces up, the close-up looks
            # down at it as at home.
            frames = [replace(f, target="PA") if f.id in hidden else f for f in frames if f.id in refused]
            if not frames:
                break
        welded = {w.id for g in groups for w in g.seams if w.welded}
        unheld |= {i: why for i, why in swept.items() if i not in welded and i not in unheld}
        from cell.pipeline.coordinated import weld_curves_coordinated  # curved seams: the part turns while welded

        done, why_c = weld_curves_coordinated(station, det, pos, q_now, execute=job.execute, progress=progress)
        groups_c = [GroupRun(p, 0.0, None, None, ex, (w,), sum(a.plan_s for a in cw.arcs)) for p, w, cw, ex in done
                    if cw is not None]  # fmt: skip
        coordinated = tuple(a for _, _, cw, _ in done if cw is not None for a in cw.arcs)  # each arc its program
        unheld |= why_c
        codes |= {w.id: w.code or WeldReason.NOT_PLANNED for _, w, cw, _ in done if cw is None}
        timings = {**det.timings, "choose_poses_s": choose_s, "choose_poses_cpu_s": choose_cpu_s}
        timings["move_check_s"] = sweep_s
        timings["total_s"] = time.perf_counter() - t_all
        codes |= {i: WeldReason.NOT_PLANNED for i in unheld if i not in codes}  # no pose holds it
        return PositionerRun(det, (*groups, *groups_c), unheld, rescan_s, timings=timings, unheld_codes=codes,
                             coordinated=coordinated)  # fmt: skip


def _weld_pose(
    station: SimStation,
    det: Detection,
    weldmap: WeldMap,
    pos: TiltRotatePositioner,
    pose: PositionerPose,
    move_s: float,
    q_now: FloatArray,
    progress: Progress,
) -> GroupRun:
    """Turn the positioner to ``pose``, carry its seams, plan, gate and weld them."""
    from cell.gate import GateRefusedError
    from cell.pipeline.gated import plan_for
    from cell.pipeline.outcomes import doubt, seam_welds
    from cell.pipeline.playback import measurer
    from cell.pipeline.weld import execute

    sc = det.scenario
    progress(
        f"positioner: tilt {np.degrees(pose.tilt):+.1f} deg, rotate {np.degrees(pose.rotate):+.1f} deg "
        f"for {', '.join(pose.seams)}"
    )
    station.move_positioner(pose.tilt, pose.rotate)
    X_R = pos.move(pose.tilt, pose.rotate)
    X_WM = sc.X_WR @ X_R @ invert(sc.X_WR) @ sc.X_WM
    repeat = (pos.repeatability_m, pos.X_R_F(pose.tilt, pose.rotate)[:3, 3], pos.faceplate_radius_m)
    det_g = carried(det, pose.seams, X_R, truths_at(station, det, weldmap, X_WM), repeat)
    motion = posed_motion(station.arm, det_g, posed_obstacles(det_g, pos, (pose.tilt, pose.rotate), X_R))
    rescan_s = 0.0
    hidden = [e.id for e in det_g.estimates if e.status is SeamStatus.NOT_VISIBLE]
    # The seams whose bound the repeatability carried over the tolerance are located up close here too.
    grown = [e.id for e in det_g.estimates if e.status is SeamStatus.FOUND and doubt(e, sc) is not None]
    if hidden or grown:  # hidden: seen at home by no camera, located from the carried map's drawn seams
        from cell.pipeline.rescan import rescan_chosen

        progress(f"positioner: locating {', '.join(hidden + grown)} up close at this pose")
        rs, det_g, _ = rescan_chosen(
            station, drawn_estimates(det_g, hidden), "all", seam_ids=hidden + grown, motion=motion, progress=progress
        )
        if rs is not None:
            rescan_s, q_now = rs.motion_s, rs.q_end
    doubtful = {e.id for e in det_g.estimates if e.status is SeamStatus.FOUND and doubt(e, sc) is not None}
    t = time.perf_counter()
    plan = pre = ex = None
    error: CellError | None = None
    try:
        plan, pre, violations = plan_for(
            station, det_g, skip=doubtful, q_start=q_now, motion=motion, progress=progress, elsewhere=True
        )
        plan_s = time.perf_counter() - t
        if violations:
            why = f"the safety gate refused the pose's plan: {violations[0]} (+{len(violations) - 1} more)"
            raise GateRefusedError(why, violations=violations)
        ex = execute(station, plan, pre, progress=progress, measure=measurer(det_g, plan, pre, sc))
    except CellError as e:
        plan_s = time.perf_counter() - t
        error = e
    refused = f"not executed: {error.message}" if error is not None else ""
    seams = seam_welds(det_g, plan, ex, pre.duration if pre is not None else 0.0, refused, sc, True)
    return replace(GroupRun(pose, move_s, plan, pre, ex, seams, plan_s, rescan_s=rescan_s), error=error)


def X_F_M(sc: Scenario, pos: TiltRotatePositioner) -> FloatArray:
    """(4, 4): the map's frame M in the faceplate frame F at home (where the clamp holds the part)."""
    return np.asarray(invert(pos.X_R_F(*pos.home)) @ invert(sc.X_WR) @ sc.X_WM, dtype=float)
