"""A welding plan's robot time taken apart (arc, craters and dwells, approaches, departs, transfers, the legs from and
to home, waits) and the bound its air time is measured against: time-optimal rest-to-rest PTP moves (Ruckig with
the arm's own limits, straight in joint space, no collisions; the track's E1 as a seventh axis) between the plan's
weld starts and ends, over the best order and direction of the seams (docs/cycle.md).

Used by ``benchmarks/bench_cycle.py``. Joints [rad], E1 [m], times [s]."""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from cell.geometry import FloatArray
from cell.motion.limits import JointLimits
from cell.motion.timing import ptp_duration
from cell.planning.track_moves import arm_and_track
from cell.types.plan import Segment, WeldPlan
from cell.types.track import LinearTrack

EXACT_MAX = 13  # seams up to which the tour is exact (a DP over subsets and directions); more: 2-opt, Or-opt
_REST = 1e-9  # [rad/s, m/s] slower than this is at rest


@dataclass(frozen=True)
class Breakdown:
    """Where a plan's time goes [s]: arc (craters and dwells included), the arc on at rest (craters and dwells),
    the seams' own approaches and departs, the transfers between seams (lifts included), the legs from and to
    home, the time the arm and track stand still with the arc off, and the track moving with the arm at rest."""

    cycle_s: float
    arc_s: float
    crater_dwell_s: float
    approach_s: float
    depart_s: float
    transfer_s: float
    home_s: float
    wait_s: float
    track_only_s: float

    @property
    def air_s(self) -> float:
        return self.cycle_s - self.arc_s


def _rest_time(seg: Segment) -> tuple[float, float]:
    """(time at rest [s], time with the arm at rest while the track moves [s]) of a segment's samples."""
    tr = seg.trajectory
    if len(tr.times) < 2:
        return 0.0, 0.0
    arm_still = np.all(np.abs(tr.qd) < _REST, axis=1)
    both = arm_still[:-1] & arm_still[1:]
    dt = np.diff(tr.times)
    if tr.e1 is None:
        return float(dt[both].sum()), 0.0
    track_still = np.abs(np.diff(tr.e1)) < _REST * np.maximum(dt, 1e-12)
    return float(dt[both & track_still].sum()), float(dt[both & ~track_still].sum())


def breakdown(plan: WeldPlan) -> Breakdown:
    """Every segment of ``plan`` in one bin: a weld's own approach is the segment just before it, its depart the
    one just after; any other arc-off segment before the first approach or after the last depart is a leg from or
    to home, the rest transfers."""
    segs = plan.segments
    welds = [k for k, s in enumerate(segs) if s.arc_on]
    own_app = {k - 1 for k in welds if k > 0 and segs[k - 1].kind == "approach"}
    own_dep = {k + 1 for k in welds if k + 1 < len(segs) and segs[k + 1].kind == "depart"}
    first = min(own_app | set(welds), default=len(segs))
    last = max(own_dep | set(welds), default=-1)
    bins = dict.fromkeys(("arc", "crater", "app", "dep", "transfer", "home", "wait", "track"), 0.0)
    for k, s in enumerate(segs):
        d = s.trajectory.duration
        rest, track = _rest_time(s)
        if s.arc_on:
            bins["arc"] += d
            bins["crater"] += rest
            continue
        bins["wait"] += rest
        bins["track"] += track
        key = "app" if k in own_app else "dep" if k in own_dep else "home" if k < first or k > last else "transfer"
        bins[key] += d
    return Breakdown(
        plan.cycle_time,
        bins["arc"],
        bins["crater"],
        bins["app"],
        bins["dep"],
        bins["transfer"],
        bins["home"],
        bins["wait"],
        bins["track"],
    )


def with_track(limits: JointLimits, track: LinearTrack | None) -> JointLimits:
    """The arm's limits, with the track's E1 as a last axis when there is one (the planner's own)."""
    return limits if track is None else arm_and_track(limits, track)


def _state(seg: Segment, k: int, track: LinearTrack | None) -> FloatArray:
    tr = seg.trajectory
    q = tr.q[k]
    return np.append(q, tr.e1[k] if tr.e1 is not None else 0.0) if track is not None else np.asarray(q)


@dataclass(frozen=True)
class Nodes:
    """The plan's seams as tour nodes: per seam its first weld start and last weld end (dof,), the fixed air time
    between its own passes [s]; the plan's start and end states."""

    ids: tuple[str, ...]
    starts: FloatArray
    ends: FloatArray
    inner_s: FloatArray
    q_start: FloatArray
    q_end: FloatArray


def nodes(plan: WeldPlan, track: LinearTrack | None, limits: JointLimits) -> Nodes:
    """The welded seams of ``plan`` in its order (a seam's passes stay together, in their order)."""
    welds: dict[str, list[Segment]] = {}
    for s in plan.segments:
        if s.arc_on:
            welds.setdefault(s.seam_id, []).append(s)
    ids = tuple(welds)
    starts = np.array([_state(welds[i][0], 0, track) for i in ids])
    ends = np.array([_state(welds[i][-1], -1, track) for i in ids])
    inner = np.array(
        [
            sum(
                ptp_duration(_state(a, -1, track), _state(b, 0, track), limits) for a, b in itertools.pairwise(welds[i])
            )
            for i in ids
        ]
    )
    first, last = plan.segments[0], plan.segments[-1]
    return Nodes(ids, starts, ends, inner, _state(first, 0, track), _state(last, -1, track))


@dataclass(frozen=True)
class Tour:
    """The bound's tour: seam ids in order, each reversed or not, its air time [s] (the PTP moves and the seams'
    own inter-pass moves), whether it is exact, and a certified lower bound [s] on the optimal tour."""

    order: tuple[str, ...]
    reversed: tuple[bool, ...]
    air_s: float
    exact: bool
    lower_s: float


def best_tour(n: Nodes, limits: JointLimits) -> Tour:
    """The fastest tour from the plan's start through every seam (either direction) to its end, by rest-to-rest
    PTP moves: exact for at most :data:`EXACT_MAX` seams, else greedy, then 2-opt and flips until no move helps."""
    m = len(n.ids)
    if m == 0:
        return Tour((), (), ptp_duration(n.q_start, n.q_end, limits), True, 0.0)
    # state 2 i + o: seam i entered at its start (o = 0) or at its end (o = 1, welded the other way)
    entry = np.array([n.starts, n.ends]).transpose(1, 0, 2).reshape(2 * m, -1)
    exit_ = np.array([n.ends, n.starts]).transpose(1, 0, 2).reshape(2 * m, -1)
    C = np.array([[ptp_duration(a, b, limits) for b in entry] for a in exit_])
    s0 = np.array([ptp_duration(n.q_start, b, limits) for b in entry])
    s1 = np.array([ptp_duration(a, n.q_end, limits) for a in exit_])
    inner = float(n.inner_s.sum())
    seam = np.arange(2 * m) // 2
    C[seam[:, None] == seam[None, :]] = np.inf
    lower = _lower(C, s0, s1, m) + inner
    states = _dp(C, s0, s1, m) if m <= EXACT_MAX else _local(C, s0, s1, m)
    cost = s0[states[0]] + sum(C[a, b] for a, b in itertools.pairwise(states)) + s1[states[-1]] + inner
    order = tuple(n.ids[k // 2] for k in states)
    return Tour(order, tuple(bool(k % 2) for k in states), float(cost), m <= EXACT_MAX, float(min(lower, cost)))


def _lower(C: FloatArray, s0: FloatArray, s1: FloatArray, m: int) -> float:
    """Every seam is entered once (from the start or another seam's exit) and left once (to another or the end):
    the larger of the sums of each seam's cheapest way in and cheapest way out bounds any tour from below."""
    into = np.minimum(C.min(axis=0), s0).reshape(m, 2).min(axis=1)
    out = np.minimum(C.min(axis=1), s1).reshape(m, 2).min(axis=1)
    return float(max(into.sum(), out.sum()))


def _dp(C: FloatArray, s0: FloatArray, s1: FloatArray, m: int) -> list[int]:
    """Held-Karp over subsets of seams, each state a seam and its direction."""
    full = (1 << m) - 1
    dp = np.full((1 << m, 2 * m), np.inf)
    back = np.full((1 << m, 2 * m), -1, dtype=int)
    for k in range(2 * m):
        dp[1 << (k // 2), k] = s0[k]
    bit = 1 << (np.arange(2 * m) // 2)
    for mask in range(1, full + 1):
        row = dp[mask]
        live = np.flatnonzero(np.isfinite(row))
        if live.size == 0:
            continue
        free = (bit & mask) == 0
        if not free.any():
            continue
        cand = row[live, None] + C[np.ix_(live, np.flatnonzero(free))]  # (live, free states)
        arg = np.argmin(cand, axis=0)
        for col, tgt in enumerate(np.flatnonzero(free)):
            nm = mask | int(bit[tgt])
            v = cand[arg[col], col]
            if v < dp[nm, tgt]:
                dp[nm, tgt], back[nm, tgt] = v, live[arg[col]]
    last = int(np.argmin(dp[full] + s1))
    states, mask = [last], full
    while back[mask, states[-1]] >= 0:
        prev = int(back[mask, states[-1]])
        mask ^= int(bit[states[-1]])
        states.append(prev)
    return states[::-1]


def _local(C: FloatArray, s0: FloatArray, s1: FloatArray, m: int) -> list[int]:
    """Greedy nearest from the start, then 2-opt (a reversed stretch flips each seam's direction in it) and
    single flips until neither improves the tour."""
    left, tour = set(range(m)), []
    cur_cost = s0
    while left:
        k = min((s for s in range(2 * m) if s // 2 in left), key=lambda s: cur_cost[s])
        tour.append(k)
        left.remove(k // 2)
        cur_cost = C[k]

    def cost(t: Sequence[int]) -> float:
        return float(s0[t[0]] + sum(C[a, b] for a, b in itertools.pairwise(t)) + s1[t[-1]])

    best, improved = cost(tour), True
    while improved:
        improved = False
        for i in range(m):
            for k in range(i, m):
                cand = tour[:i] + [s ^ 1 for s in tour[i : k + 1][::-1]] + tour[k + 1 :]
                c = cost(cand)
                if c < best - 1e-9:
                    tour, best, improved = cand, c, True
    return tour
