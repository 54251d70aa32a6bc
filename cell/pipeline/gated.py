"""The plan the safety gate passes: the found seams (and curves, tacks) planned, gated, and planned again in another
order or without what the gate faults, until it passes or its word is final (docs/reference.md section 7)."""

from __future__ import annotations

from collections.abc import Callable, Collection, Sequence
from dataclasses import replace
from functools import partial
from typing import TYPE_CHECKING

from cell.errors import PlanError, ScenarioError
from cell.geometry import FloatArray
from cell.pipeline.detect import Progress, quiet
from cell.pipeline.geometry import MotionScene, motion_scene
from cell.pipeline.placeable import curve_procedures_for, joint_parts, seam_procedures
from cell.pipeline.progress import seam_counter
from cell.pipeline.records import Detection
from cell.station import Station
from cell.types import Violation, ViolationKind
from cell.types.plan import Remainder

TackRule = Callable[[Detection, Sequence["SeamTask"]], Sequence["SeamTask"]]  # seam tasks -> tack tasks (tacks.py)

if TYPE_CHECKING:
    from cell.types.curve_estimate import CurveEstimate
    from cell.types.plan import SeamOutcome, SeamTask, WeldPlan
    from cell.types.trajectory import Trajectory


def plan_for(
    station: Station,
    det: Detection,
    *,
    skip: Collection[str] = (),
    q_start: FloatArray | None = None,
    motion: MotionScene | None = None,
    progress: Progress = quiet,
    tacks: TackRule | None = None,
    curves: Sequence[CurveEstimate] = (),
    elsewhere: bool = False,
) -> tuple[WeldPlan, Trajectory, tuple[Violation, ...]]:
    """Plan the found seams of a detection (but those in ``skip``) and run the safety gate (docs/reference.md
    section 7).

    q_start : where the arm is now (default: its scan configuration). motion : the run's obstacles and checker
    (built here when not given). Returns the plan, the move from q_start to
    home that precedes it, and the gate's violations (empty when the plan may run). PlanError when nothing can be
    planned at all.
    tacks : the tack welds to lay first (:mod:`cell.pipeline.tacks`, from the seam tasks): welded before every
        seam, each with its seam's procedure; the plan's outcomes list them after the seams (an arm on a track
        lays none).
    curves : located curved seams (in R) to weld too (:func:`cell.planning.plan.plan_welds`; on a track too).
    elsewhere : another pose may hold a seam (a positioner's): :func:`~cell.planning.plan.plan_welds`'s.
    """
    from cell.gate import find_violations
    from cell.gate.answer import gate_answer
    from cell.motion.timing import ptp
    from cell.pipeline.tacks import tack_procedures
    from cell.planning.curves.split import seam_of
    from cell.planning.memo import PlanMemo
    from cell.planning.plan import plan_welds
    from cell.planning.tasks import seam_tasks
    from cell.planning.track import plan_on_track
    from cell.planning.transfers import TransferFail, Transfers, joined
    from cell.process.torch import WeldProcess

    sc = det.scenario
    arm = station.arm
    if arm is None:
        raise ScenarioError(f"scenario {sc.name!r} has no robot to weld with: set robot.urdf and robot.X_WR")
    if det.scene is None:
        raise PlanError(f"nothing to plan: the detection of {sc.name!r} kept no scene ({det.error})")
    ss = det.scene.seam_scene
    tasks = seam_tasks([e for e in det.estimates if e.id not in skip], ss.weldmap, ss.joints, ss.table_z)
    motion = motion or motion_scene(arm, det)
    obstacles, checker = motion.obstacles, motion.checker
    track = sc.robot.track.track(sc.X_WR) if sc.robot.track is not None else None
    tack_tasks = tuple(tacks(det, tasks)) if tacks is not None and track is None else ()
    progress(
        f"planning {len(tasks)} seams{f' and {len(tack_tasks)} tacks' if tack_tasks else ''} (IK, timing, collisions)"
    )
    process = WeldProcess.from_spec(sc.process, sc.robot.stickout_mm)
    q_now = arm.q_scan if q_start is None else q_start
    problems: list[Violation] = []
    # The move home takes the transfers' ways (direct, lifted over the parts): a close-up view can leave the
    # torch low between parts, where the direct move collides. When no way is free, nothing can move: the whole
    # plan is refused (the start state, not a seam).
    way = Transfers(arm.model, process, checker, sc.motion.plan, obstacles, arm.q_home).move(q_now, arm.q_home)
    if isinstance(way, TransferFail):
        pre = ptp(q_now, arm.q_home, arm.model.limits, dt=0.001)
        why = f"move from the arm's position to home collides whichever way: {way.reason}"
        problems.append(Violation(ViolationKind.COLLISION, why, 0.0))
    else:
        pre = joined(way) if way else ptp(q_now, arm.q_home, arm.model.limits, dt=0.001)
    dropped: dict[str, SeamOutcome] = {}
    avoid: set[tuple[str, str]] = set()  # transfers the gate found at fault: another order is tried first
    refused: dict[str, list[Remainder]] = {}  # curved seam -> its arcs' stretches the gate found at fault
    memo = PlanMemo(arm.model, checker, sc.motion.plan)  # each round asks the reach map and transfers the same
    for _ in range(_GATE_ROUNDS):
        kept = [t for t in tasks if t.id not in dropped]
        kept_tacks = [t for t in tack_tasks if t.id not in dropped]
        procs = seam_procedures(sc, det, kept) | curve_procedures_for(sc, ss.weldmap, curves)
        first = {t.id for t in kept_tacks}  # the tacks before every seam
        fixed = partial(
            plan_welds, first=first, elsewhere=elsewhere, avoid=set(avoid), refused=dict(refused), memo=memo
        )
        planner = fixed if track is None else partial(plan_on_track, track=track)
        plan = planner(
            arm.model,
            [*kept, *kept_tacks],
            arm.q_home,
            process,
            obstacles,
            options=sc.motion.plan,
            rng=sc.rng("plan"),
            checker=checker,
            procedures=procs | tack_procedures(procs, kept_tacks),
            on_seam=seam_counter(progress) if not dropped and not avoid and not refused else None,
            curves=[c for c in curves if c.id not in dropped],
        )
        progress(
            "safety gate: limits at 1 kHz, collisions along the path, singularities, arc at exact stops, the wire"
            " clear of every part's body"
        )
        found = find_violations(
            arm.model,
            plan,
            arm.q_home,
            checker=checker,
            options=sc.motion.gate,
            bodies=ss.weldmap.parts,  # no TCP or wire inside a part's body (the aligned map's)
            wire_m=process.stickout,
            joint_parts=joint_parts(ss.joints, [t.id for t in (*kept, *kept_tacks)], ss.weldmap, curves),
        )
        # Another order first for a move into a seam; an arc of a curve welded in arcs left out alone (its stretch
        # for a manual weld, with the gate's reason); else the seam dropped (at most _GATE_ROUNDS plans in all).
        manual = process.curve_remainder == "manual" and track is None
        got = gate_answer(plan, found, avoid, by_arc=manual, reorder=track is None)
        if got is None:  # none, or one that concerns the whole plan
            break
        if got.moves:
            progress(f"safety gate: {', '.join(got.moves)} again in another order (the move into it violates it)")
            avoid |= set(got.moves.values())
        if got.arcs:
            progress(f"safety gate: leaving out {', '.join(got.arcs)} (its own motions violate it), planning the rest")
            for aid, r in got.arcs.items():
                refused.setdefault(seam_of(aid), []).append(r)
        if got.drop:
            progress(f"safety gate: dropping {', '.join(got.drop)} (their own motions violate it), planning the rest")
            dropped.update(got.drop)
    outcomes = {o.seam_id: o for o in plan.seams} | dropped
    ids = [*(t.id for t in (*tasks, *tack_tasks)), *(c.id for c in curves)]
    plan = replace(plan, seams=tuple(outcomes[i] for i in ids if i in outcomes))
    problems += found
    return plan, pre, tuple(problems)


_GATE_ROUNDS = 6  # plans tried: after the fifth round of other orders and drops the gate's word is final
