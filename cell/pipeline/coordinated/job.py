"""The located curved seams of a part on a positioner welded by coordinated motion (docs/positioner.md,
"Coordinated motion"): each one too uncertain refused as anywhere else, the others planned with the positioner
turning the part (:func:`cell.coordinated.plan.plan_coordinated`), played in the simulator and measured against
the true curve the part carries. Frames: R the robot base at the positioner's home [m]; [rad]."""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from cell.coordinated.record import CoordinatedWeld
from cell.errors import MotionError, PlanError
from cell.geometry import FloatArray
from cell.pipeline.records import Detection
from cell.positioner.poses import PositionerPose
from cell.station.sim import SimStation
from cell.types import Part, SeamStatus
from cell.types.curve_estimate import CurveEstimate
from cell.types.execution import Execution
from cell.types.positioner import TiltRotatePositioner, WeldPosition
from cell.types.run import SeamWeld, WeldReason, in_part_text

if TYPE_CHECKING:
    from cell.config.motion import PlanOptions
    from cell.coordinated.gate import MovingScene
    from cell.motion.robot import RobotModel
    from cell.process.torch import WeldProcess
    from cell.types.procedure import WeldProcedure


def _pa_probe(pos: TiltRotatePositioner, c: CurveEstimate, cw_axes: FloatArray) -> CurveEstimate:
    """The curve as the torch sees it: every sample carried to where the positioner holds it under the torch (its
    bisector up), for choosing the weld procedure of a weld made in PA all round."""
    from dataclasses import replace

    from cell.coordinated.axes import CurveInF, knots_in_R, pa_axes

    X_FR = np.linalg.inv(pos.X_R_F(*pos.home))
    R, o = X_FR[:3, :3], X_FR[:3, 3]
    curve = CurveInF(c.p_RS @ R.T + o, c.tangent_R @ R.T, c.n_abutting_R @ R.T, c.n_receiving_R @ R.T,
                     np.zeros(len(c.p_RS)))  # fmt: skip
    axes = pa_axes(pos, curve, 1 if cw_axes[0] >= 0.0 else -1)
    if axes is None:
        return c
    p, _, na, nb = knots_in_R(pos, curve, axes)
    return replace(c, p_RS=p, n_abutting_R=na, n_receiving_R=nb, closed=False)


def _carried(det: Detection) -> list[Part]:
    """What the faceplate carries, in R at home: the aligned map's parts and fixtures and the clamping table."""
    from cell.geometry import invert, make_pose
    from cell.types import Box

    sc = det.scenario
    table = Box(invert(sc.X_WR) @ make_pose(p=sc.table.center_m), np.asarray(sc.table.size_m))
    return [*det.weldmap_R.parts, *det.weldmap_R.fixtures, Part("CLAMP_TABLE", table)]


def weld_curves_coordinated(
    station: SimStation,
    det: Detection,
    pos: TiltRotatePositioner,
    q_now: FloatArray,
    *,
    execute: bool = True,
    progress: Callable[[str], None] = lambda _: None,
    refuse_doubtful: bool = True,
) -> tuple[list[tuple[PositionerPose, SeamWeld, CoordinatedWeld | None, Execution | None]], dict[str, str]]:
    """Each found curve of ``det`` (located at the positioner's home): (its pose record, its weld, its coordinated
    motion, its execution) for those planned; curve id -> why not (a sentence) for the others, their codes in the
    returned welds. ``refuse_doubtful`` False is a study's (benchmarks/bench_coordinated.py): a curve the weld
    gate refuses is planned and welded all the same, its refusal kept in its weld's reason; never the cell's."""
    from cell.coordinated.gate import MovingScene
    from cell.pipeline.coordinated.play import joined, play_arcs, quality
    from cell.pipeline.curved.welds import curve_doubt
    from cell.pipeline.placeable import curve_procedures_for
    from cell.process.torch import WeldProcess
    from cell.types.plan import SeamProcedure

    sc = det.scenario
    arm = station.arm
    assert arm is not None
    out: list[tuple[PositionerPose, SeamWeld, CoordinatedWeld | None, Execution | None]] = []
    why: dict[str, str] = {}
    found = [c for c in det.curve_estimates if c.status is SeamStatus.FOUND]
    if not found:
        return out, why
    process = WeldProcess.from_spec(sc.process, sc.robot.stickout_mm)
    opt: PlanOptions = sc.motion.plan
    carried = _carried(det)
    scene = MovingScene.build(arm.model, pos, carried, opt.collision)
    for c in found:
        doubt = curve_doubt(c, sc)
        if doubt is not None and refuse_doubtful:
            why[c.id] = doubt.detail
            out.append((PositionerPose(*pos.home, (), {}), SeamWeld(c.id, False, False, doubt.detail, code=doubt.code),
                        None, None))  # fmt: skip
            continue
        progress(f"coordinated: planning {c.id} with the positioner turning the part")
        t0 = time.perf_counter()
        try:
            probe = _pa_probe(pos, c, np.array([1.0]))
            sel = curve_procedures_for(sc, det.weldmap_R, [probe]).get(c.id)
            proc = sel.procedure if isinstance(sel, SeamProcedure) else None
            cw = _planned(arm.model, pos, c, process, opt, scene, np.asarray(q_now), sc.rng("coordinated"), proc,
                          progress)  # fmt: skip
        except MotionError as e:
            why[c.id] = e.message
            pose = PositionerPose(*pos.home, (), {})
            out.append((pose, SeamWeld(c.id, False, False, e.message, code=WeldReason.NOT_PLANNED), None, None))
            continue
        wp = WeldPosition("PA" if cw.in_position else "PB", float(np.max(np.abs(cw.slope_deg))),
                          float(cw.rotation_deg[int(np.argmax(np.abs(cw.rotation_deg - 180.0)))]), "PA",
                          cw.in_position)  # fmt: skip
        pose = PositionerPose(float(cw.knot_axes[0, 0]), float(cw.knot_axes[0, 1]), (c.id,), {c.id: wp})
        progress(
            f"coordinated: {c.id} planned in {time.perf_counter() - t0:.1f} s: tilt "
            f"{math.degrees(cw.knot_axes[0, 0]):+.1f} deg, rotate {math.degrees(cw.knot_axes[0, 1]):+.1f} to "
            f"{math.degrees(cw.knot_axes[-1, 1]):+.1f} deg, arc {cw.arc_s:.1f} s of {cw.duration:.1f} s"
            + "".join(
                f"; then {math.degrees(a.knot_axes[0, 1]):+.1f} to {math.degrees(a.knot_axes[-1, 1]):+.1f} deg,"
                f" arc {a.arc_s:.1f} s of {a.duration:.1f} s"
                for a in cw.then
            )
        )
        in_part = _in_part_text(cw)
        if not execute:
            said = "planned, not executed (preview)" + (f"; {in_part}" if in_part else "")
            out.append((pose, SeamWeld(c.id, True, False, said, code=WeldReason.PREVIEW, procedure=proc,
                                       share=cw.share, remainder=cw.remainder), cw, None))  # fmt: skip
            continue
        played = play_arcs(station, cw, pos.X_R_F(*pos.home)[:3, :3])
        ex, back, weave = joined(played)
        truth = det.curve_truths.get(c.id)
        q = quality(ex, back, truth, c.closed, weave) if truth is not None else None
        per_arc = tuple(quality(*p[:2], truth, c.closed, p[2]) for p in played) if truth is not None and cw.then else ()
        study = f"welded for a study despite the weld gate: {doubt.detail}" if doubt is not None else ""
        if in_part:  # its stretches welded, the rest left for a manual weld: never counted as welded
            w = SeamWeld(c.id, True, False, in_part, q, WeldReason.PARTIAL, proc, (q,) if q else (), share=cw.share,
                         remainder=cw.remainder, arc_quality=per_arc)  # fmt: skip
            out.append((pose, w, cw, ex))
            continue
        out.append((pose, SeamWeld(c.id, True, True, study or _arcs_text(cw), q, procedure=proc,
                                   passes=(q,) if q else (), arc_quality=per_arc), cw, ex))  # fmt: skip
    return out, why


def _planned(robot: RobotModel, pos: TiltRotatePositioner, c: CurveEstimate, process: WeldProcess, opt: PlanOptions,
             scene: MovingScene, q_now: FloatArray, rng: np.random.Generator, proc: WeldProcedure | None,
             progress: Callable[[str], None]) -> CoordinatedWeld:  # fmt: skip
    """``c`` welded whole with the part turning; else, with the process's ``curve_remainder: manual``, in part
    (:func:`cell.coordinated.partial.plan_in_part`: the longest stretch the arm holds, the rest left for a manual
    weld); MotionError with the whole weld's reason when neither is planned."""
    from cell.coordinated.partial import plan_in_part
    from cell.coordinated.plan import Setup, candidates, plan_coordinated

    try:
        return plan_coordinated(robot, pos, c, process, opt, scene, q_now, rng=rng, procedure=proc)
    except MotionError as whole:
        su = Setup.of(robot, pos, process, opt, scene, q_now, proc)
        if process.curve_remainder != "manual" or not candidates(su, c):  # no axes hold it in PA: nothing held
            raise
        progress(f"coordinated: {c.id} not welded whole ({whole.message}); planning the stretch the arm holds")
        try:
            return plan_in_part(su, c, rng)
        except MotionError as e:
            raise PlanError(f"{whole.message}; in part: {e.message}") from e


def _in_part_text(cw: CoordinatedWeld) -> str:
    """A coordinated weld of part of its curve in words (as the fixed arm's): the share welded and each stretch
    left for a manual weld; "" for a weld of the whole curve."""
    return in_part_text(cw.share, cw.remainder, len(cw.arcs), " with the part turning") if cw.remainder else ""


def _arcs_text(cw: CoordinatedWeld) -> str:
    """A loop welded whole in more than one coordinated arc, in words ("": in one)."""
    n = len(cw.arcs)
    return f"welded whole in {n} arcs with the part turning, each restarting over the bead before" if n > 1 else ""
