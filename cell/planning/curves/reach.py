"""Where along a curve the arm can hold the torch, and the fewest arcs that cover it: a reach map of the curve
(stations a few millimetres apart, each torch setting walked along them by warm-started IK) and the cover of the
curve by the stretches each setting holds without a break (docs/curves-welding.md section 10).

Frames: everything in the robot base frame R [m]; joints [rad]."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from cell.errors import IKError
from cell.geometry import FloatArray
from cell.motion.ik import solve_ik
from cell.planning.seam_search import SeamSearch
from cell.process.torch_orientations import Candidate
from cell.types.curve_estimate import CurveEstimate
from cell.types.plan import PlanReason

STATION_M = 0.008  # [m] the reach map's stations at most this far apart along the curve
STATION_TURN = math.radians(8.0)  # [rad] and closer where the tangent would turn more than this between two
SPINS = 8  # torch spins about its axis tried, evenly round (the flange's axis held, then spun by each)
JUMP_FACTOR = 3.0  # a joint's step between stations beyond this many times the knot's flip bound breaks a stretch
STATION_SEEDS = 2  # random IK seeds tried, besides the home seed, where a stretch starts afresh
MAX_JUMP = math.radians(60.0)  # [rad] and beyond this in any case


@dataclass(frozen=True)
class Run:
    """A stretch of the curve the torch holds without a break: ``cand`` (direction, spin, angle offsets at its
    weld start), from a_m to b_m [m] along the located curve's own order (b_m may pass a closed curve's length:
    round its start), the weld starting at a_m (b_m when reversed) with the arm at ``q_start`` (dof,) [rad];
    ``whole``: a closed curve held all round and on over its overlap; ``track`` (m, 4): the settings at its
    stations (position along the located curve [m] less ``origin_m``, spin, work and travel offsets [rad]), the
    torch turned and tilted from one to the next (None: ``cand`` held throughout); ``spare``: another path over a
    stretch some run already holds, for when that one fails its full solve; ``q_track`` (m, dof): the joints
    holding the torch at ``track``'s stations [rad] (None: not kept)."""

    cand: Candidate
    a_m: float
    b_m: float
    q_start: FloatArray
    whole: bool = False
    track: FloatArray | None = None
    origin_m: float = 0.0
    spare: bool = False
    q_track: FloatArray | None = None

    @property
    def length(self) -> float:
        return self.b_m - self.a_m


def station_spacing(est: CurveEstimate) -> float:
    """The reach map's station spacing [m] along ``est``: :data:`STATION_M`, closer on a tight curve."""
    t = est.tangent_R
    step = np.linalg.norm(np.diff(np.asarray(est.p_RS), axis=0), axis=1)
    turn = np.arccos(np.clip(np.sum(t[1:] * t[:-1], axis=1), -1.0, 1.0))
    ok = step > 1e-9
    per_m = float(np.max(turn[ok] / step[ok])) if np.any(ok) else 0.0
    return min(STATION_M, STATION_TURN / per_m) if per_m > 0.0 else STATION_M


def settings(search: SeamSearch, widened: bool) -> list[Candidate]:
    """The torch settings the map walks: both directions (one if the process is not reversible) x
    :data:`SPINS` spins (within the spin tolerance) at the nominal angles; ``widened``: the work and travel
    angles each at either end of their tolerance instead."""
    pr = search.process
    spins = sorted({round(math.remainder(2.0 * math.pi * k / SPINS, 2.0 * math.pi), 9) for k in range(SPINS)})
    spins = [s for s in spins if abs(s) <= pr.spin_tol + 1e-9] or [0.0]
    if widened:
        w, t = pr.work_angle_tol, pr.travel_angle_tol
        angles = [(w, 0.0), (-w, 0.0), (0.0, t), (0.0, -t)]
    else:
        angles = [(0.0, 0.0)]
    directions = (False, True) if pr.reversible else (False,)
    return [Candidate(r, s, w, a) for w, a in angles for r in directions for s in spins]


@dataclass(frozen=True)
class Miss:
    """A station where a torch setting could not start a stretch: ``at_m`` [m] along the located curve, ``code``
    why (IK, the arm against a part or itself, singular) and ``what`` (the bodies that met; "" otherwise)."""

    at_m: float
    code: PlanReason
    what: str = ""


def _fresh(search: SeamSearch, X: FloatArray, seeds: Sequence[FloatArray]) -> FloatArray | Miss:
    """IK at X (4, 4) from each seed in turn, the first clear of the parts and the arm itself and not singular;
    else why not (the last seed's, a collision's or singularity's before an IK failure's; ``at_m`` unset); kept in
    the search's memo when it has one."""
    if search.memo is not None:
        return search.memo.answer("fresh", (X, *seeds), 0.0, lambda: _fresh_solved(search, X, seeds))
    return _fresh_solved(search, X, seeds)


def _fresh_solved(search: SeamSearch, X: FloatArray, seeds: Sequence[FloatArray]) -> FloatArray | Miss:
    miss = Miss(0.0, PlanReason.IK_FAILED)
    for seed in seeds:
        try:
            q = np.asarray(solve_ik(search.robot, X, seed, options=search.opt.ik))
        except IKError:
            continue
        hit = search.checker.check(q)
        if hit is not None:
            miss = Miss(0.0, PlanReason.COLLISION, f"{hit.a} vs {hit.b}")
        elif search.robot.manipulability(q) < search.opt.min_manipulability:
            miss = Miss(0.0, PlanReason.SINGULAR)
        else:
            return q
    return miss


def _next(search: SeamSearch, X: FloatArray, q_prev: FloatArray, max_step: float) -> FloatArray | None:
    """IK at X (4, 4) warm-started from q_prev (dof,): None where it fails, a joint steps more than max_step [rad]
    or the arm meets a part or itself or is singular; kept in the search's memo when it has one."""
    if search.memo is not None:
        return search.memo.answer("next", (X, q_prev), max_step, lambda: _next_solved(search, X, q_prev, max_step))
    return _next_solved(search, X, q_prev, max_step)


def _next_solved(search: SeamSearch, X: FloatArray, q_prev: FloatArray, max_step: float) -> FloatArray | None:
    try:
        q = np.asarray(solve_ik(search.robot, X, q_prev, options=search.opt.ik))
    except IKError:
        return None
    jump = np.abs(np.angle(np.exp(1j * (q - q_prev))))
    return q if float(jump.max()) <= max_step and _fits(search, q) else None


def _fits(search: SeamSearch, q: FloatArray) -> bool:
    return search.checker.check(q) is None and search.robot.manipulability(q) >= search.opt.min_manipulability


def _a46_fits(search: SeamSearch, span4: float, span6: float) -> bool:
    """Whether A4's and A6's travel so far fit their limits and A6 its hose window."""
    lim = search.robot.limits
    return span4 <= float(lim.q_max[-3] - lim.q_min[-3]) and span6 <= 2.0 * search.window.half_width


def cover(runs: Sequence[Run], total: float, closed: bool, overlap: float, max_arcs: int) -> list[Run] | None:
    """The fewest stretches (at most ``max_arcs``) that cover a curve ``total`` [m] long whole, each next one
    starting at least ``overlap`` [m] back on the last (a closed curve: the last one on over the first's start by
    as much), greedy from every stretch as the first; None when none does."""
    best: list[Run] | None = None
    for first in sorted(runs, key=lambda r: -r.length):
        chosen, end = [first], first.b_m
        goal = first.a_m + total + overlap if closed else total - 1e-9
        if not closed and first.a_m > 1e-9:
            continue
        while end < goal and len(chosen) < max_arcs:
            nxt = _furthest(runs, end - overlap, end, total, closed)
            if nxt is None or nxt.b_m <= end + 1e-9:
                break
            chosen.append(nxt)
            end = nxt.b_m
        if end >= goal and (best is None or len(chosen) < len(best)):
            best = chosen
    return best


def _furthest(runs: Sequence[Run], lo: float, hi: float, total: float, closed: bool) -> Run | None:
    """The stretch starting at most at ``lo`` (and after ``hi``'s last cover start) that reaches furthest past
    ``hi``, shifted by whole laps of a closed curve to follow on."""
    best: Run | None = None
    for r in runs:
        for lap in (0.0, total, 2.0 * total) if closed else (0.0,):
            a, b = r.a_m + lap, r.b_m + lap
            if a <= lo + 1e-9 and b > hi and (best is None or b > best.b_m):
                best = replace(r, a_m=a, b_m=b, origin_m=r.origin_m + lap)
    return best


def share(runs: Sequence[Run], total: float, closed: bool) -> float:
    """The part of a curve ``total`` [m] long that at least one stretch holds."""
    bins = np.zeros(max(1, math.ceil(total / 0.001)), dtype=bool)
    for r in runs:
        idx = np.arange(math.floor(r.a_m / 0.001), math.ceil(r.b_m / 0.001))
        idx = np.mod(idx, len(bins)) if closed else idx[(idx >= 0) & (idx < len(bins))]
        bins[idx] = True
    return float(bins.mean())


def pinch(runs: Sequence[Run], total: float, overlap: float, step: float = 0.0005) -> tuple[float, float] | None:
    """Where on a closed curve ``total`` [m] long, every point of it held by some stretch, each stretch through a
    point gives out less than half the restart ``overlap`` [m] from it: (that point [m] along the located curve,
    how far the deepest stretch through it holds on either side [m]), the shallowest such point, sampled ``step``
    [m] apart; None where there is none or a point is held by no stretch (a gap). No cover of arcs each restarting
    ``overlap`` back over the last passes such a point, however many arcs: the arc that would pass it gives out
    there, and the next must start further back than any stretch through it reaches."""
    x = np.arange(0.0, total, step)
    deep = np.full(len(x), -1.0)
    for r in runs:
        for lap in (-2.0 * total, -total, 0.0, total):
            a, b = r.a_m + lap, r.b_m + lap
            inside = (x >= a) & (x <= b)
            deep[inside] = np.maximum(deep[inside], np.minimum(x[inside] - a, b - x[inside]))
    k = int(np.argmin(deep))
    return (float(x[k]), float(deep[k])) if 0.0 <= deep[k] < 0.5 * overlap else None


def balanced(chosen: Sequence[Run], total: float, closed: bool, overlap: float) -> list[Run]:
    """A cover's arcs with each junction's spare overlap shared out: where two arcs overlap by more than
    ``overlap`` [m] the first stops and the next starts half the excess back from their stretches' ends (a stretch
    ends where its setting gives out, the arm at a limit: an arc should not start or stop there), as on a closed
    curve the last one and the first (a lap on)."""
    out = list(chosen)
    n = len(out)
    for i in range(n if closed else n - 1):
        j = (i + 1) % n
        lap = total if j == 0 else 0.0
        excess = out[i].b_m - (out[j].a_m + lap) - overlap
        if excess > 0.0:
            out[i] = replace(out[i], b_m=out[i].b_m - 0.5 * excess)
            out[j] = replace(out[j], a_m=out[j].a_m + 0.5 * excess)
    return out
