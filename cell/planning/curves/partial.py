"""A curved seam welded in part (the process's ``curve_remainder: manual``): where no cover of arcs welds it whole,
the arcs that weld the most of what the arm holds, each restarting the WPS overlap back over the bead before it
within a held stretch, stopping with its crater just short of a stretch no torch setting holds; and the stretches
they leave for a manual weld, each with what stops the arm there (docs/curves-welding.md section 10).

Frames: everything in the robot base frame R [m]; joints [rad]."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from cell.geometry import FloatArray
from cell.planning.curves.arc_solve import MIN_ARC_M, TRIES, arc_solution, same_stretch, trimmed, why_stopped
from cell.planning.curves.graph import gaps
from cell.planning.curves.reach import Miss, Run, balanced, pinch
from cell.planning.curves.split import MAX_PARTIAL_ARCS, Split, arc_id, sub_arc
from cell.planning.failures import SeamFailure
from cell.planning.seam_search import SeamSearch, SeamSolution
from cell.process.torch_orientations import Candidate
from cell.types.curve_estimate import CurveEstimate
from cell.types.plan import PlanReason, Remainder
from cell.types.procedure import WeldProcedure

EPS_M = 1e-6  # [m] two ends this close are one place
SHORT_OR_BEYOND = "too short to weld or beyond the arcs' bound"
# [m] an arc stops (or starts) this far short of a gap's edge: its stretch gives out there with the arm at a
# limit (a joint, the hose window, against itself or a part), and the depart and the move on need room
STOP_BACK_M = 0.005
HELD_SLACK_M = 0.001  # [m] the map's held stretches are binned by the millimetre (:func:`.graph.gaps`)


def partial_cover(
    runs: Sequence[Run], total: float, closed: bool, overlap: float, min_arc: float, max_arcs: int = MAX_PARTIAL_ARCS
) -> list[tuple[Run, Run]]:
    """The arcs that weld the most of a curve ``total`` [m] long its stretches hold, as (the stretch, the arc: that
    stretch cut to where it welds) in order along the curve: in each held piece between two stretches no setting
    holds (the whole of a closed curve held all round: from its pinch, :func:`.reach.pinch`), greedy from the
    piece's start, each next stretch starting at least ``overlap`` [m] back on the last where one does, else the
    one that reaches furthest from where the last gives out (a restart short of the overlap: :func:`remainder`
    lists it); excess overlaps shared out as in a whole cover (:func:`.reach.balanced`), the piece's arcs
    :data:`STOP_BACK_M` off a gap's edge at either end. Arcs shorter than ``min_arc`` [m] are left out, and beyond
    ``max_arcs`` the shortest."""
    if not runs:
        return []
    free = gaps(runs, total, closed, 0.0)
    laps = (-total, 0.0, total, 2.0 * total) if closed else (0.0,)
    copies = [_lap(r, k) for r in runs for k in laps]
    out: list[tuple[Run, Run]] = []
    if closed and not free:
        at = pinch(runs, total, overlap)
        x0 = at[0] if at is not None else max(runs, key=lambda r: r.length).a_m
        through = [r for r in copies if r.a_m <= x0 + EPS_M and r.b_m > x0 + EPS_M]
        first = max(through, key=lambda r: r.b_m)
        goal = first.a_m + total + overlap
        chain = _chain(copies, first, goal, overlap, ring=first.a_m + total)
        parts = balanced(chain, total, True, overlap)
        parts[-1] = replace(parts[-1], b_m=max(min(parts[-1].b_m, goal), parts[-1].a_m))  # no further round
        out = list(zip(chain, parts, strict=True))
    else:
        for lo, hi in _held(free, total, closed):
            inside = [r for r in copies if r.a_m >= lo - HELD_SLACK_M and r.b_m <= hi + HELD_SLACK_M]
            if not inside:
                continue
            starts = [r for r in inside if r.a_m <= lo + HELD_SLACK_M] or [min(inside, key=lambda r: r.a_m)]
            first = max(starts, key=lambda r: r.b_m)
            chain = _chain(inside, first, hi - HELD_SLACK_M, overlap)
            parts = balanced(chain, total, False, overlap)
            if closed or lo > EPS_M:  # off a gap's edge, not the curve's own start
                parts[0] = replace(parts[0], a_m=parts[0].a_m + STOP_BACK_M)
            if closed or hi < total - EPS_M:
                parts[-1] = replace(parts[-1], b_m=parts[-1].b_m - STOP_BACK_M)
            out += list(zip(chain, parts, strict=True))
    out = [(r, p) for r, p in out if p.length >= min_arc]
    if closed:  # each arc from its start on the located curve's own lap
        out = [
            (_lap(r, -math.floor(p.a_m / total) * total), _lap(p, -math.floor(p.a_m / total) * total)) for r, p in out
        ]
    if len(out) > max_arcs:
        keep = sorted(sorted(range(len(out)), key=lambda k: -out[k][1].length)[:max_arcs])
        out = [out[k] for k in keep]
    return out


def _lap(r: Run, by: float) -> Run:
    """``r`` moved ``by`` [m] along the curve (whole laps of a closed one)."""
    return replace(r, a_m=r.a_m + by, b_m=r.b_m + by, origin_m=r.origin_m + by)


def _held(free: list[tuple[float, float]], total: float, closed: bool) -> list[tuple[float, float]]:
    """The held pieces (from, to) [m] of a curve ``total`` long between its stretches no setting holds (``free``,
    in order; a closed curve's last piece on round its start)."""
    if not closed:
        edges = [0.0, *[v for g in free for v in g], total]
        return [(a, b) for a, b in zip(edges[::2], edges[1::2], strict=True) if b - a > EPS_M]
    ends = sorted(free)
    return [
        (ends[k][1], ends[(k + 1) % len(ends)][0] + (total if k + 1 == len(ends) else 0.0)) for k in range(len(ends))
    ]


def _chain(runs: Sequence[Run], first: Run, goal: float, overlap: float, ring: float | None = None) -> list[Run]:
    """Stretches from ``first`` on to ``goal`` [m]: each next the one reaching furthest that starts ``overlap`` back
    on the last, else (a pinch: none does) the furthest one through where the last gives out; ``ring``: a closed
    curve's lap end (the first arc's start a lap on), where the chain may stop short of the overlap."""
    chain, end = [first], first.b_m
    while end < goal - EPS_M:
        on = [r for r in runs if r.b_m > end + EPS_M]
        lapped = [r for r in on if r.a_m <= end - overlap + EPS_M]
        touching = [r for r in on if r.a_m <= end + EPS_M]
        nxt = max(lapped or touching, key=lambda r: r.b_m, default=None)
        if nxt is None or (ring is not None and end >= ring - EPS_M and not lapped):
            break
        chain.append(nxt)
        end = nxt.b_m
    return chain


def remainder(
    spans: Sequence[tuple[float, float]],
    runs: Sequence[Run],
    misses: Sequence[Miss],
    total: float,
    closed: bool,
    overlap: float,
    failed: Sequence[tuple[float, float, SeamFailure]] = (),
    refused: Sequence[Remainder] = (),
) -> list[Remainder]:
    """What arcs welding ``spans`` (from, to) [m] along a curve ``total`` long leave for a manual weld, in order:
    every stretch no arc welds (its code and words: an arc over it that failed its full solve, ``failed``; else
    what stops the torch settings there, from ``misses``; else that the arm holds it only in stretches too short
    to weld or beyond the arcs' bound; an arc over it refused after the search, ``refused``: its code and words)
    and, where one arc restarts over the last by less than ``overlap`` [m], the
    ``overlap`` about that restart (the arcs give out there: a pinch; the restart is a manual weld's, never the
    robot's with a shorter overlap)."""
    if not spans:
        code, why = why_stopped(list(misses), 0.0, total, total, closed)
        return [Remainder(0.0, total, code, f"no arc welds any of it ({why})")]
    arcs = sorted(((a % total, a % total + (b - a)) if closed else (a, b) for a, b in spans), key=lambda s: s[0])
    out: list[Remainder] = []
    if not closed and arcs[0][0] > EPS_M:
        out.append(_unwelded(0.0, arcs[0][0], runs, misses, total, closed, failed, refused))
    end = arcs[0][1]
    after = [*arcs[1:], (arcs[0][0] + total, arcs[0][1] + total)] if closed else arcs[1:]
    for a_next, b_next in after:
        if b_next <= end + EPS_M:  # wholly within the arcs before it
            continue
        if a_next > end + EPS_M:
            out.append(_unwelded(end, a_next, runs, misses, total, closed, failed, refused))
        elif end - a_next < overlap - EPS_M:
            mid = 0.5 * (end + a_next)
            code, why = why_stopped(list(misses), mid - overlap, mid + overlap, total, closed)
            words = (f"the arcs restart over each other by {max(end - a_next, 0.0) * 1000:.1f} mm < the WPS's "
                     f"{overlap * 1000:.0f} mm: the arm holds no setting through here further ({why})")  # fmt: skip
            out.append(Remainder(mid - 0.5 * overlap, mid + 0.5 * overlap, code, words))
        end = max(end, b_next)
    if not closed and end < total - EPS_M:
        out.append(_unwelded(end, total, runs, misses, total, closed, failed, refused))
    if closed:  # each from where it starts on the located curve's own lap
        out = sorted((replace(r, from_m=r.from_m % total, to_m=r.from_m % total + r.length_m) for r in out),
                     key=lambda r: r.from_m)  # fmt: skip
    return out


def _unwelded(
    lo: float,
    hi: float,
    runs: Sequence[Run],
    misses: Sequence[Miss],
    total: float,
    closed: bool,
    failed: Sequence[tuple[float, float, SeamFailure]],
    refused: Sequence[Remainder] = (),
) -> Remainder:
    """A stretch from lo to hi [m] no arc welds, with why (:func:`remainder`)."""
    gated = next((r for r in refused if shared_m(r.from_m, r.to_m, lo, hi, total, closed) > EPS_M), None)
    f = next((f for a, b, f in failed if shared_m(a, b, lo, hi, total, closed) > EPS_M), None)
    unheld = sum(shared_m(a, b, lo, hi, total, closed) for a, b in gaps(runs, total, closed, 0.0))
    if unheld > EPS_M or not runs:
        code, why = why_stopped(list(misses), lo - 0.01, hi + 0.01, total, closed)
        words = f"no torch setting holds {unheld * 1000:.0f} mm of it ({why})"
        if f is not None and hi - lo > unheld + 0.002:
            words += f"; an arc over the rest failed its full solve ({f.code}: {f.where})"
        elif hi - lo > unheld + 2.0 * STOP_BACK_M + 0.002:
            words += f"; the rest held only in stretches {SHORT_OR_BEYOND}"
        elif hi - lo > unheld + 0.002:
            words += f"; the arcs stop {STOP_BACK_M * 1000:.0f} mm short of it (the arm at a limit where it gives out)"
        return Remainder(lo, hi, code, words)
    if gated is not None:  # trimmed off an arc refused after the search: that refusal
        return Remainder(lo, hi, gated.code, gated.why)
    if f is not None:
        return Remainder(lo, hi, f.code or PlanReason.IK_FAILED, f"an arc over it failed its full solve: {f.where}")
    code, _ = why_stopped(list(misses), lo - 0.01, hi + 0.01, total, closed)
    return Remainder(lo, hi, code, f"the arm holds it only in stretches {SHORT_OR_BEYOND}")


def shared_m(a: float, b: float, lo: float, hi: float, total: float, closed: bool) -> float:
    """How long [m] [a, b] and [lo, hi] (along a curve ``total`` long, round a closed one's start) share."""
    shifts = (-total, 0.0, total) if closed else (0.0,)
    return sum(max(0.0, min(b + k, hi) - max(a + k, lo)) for k in shifts)


def welded_share(rest: Sequence[Remainder], total: float, closed: bool) -> float:
    """The part of a curve ``total`` [m] long outside the stretches ``rest`` leaves for a manual weld (by the
    millimetre)."""
    bins = np.zeros(max(1, math.ceil(total / 0.001)), dtype=bool)
    for r in rest:
        idx = np.arange(math.floor(r.from_m / 0.001 + 1e-6), math.ceil(r.to_m / 0.001 - 1e-6))
        bins[np.mod(idx, len(bins)) if closed else idx[(idx >= 0) & (idx < len(bins))]] = True
    return 1.0 - float(bins.mean())


def partial_arcs(
    search: SeamSearch,
    est: CurveEstimate,
    runs: list[Run],
    misses: list[Miss],
    flange: tuple[FloatArray, FloatArray],
    knot: float,
    procedure: WeldProcedure | None,
    failure: SeamFailure,
    refused: Sequence[Remainder] = (),
) -> Split:
    """``est`` welded in part (:func:`partial_cover`), each arc solved as a whole cover's
    (:func:`.arc_solve.arc_solution`); an arc that fails is trimmed or dropped (:func:`.arc_solve.trimmed`) and
    the arcs chosen again, up to :data:`.arc_solve.TRIES` times; then the solved arcs of the try that welds the
    most are kept and the failed ones' stretches left to the manual weld. ``failure``: why no cover welds it whole
    (kept as the split's). No arc solved: that failure alone. ``refused``: arcs refused after the search at one
    end (each its stretch, the refusal's code and words, ``end``): an arc chosen on exactly that stretch fails
    so at once, without a solve (:func:`refusal`), and is trimmed at that end; the stretch given up is listed
    with the refusal's code and words."""
    pr, total = search.process, est.length_m
    overlap = pr.closed_overlap if est.closed else 0.0
    memo: dict[tuple[float, float, Candidate], tuple[SeamSolution, ...] | SeamFailure] = {}
    failed: list[tuple[float, float, SeamFailure]] = []
    named: set[tuple[float, float, Candidate]] = set()  # arcs a refusal names (failed so, not solved)
    kept: list[tuple[Run, tuple[SeamSolution, ...]]] = []
    best: list[tuple[Run, tuple[SeamSolution, ...]]] = []
    mapped = list(runs)  # what the map holds, before failed arcs are trimmed out of it
    for _ in range(TRIES):
        chosen = partial_cover(runs, total, est.closed, overlap, MIN_ARC_M)
        kept, again = [], False
        for k, (run, part) in enumerate(chosen, 1):
            key = (round(part.a_m % total if est.closed else part.a_m, 6), round(part.length, 6), part.cand)
            arc = sub_arc(est, part.a_m, part.b_m, k)
            gated = refusal(refused, part, arc, total, est.closed)
            named |= {key} if gated is not None else set()
            got = gated or memo.get(key) or arc_solution(search, arc, part, flange, knot, procedure)
            memo[key] = got
            if isinstance(got, SeamFailure):
                failed += [] if key in named else [(part.a_m, part.b_m, got)]
                runs = [r for r in runs if not same_stretch(r, run, total)] + trimmed(part, got, arc)
                again = True
            else:
                kept.append((part, got))
        if sum(p.length for p, _ in kept) > sum(p.length for p, _ in best):
            best = kept
        if not again:
            break
    kept = best  # the try whose solved arcs weld the most (a later try may lose what an earlier one solved)
    if not kept:
        return Split((), 0.0, failure)
    spans_m = [(p.a_m, p.b_m) for p, _ in kept]
    rest = remainder(spans_m, mapped, misses, total, est.closed, overlap, failed, [r for r in refused if r.end])
    arcs = tuple((sub_arc(est, p.a_m, p.b_m, k), _named(s, arc_id(est.id, k))) for k, (p, s) in enumerate(kept, 1))
    spans = tuple((a.id, p.a_m, p.b_m) for (a, _), (p, _) in zip(arcs, kept, strict=True))
    return Split(arcs, welded_share(rest, total, est.closed), failure, tuple(rest), spans)


def refusal(
    refused: Sequence[Remainder], part: Run, arc: CurveEstimate, total: float, closed: bool
) -> SeamFailure | None:
    """The failure of an arc ``part`` (along a curve ``total`` [m] long) that a refusal in ``refused`` names at one
    end (its stretch exactly the arc's, its ``end`` set): its code and words, before the weld's start (``start``)
    or at the weld's end (``end``), so that :func:`.arc_solve.trimmed` cuts that end; None when none names it."""
    for r in refused:
        same = abs(math.remainder(r.from_m - part.a_m, total) if closed else r.from_m - part.a_m) < EPS_M
        if r.end and same and abs(r.length_m - part.length) < EPS_M:
            ends = np.asarray(arc.p_RS)[[-1, 0] if part.cand.reversed else [0, -1]]  # the weld's start and end
            at_start = r.end == "start"
            return SeamFailure(r.code, r.why, ends[0 if at_start else 1].copy(), -1.0 if at_start else arc.length_m)
    return None


def _named(sols: tuple[SeamSolution, ...], aid: str) -> tuple[SeamSolution, ...]:
    """An arc's solutions under its id in the kept arcs' order (solved, maybe, under its number in an earlier try)."""
    return tuple(replace(s, task=replace(s.task, id=aid)) for s in sols)
