"""A curved seam the coordinated weld cannot weld whole, welded in part (the process's ``curve_remainder: manual``;
docs/positioner.md, "Coordinated motion"): for every candidate (either way round, either tilt branch, each spin)
the stretches of its knots the arm holds (IK warm-started from knot to knot with no joint jump over the planner's
step, the arm and torch clear of everything at each knot's axes), the longest planned as an open coordinated weld
(its approach, crater and depart, timed and gated like any), stopped back from where the arm gives out; the rest
left for a manual weld as the fixed arm's remainder (:class:`cell.types.plan.Remainder`). Frames: R the robot base
at the positioner's home [m]; joints [rad]."""

from __future__ import annotations

import re
import time
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
import numpy.typing as npt

from cell.coordinated.cover import cover, loop_gaps
from cell.coordinated.plan import SPINS_DEG, Candidate, Setup, candidates, solve_candidate, torch_poses
from cell.coordinated.record import CoordinatedWeld
from cell.errors import MotionError, PlanError
from cell.geometry import FloatArray
from cell.motion.ik import IKSolveError, solve_ik
from cell.planning.curves.arc_solve import MIN_ARC_M, why_stopped
from cell.planning.curves.partial import EPS_M, STOP_BACK_M, welded_share
from cell.planning.curves.reach import Miss
from cell.planning.curves.split import sub_arc
from cell.types.curve_estimate import CurveEstimate
from cell.types.plan import PlanReason, Remainder

MAX_TRIES = 6  # the longest stretches planned in turn until one is timed and gated


@dataclass(frozen=True)
class Walk:
    """The knots of one candidate at one spin in the order walked: ``index`` (k,) each knot's index on the path,
    ``s_m`` (k,) its length along the path from the weld start (unwrapped: a closed path's second lap past its
    length), ``ok`` (k,) the arm holds it, ``link`` (k,) it follows from the knot before without a joint jump;
    ``misses``: why each knot not held is not (at its length along the located curve)."""

    index: np.ndarray
    s_m: FloatArray
    ok: np.ndarray
    link: np.ndarray
    misses: tuple[Miss, ...]


def stretches(ok: npt.ArrayLike, link: npt.ArrayLike) -> list[tuple[int, int]]:
    """The held stretches (first, last) [inclusive positions] of a walk: runs of knots held, each following from
    the one before (``link``), longest first (the earlier first among equals)."""
    out: list[tuple[int, int]] = []
    start: int | None = None
    for k, (o, ln) in enumerate(zip(np.asarray(ok, bool), np.asarray(link, bool), strict=True)):
        if start is not None and (not o or not ln):
            out.append((start, k - 1))
            start = None
        if o and start is None:
            start = k
    if start is not None:
        out.append((start, len(np.asarray(ok)) - 1))
    return sorted(out, key=lambda r: (-(r[1] - r[0]), r[0]))


def on_curve(start_m: float, rev: bool, s_a: float, s_b: float, total: float, closed: bool) -> tuple[float, float]:
    """A stretch [s_a, s_b] [m] along a path welded from ``start_m`` on the located curve (``rev``: against
    its order) as (from, to) [m] along the located curve's own order (a closed curve's from within its length, its
    to maybe past it)."""
    a, b = (start_m - s_b, start_m - s_a) if rev else (start_m + s_a, start_m + s_b)
    if closed:
        a0 = a % total
        return a0, a0 + (b - a)
    return max(a, 0.0), min(b, total)


def leftover(spans: Sequence[tuple[float, float]], total: float, closed: bool,
             misses: Sequence[Miss]) -> tuple[Remainder, ...]:  # fmt: skip
    """What open welds over ``spans`` (from, to) [m] along a curve ``total`` long leave for a manual weld: the
    stretches of a closed loop no span covers (each from within the curve's length), or an open curve's ends
    beyond its one span; each with what stops the arm there (the knots' ``misses``: the commonest code, the two
    commonest in words)."""
    if closed:
        pieces = loop_gaps(spans, total)
    else:
        (a, b), *_ = spans
        pieces = [(0.0, a), (b, total)]
    out = []
    for lo, hi in pieces:
        if hi - lo <= EPS_M:
            continue
        code, why = why_stopped(list(misses), lo, hi, total, closed)
        out.append(
            Remainder(
                lo,
                hi,
                code,
                f"the arm holds no torch spin there with the part in PA ({why}); the "
                f"weld stops {STOP_BACK_M * 1000:.0f} mm short of where it gives out",
            )
        )
    return tuple(out)


def _ik_what(e: MotionError) -> tuple[PlanReason, str]:
    if isinstance(e, IKSolveError) and e.beyond_reach:
        return PlanReason.BEYOND_REACH, "beyond the arm's reach"
    m = re.search(r"joints at their limits: ([\w, ]+)", e.message)
    return PlanReason.IK_FAILED, f"IK: {m.group(1)} at its limit" if m else "IK did not converge"


def walk(su: Setup, est: CurveEstimate, cand: Candidate, X_RT: FloatArray, rng: np.random.Generator) -> Walk:
    """The knots of ``cand`` at the torch poses X_RT (n, 4, 4) walked from its weld start (a closed one's loop,
    then on round its start to where the first lap first broke off, so a stretch over the start is whole): each
    knot's IK from the last one held (the first from ``su.q_start`` with restarts from ``rng``), the arm and torch
    at it against everything at the knot's axes."""
    _, _, path, _, axes = cand
    total = est.length_m
    n = int(np.sum(path.s < total - 1e-9)) if est.closed else len(path.s)
    lim = su.opt.max_joint_step
    order = list(range(n))
    ok: list[bool] = []
    link: list[bool] = []
    miss: list[Miss] = []
    q_last: FloatArray | None = None

    def at_m(i: int) -> float:  # knot i's place along the located curve
        at = path.start - float(path.s[i]) if path.reversed else path.start + float(path.s[i])
        return at % total if est.closed else at

    k = 0
    while k < len(order):
        i = order[k]
        try:
            q = np.asarray(solve_ik(su.robot, X_RT[i], su.q_start if q_last is None else q_last,
                                    rng=rng if q_last is None else None))  # fmt: skip
            hit = su.scene.contact_at(np.concatenate([q, axes[i]]))
            if hit is not None:
                raise PlanError(f"{hit.a} vs {hit.b}")
        except MotionError as e:
            code, what = (PlanReason.COLLISION, e.message) if isinstance(e, PlanError) else _ik_what(e)
            if k < n:  # a knot tried again on the second lap is counted once
                miss.append(Miss(at_m(i), code, what))
            ok.append(False)
            link.append(False)
        else:
            jump = float(np.max(np.abs(q - q_last))) if q_last is not None and ok and ok[-1] else None
            if jump is not None and jump > lim:  # held, but not from the knot before: a configuration flip
                miss.append(
                    Miss(at_m(i), PlanReason.FLIP, f"a joint jumps {np.degrees(jump):.0f} deg from the knot before")
                )
            ok.append(True)
            link.append(jump is not None and jump <= lim)
            q_last = q
        if est.closed and k == n - 1 and not all(link[1:] + ok[:1]):  # on round the start to the first break
            cut = next(j for j in range(n) if not ok[j] or (j > 0 and not link[j]))
            order += list(range(cut + (0 if ok[cut] else 1)))
        k += 1
    idx = np.array(order)
    s = np.array([float(path.s[i]) + (total if j >= n else 0.0) for j, i in enumerate(order)])
    return Walk(idx, s, np.array(ok), np.array(link), tuple(miss))


def _stretch_plan(su: Setup, est: CurveEstimate, cand: Candidate, spin: float, lo: float, hi: float,
                  rng: np.random.Generator, t_wall: float) -> CoordinatedWeld:  # fmt: skip
    """The open coordinated weld of the located curve from ``lo`` to ``hi`` [m] along it, ``cand``'s way round and
    tilt branch, at ``spin`` [deg]."""
    rev, branch = cand[0], cand[1]
    arc = replace(sub_arc(est, lo, hi, 1), id=est.id)
    for c in candidates(su, arc):
        if c[0] == rev and c[1] == branch:
            return solve_candidate(su, est.id, c, spin, rng, t_wall)
    raise PlanError(f"curved seam {est.id}: no tilt within the limits puts {lo * 1000:.0f}-{hi * 1000:.0f} mm in PA")


@dataclass(frozen=True)
class Held:
    """A stretch of a candidate's knots the arm holds at one spin, cut :data:`STOP_BACK_M` back from where it gives
    out: ``cand``, ``spin`` [deg], from ``lo_m`` to ``hi_m`` [m] along the located curve's own order (a closed one's
    from within its length), ``misses`` its walk's (why each knot not held is not)."""

    cand: Candidate
    spin: float
    lo_m: float
    hi_m: float
    misses: tuple[Miss, ...]

    @property
    def length(self) -> float:
        return self.hi_m - self.lo_m


def held_stretches(su: Setup, est: CurveEstimate, rng: np.random.Generator) -> list[Held]:
    """Every candidate's held stretches at every spin (:func:`walk`, :func:`stretches`) at least
    :data:`MIN_ARC_M` long, the longest first; a candidate whose every knot is held (its motion refused it whole)
    leaves none."""
    out = []
    for cand in candidates(su, est):
        path = cand[2]
        for spin in SPINS_DEG:
            w = walk(su, est, cand, torch_poses(su, cand, spin)[1], rng)
            if not w.misses:
                continue
            for k0, k1 in stretches(w.ok, w.link):
                s_a, s_b = float(w.s_m[k0]), float(w.s_m[k1])
                s_a += 0.0 if not est.closed and k0 == 0 else STOP_BACK_M
                s_b -= 0.0 if not est.closed and k1 == len(w.ok) - 1 else STOP_BACK_M
                if s_b - s_a >= MIN_ARC_M:
                    lo, hi = on_curve(path.start, path.reversed, s_a, s_b, est.length_m, est.closed)
                    out.append(Held(cand, spin, lo, hi, w.misses))
    return sorted(out, key=lambda h: -h.length)


def plan_in_part(su: Setup, est: CurveEstimate, rng: np.random.Generator) -> CoordinatedWeld:
    """``est`` welded in part with the part turning: every candidate's held stretches (:func:`held_stretches`),
    the longest planned as an open coordinated weld, the next longest where one is not timed or gated, up to
    :data:`MAX_TRIES`; on a closed curve then further arcs over what it leaves (:func:`further_arcs`); the weld's
    ``remainder`` what they leave for a manual weld (:func:`leftover`) and its ``share`` of the curve. PlanError
    when none is planned."""
    t_wall = time.perf_counter()
    total = est.length_m
    held = held_stretches(su, est, rng)
    why = "the arm holds no stretch of it long enough to weld"
    for h in held[:MAX_TRIES]:
        try:
            cw = _stretch_plan(su, est, h.cand, h.spin, h.lo_m, h.hi_m, rng, t_wall)
        except MotionError as e:
            why = f"{h.lo_m * 1000:.0f}-{h.hi_m * 1000:.0f} mm at spin {h.spin:+.0f} deg: {e.message}"
            continue
        then = further_arcs(su, est, held, (h.lo_m, h.hi_m), rng) if est.closed else ()
        spans = [(h.lo_m, h.hi_m), *(a.span_m for a in then if a.span_m is not None)]
        rest = leftover(spans, total, est.closed, h.misses)
        return replace(cw, remainder=rest, share=welded_share(rest, total, est.closed), span_m=(h.lo_m, h.hi_m),
                       then=then)  # fmt: skip
    raise PlanError(f"curved seam {est.id}: no coordinated motion, whole or in part: {why}")


def further_arcs(su: Setup, est: CurveEstimate, held: Sequence[Held], first: tuple[float, float],
                 rng: np.random.Generator) -> tuple[CoordinatedWeld, ...]:  # fmt: skip
    """The coordinated arcs after the ``first`` (from, to) [m] over what it leaves of a closed curve: each time the
    held stretch that welds the most of what is left, restarting the process's ``closed_overlap`` back over the
    bead at each junction, the next where one is not timed or gated (up to :data:`MAX_TRIES`), up to
    :data:`cell.coordinated.cover.MAX_ARCS` arcs in all (:func:`cell.coordinated.cover.cover`)."""
    out: list[CoordinatedWeld] = []
    since = [time.perf_counter()]  # the wall clock from the last arc planned: each arc's planning time

    def planned(i: int, lo: float, hi: float) -> bool:
        try:
            cw = _stretch_plan(su, est, held[i].cand, held[i].spin, lo, hi, rng, since[0])
        except MotionError:
            return False
        out.append(replace(cw, span_m=(lo, hi)))
        since[0] = time.perf_counter()
        return True

    stretches_m = [(h.lo_m, h.hi_m) for h in held]
    cover(first, stretches_m, est.length_m, su.process.closed_overlap, MIN_ARC_M, planned=planned, tries=MAX_TRIES)
    return tuple(out)
