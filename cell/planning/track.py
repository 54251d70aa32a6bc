"""Planning with a linear track under the base (an external axis E1): seams grouped along the track, one E1 per
group, the arm planned per group with its base there, the arm and the track moved together between groups
(:mod:`cell.planning.track_moves`; docs/track.md, "Planning").

Frames: R is the base at E1 = 0; every pose of the plan stays in R. Units: metres, radians, seconds."""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace

import numpy as np
import numpy.typing as npt

from cell.config.motion import PlanOptions
from cell.errors import PlanError
from cell.geometry import FloatArray, readonly
from cell.motion.collision import CollisionChecker
from cell.motion.robot import RobotModel
from cell.motion.timing import path_profile
from cell.planning.blend import blend_plan, blend_track
from cell.planning.curves import weldable
from cell.planning.curves.track import curve_e1s, curve_probes, in_part_at, retried
from cell.planning.plan import plan_welds, reach_model
from cell.planning.reach import ReachModel, cone_excess
from cell.planning.seam_search import seam_process
from cell.planning.track_moves import GroupLegs, TrackMoves, stitched
from cell.planning.transfers import Transfers
from cell.process.torch import WeldProcess, fillet_axes
from cell.types import Part
from cell.types.curve_estimate import CurveEstimate
from cell.types.plan import NoProcedure, PlanReason, SeamOutcome, SeamProcedure, SeamTask, Segment, WeldPlan
from cell.types.track import LinearTrack
from cell.types.trajectory import Trajectory

GRID_STEP = 0.01  # [m] E1 values tried for the groups
MARGIN = 0.15  # [m] how far inside the reach the nominal torch's wrist centre should lie at a group's E1 (room
# for IK, the joint limits, the torch's tilts and the wrist)
_BEST_TOL = 0.005  # [m] a seam that never gets the margin: E1 values within this of its best are usable


@dataclass(frozen=True)
class TrackGroup:
    """Seams planned with the base at one E1 [m]: their ids, in input order."""

    e1: float
    seam_ids: tuple[str, ...]


def e1_grid(track: LinearTrack, step: float = GRID_STEP) -> FloatArray:
    """(G,) [m]: E1 values every ``step`` over the track's limits, 0 among them."""
    lo = np.arange(0.0, track.e1_min - 1e-12, -step)[::-1]
    hi = np.arange(step, track.e1_max + 1e-12, step)
    return np.concatenate([lo, hi])


def reach_curves(
    reach: ReachModel,
    tasks: Sequence[SeamTask],
    processes: Sequence[WeldProcess],
    track: LinearTrack,
    grid: FloatArray,
    step: float = 0.02,
    cone: bool = False,
) -> FloatArray:
    """(seams, G) [m]: per seam and E1 of ``grid``, the worst over the seam's points (every ``step`` [m], its ends
    included) of how far the nominal torch's wrist centre (the process's work angle, no travel angle, on the torch
    axis) lies beyond the longest shoulder-to-wrist distance d_max (negative: inside, by that much room). With
    ``cone``: the reach pre-check's excess of every torch within the process's angles instead
    (:func:`cell.planning.reach.cone_excess`, > 0: out of reach for sure). The base moved by E1 is the same as the
    seam moved by -E1 along the axis."""
    out = np.empty((len(tasks), len(grid)))
    shift = grid[:, None, None] * track.axis_R  # (G, 1, 3)
    for i, (task, pr) in enumerate(zip(tasks, processes, strict=True)):
        d = task.p_end - task.p_start
        t_b, n_b = fillet_axes(d, task.n_a, task.n_b)
        z0 = -(np.cos(pr.work_angle) * t_b + np.sin(pr.work_angle) * n_b)
        n = max(2, int(np.ceil(task.length / step)) + 1)
        pts = task.p_start + np.outer(np.linspace(0.0, 1.0, n), d)  # (n, 3)
        moved = (pts[None] - shift).reshape(-1, 3)
        if cone:
            half = pr.work_angle_tol + abs(pr.travel_angle) + pr.travel_angle_tol
            excess = cone_excess(reach, moved, z0, half, pr.standoff)
        else:
            wrist = moved - (pr.standoff - float(reach.p_TW[2])) * z0  # the wrist centre on the torch axis
            near, _ = reach.circle_distance(wrist)  # A1 turns the shoulder towards it
            excess = near - reach.d_max  # (too near is the IK's to judge: the arm folds, the wrist turns away)
        out[i] = excess.reshape(len(grid), n).max(axis=1)
    return out


def group_seams(ids: Sequence[str], curves: FloatArray, grid: FloatArray, margin: float = MARGIN) -> list[TrackGroup]:
    """Groups of seams and their E1 (increasing), ``curves`` (seams, G) from :func:`reach_curves`: the seams with
    ``margin`` [m] of room at E1 = 0 stay there (planned as without a track); the fewest further E1 values give
    every other seam one where it has that room (or, for a seam that never does, is within 5 mm of its best); a
    seam out of reach everywhere joins the group nearest its best E1 (module docstring)."""
    if not len(ids):
        return []
    best = curves.min(axis=1)
    ok = curves <= np.maximum(-margin, best + _BEST_TOL)[:, None]  # (seams, G) usable E1 of each seam
    reachable = best <= 0.0
    zero = int(np.argmin(np.abs(grid)))
    home = [int(i) for i in np.flatnonzero(reachable & ok[:, zero])]
    groups: list[tuple[float, list[int]]] = [(0.0, home)] if home else []
    lo = np.array([grid[np.flatnonzero(r)[0]] for r in ok])
    hi = np.array([grid[np.flatnonzero(r)[-1]] for r in ok])
    members: list[int] = []
    for i in sorted(np.flatnonzero(reachable & ~ok[:, zero]), key=lambda k: (hi[k], lo[k])):
        if members and lo[i] <= min(hi[m] for m in members):
            members.append(int(i))
            continue
        if members:
            groups.append((_group_e1(members, ok, curves, grid), members))
        members = [int(i)]
    if members:
        groups.append((_group_e1(members, ok, curves, grid), members))
    if not groups:  # nothing reachable anywhere: one group where most of them are least out of reach
        groups.append((float(grid[int(np.argmin(np.median(curves, axis=0)))]), []))
    e1s = np.array([e for e, _ in groups])
    for i in np.flatnonzero(~reachable):  # out of reach everywhere: refused where it is least out of reach
        best_e = grid[int(np.argmin(curves[i]))]
        groups[int(np.argmin(np.abs(e1s - best_e)))][1].append(int(i))
    return sorted((TrackGroup(e, tuple(ids[k] for k in sorted(m))) for e, m in groups), key=lambda g: g.e1)


def _group_e1(members: list[int], ok: npt.NDArray[np.bool_], curves: FloatArray, grid: FloatArray) -> float:
    """A group's E1: 0 when every member may use it, else the usable grid value with the most room for its worst
    member (the members' usable sets overlap by construction; where they only do as intervals, the best value)."""
    common = np.all(ok[members], axis=0)
    zero = int(np.argmin(np.abs(grid)))
    if common[zero]:
        return 0.0
    worst = curves[members].max(axis=0)
    if common.any():
        worst = np.where(common, worst, np.inf)
    return float(grid[int(np.argmin(worst))])


def track_move(track: LinearTrack, q_home: FloatArray, e_a: float, e_b: float, dt: float) -> Trajectory:
    """The track from E1 = e_a to e_b [m], rest to rest, the arm standing at q_home (dof,) [rad]: jerk-limited
    within the track's limits (one Ruckig axis, :func:`cell.motion.timing.path_profile`)."""
    prof = path_profile(abs(e_b - e_a), track.v_max, track.a_max, track.j_max, dt=dt)
    sign = 1.0 if e_b >= e_a else -1.0
    n = len(prof.times)
    q = np.tile(np.asarray(q_home, dtype=float), (n, 1))
    e1 = e_a + sign * prof.s
    e1[-1] = e_b
    return Trajectory(prof.times, q, np.zeros_like(q), np.zeros_like(q), e1)


def plan_on_track(
    robot: RobotModel,
    tasks: Sequence[SeamTask],
    q_home: npt.ArrayLike,
    process: WeldProcess,
    obstacles: Sequence[Part] = (),
    *,
    track: LinearTrack,
    options: PlanOptions | None = None,
    rng: np.random.Generator | None = None,
    checker: CollisionChecker | None = None,
    procedures: Mapping[str, SeamProcedure | NoProcedure] | None = None,
    on_seam: Callable[[int, int], None] | None = None,
    curves: Sequence[CurveEstimate] = (),
) -> WeldPlan:
    """:func:`~cell.planning.plan.plan_welds` for an arm on ``track`` (module docstring): the same arguments and the
    same plan, whose segments carry E1 and whose ``track`` is set. ``robot`` is the arm with its base at R
    (E1 = 0). Each found curve of ``curves`` is welded whole from one E1, the carriage still while its arcs burn
    (:mod:`cell.planning.curves.track`): in a group of the straight seams where it has the room, else in one of
    its own; one no E1 welds whole, in part from its first E1 (``process.curve_remainder: manual``). Raises
    PlanError when home is outside the limits or collides at E1 = 0; a group whose home collides at its E1 has its
    seams refused (collision) with that reason."""
    t_start = time.perf_counter()
    opt = options or PlanOptions()
    q0 = np.asarray(q_home, dtype=float)
    checker = checker or CollisionChecker(robot, obstacles, opt.collision)
    rng = rng or np.random.default_rng(0)
    chosen = procedures or {}
    reach = reach_model(robot)
    live = [t for t in tasks if not isinstance(chosen.get(t.id), NoProcedure)]
    found = weldable(curves)
    grid = e1_grid(track)
    if reach is None or not live:
        groups = [TrackGroup(0.0, tuple(t.id for t in tasks))] if tasks else []
    else:
        procs = [seam_process(process, s if isinstance(s := chosen.get(t.id), SeamProcedure) else None) for t in live]
        groups = group_seams([t.id for t in live], reach_curves(reach, live, procs, track, grid), grid)
        dead = tuple(t.id for t in tasks if isinstance(chosen.get(t.id), NoProcedure))
        if dead:  # no procedure: refused by the planner wherever it is planned
            groups[0] = TrackGroup(groups[0].e1, groups[0].seam_ids + dead)
    tries = {c.id: _curve_e1s(reach, c, process, chosen.get(c.id), track, grid, groups) for c in found}
    at: dict[float, tuple[list[SeamTask], list[CurveEstimate]]] = {}
    by_id = {t.id: t for t in tasks}
    for g in groups:
        at[g.e1] = ([by_id[i] for i in g.seam_ids], [])
    for c in found:
        at.setdefault(tries[c.id][0], ([], []))[1].append(c)
    outcomes: dict[str, SeamOutcome] = {}
    plans: list[tuple[float, WeldPlan]] = []
    done = 0
    base0 = checker.base_offset_R
    exact = replace(opt, blend=0.0)  # each group approximated once its ways from and to home are known

    whole = replace(process, curve_remainder="refuse")  # whole from some E1 first; in part only as a last resort

    def plan_at(
        e1: float, seams: list[SeamTask], arcs: list[CurveEstimate], count: bool = True, pr: WeldProcess = whole
    ) -> WeldPlan | None:
        nonlocal done
        counter = None if on_seam is None or not count else _offset_counter(on_seam, done, len(tasks))
        checker.set_base(track.offset_R(e1))
        try:
            return plan_welds(
                _arm_at(robot, track, e1),
                seams,
                q0,
                pr,
                obstacles,
                options=exact,
                rng=rng,
                checker=checker,
                procedures=chosen,
                on_seam=counter,
                curves=arcs,
            )
        except PlanError as exc:
            if e1 == 0.0:
                raise
            why = f"home collides with the base at E1 = {e1 * 1000:.0f} mm on the track: {exc.message}"
            for sid, p in [*((t.id, t.p_start) for t in seams), *((c.id, c.p_RS[0]) for c in arcs)]:
                outcomes[sid] = SeamOutcome(sid, False, f"collision: {why}", readonly(p), code=PlanReason.COLLISION)
            return None
        finally:
            done += len(seams) if count else 0

    try:
        for e1 in sorted(at):
            plan = plan_at(e1, *at[e1])
            if plan is not None:
                outcomes.update({o.seam_id: o for o in plan.seams})
                plans.append((e1, plan))
        plans += retried(found, tries, outcomes, lambda e1, c: plan_at(e1, [], [c], count=False))
        if process.curve_remainder == "manual":  # a curve no E1 welds whole: in part from its first E1, alone
            plans += in_part_at(found, tries, outcomes, lambda e1, c: plan_at(e1, [], [c], False, process))
        legs: list[GroupLegs] = []
        order: list[str] = []
        for e1, plan in sorted(plans, key=lambda ep: ep[0]):  # the carriage one way out, back home at the end
            if plan.segments:
                legs.append(GroupLegs.split(e1, plan.segments))
                order += plan.order
        checker.set_base(base0)
        moves = TrackMoves(robot, track, checker, obstacles, process.stickout, q0, opt)

        def blend(g: GroupLegs, segs: list[Segment]) -> list[Segment]:
            if opt.blend <= 0.0:
                return segs
            arm = _arm_at(robot, track, g.e1)
            checker.set_base(track.offset_R(g.e1))
            clear = Transfers(arm, process, checker, opt, obstacles, q0).clear
            return blend_plan(segs, arm.limits, lambda q: arm.fk(q)[:3, 3], clear, fraction=opt.blend, dt=opt.dt)

        segments = stitched(moves, legs, blend)
        if opt.blend > 0.0:  # the moves with the track joined to the arm's motions either side
            segments = blend_track(segments, moves.limits, moves.tcp, moves.free, fraction=opt.blend, dt=opt.dt)
    finally:
        checker.set_base(base0)
    return WeldPlan(
        joint_names=robot.joint_names,
        q_home=readonly(q0),
        segments=tuple(segments),
        seams=tuple(outcomes[i] for i in [*(t.id for t in tasks), *(c.id for c in found)]),
        order=tuple(order),
        planning_s=time.perf_counter() - t_start,
        track=track,
    )


def _curve_e1s(
    reach: ReachModel | None,
    curve: CurveEstimate,
    process: WeldProcess,
    sel: SeamProcedure | NoProcedure | None,
    track: LinearTrack,
    grid: FloatArray,
    groups: Sequence[TrackGroup],
) -> tuple[float, ...]:
    """The E1 values [m] a found curve is tried from (:func:`cell.planning.curves.track.curve_e1s`): E1 = 0 only
    without a reach model; a curve with no procedure where the first group is (the planner refuses it)."""
    if isinstance(sel, NoProcedure) or reach is None:
        return (groups[0].e1 if groups else 0.0,)
    probes = curve_probes(curve)
    proc = seam_process(process, sel)
    room = reach_curves(reach, probes, [proc] * len(probes), track, grid).max(axis=0)
    sure = reach_curves(reach, probes, [proc] * len(probes), track, grid, cone=True).max(axis=0)
    return curve_e1s(room, grid, [0.0, *(g.e1 for g in groups)], MARGIN, sure)


def _arm_at(robot: RobotModel, track: LinearTrack, e1: float) -> RobotModel:
    """The arm with its base at E1 = e1 [m] (``robot`` itself at 0)."""
    return robot.shifted(track.offset_R(e1)) if e1 else robot


def _offset_counter(on_seam: Callable[[int, int], None], done: int, total: int) -> Callable[[int, int], None]:
    return lambda k, _n: on_seam(done + k, total)
