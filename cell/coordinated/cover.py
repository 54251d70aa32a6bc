"""A closed curved seam welded with the part turning in more than one coordinated arc (docs/positioner.md,
"Coordinated motion"): after the first arc, the stretch of any candidate's held knots (either way round, either
tilt branch, any spin) that welds the most of what is left, each arc's end either restarting the process's
``closed_overlap`` back over a bead already laid (a junction: never less) or left in the unwelded stretch for the
manual weld (a free end, at least that overlap from a bead, so a restart short of the overlap is the welder's).
Pure interval arithmetic along the located curve [m] (a closed one's positions taken round its length)."""

from __future__ import annotations

from collections.abc import Callable, Sequence

from cell.planning.curves.partial import EPS_M

MAX_ARCS = 4  # a seam's coordinated arcs at most, the first one's included


def loop_gaps(spans: Sequence[tuple[float, float]], total: float) -> list[tuple[float, float]]:
    """The stretches (from, to) [m] of a loop ``total`` long no span (from, to) covers, in order, each from within
    the loop's length (its to maybe past it: round the start)."""
    if not spans:
        return [(0.0, total)]
    arcs = sorted(((a % total, a % total + min(b - a, total)) for a, b in spans), key=lambda s: s[0])
    merged: list[list[float]] = []
    for a, b in arcs:
        if merged and a <= merged[-1][1] + EPS_M:
            merged[-1][1] = max(merged[-1][1], b)
        else:
            merged.append([a, b])
    out = []
    for k, (_, b) in enumerate(merged):
        nxt = merged[k + 1][0] if k + 1 < len(merged) else merged[0][0] + total
        if nxt - b > EPS_M:
            out.append((b % total, b % total + (nxt - b)))
    return out


def next_arcs(
    spans: Sequence[tuple[float, float]],
    held: Sequence[tuple[float, float]],
    total: float,
    overlap: float,
    min_arc: float,
) -> list[tuple[float, int, float, float]]:
    """The arcs that could weld next on a loop ``total`` [m] long already welded over ``spans``: for each stretch
    ``held`` (from, to) [m] (any candidate's) in each gap, that stretch cut to the gap widened by ``overlap`` at
    either end; an end inside a bead by less than ``overlap`` (or in the gap nearer a bead than that) moved into
    the gap to ``overlap`` from the bead (a free end: the welder's restart). As (the length of the gap it welds
    [m], the stretch's index, from, to [m] along the curve, from within its length), the most welded first; arcs
    shorter than ``min_arc`` [m] left out."""
    out = []
    for g0, g1 in loop_gaps(spans, total):
        for i, (a, b) in enumerate(held):
            for lap in (-2.0 * total, -total, 0.0, total, 2.0 * total):
                s, e = max(a + lap, g0 - overlap), min(b + lap, g1 + overlap)
                if g0 - overlap + EPS_M < s < g0 + overlap:  # short of a junction: a free end off the bead
                    s = g0 + overlap
                if g1 - overlap < e < g1 + overlap - EPS_M:
                    e = g1 - overlap
                gain = min(e, g1) - max(s, g0)
                if e - s >= min_arc and gain > EPS_M:
                    out.append((gain, i, s % total, s % total + (e - s)))
    return sorted(out, key=lambda o: (-o[0], o[1], o[2]))


def cover(
    first: tuple[float, float],
    held: Sequence[tuple[float, float]],
    total: float,
    overlap: float,
    min_arc: float,
    max_arcs: int = MAX_ARCS,
    planned: Callable[[int, float, float], bool] = lambda i, lo, hi: True,
    tries: int = 1,
) -> list[tuple[int, float, float]]:
    """The further arcs (the stretch's index, from, to [m]) a greedy cover of a loop ``total`` [m] long adds to the
    first arc ``first`` (from, to): each time the one welding the most of what is left (:func:`next_arcs`) that
    ``planned(index, from, to)`` plans, the next of the ``tries`` best where it does not, up to ``max_arcs`` in
    all; it stops where none of them is planned. By default every arc is taken as planned (what the held stretches
    can cover); the planner passes its own (:func:`cell.coordinated.partial.further_arcs`)."""
    spans = [first]
    out: list[tuple[int, float, float]] = []
    while len(spans) < max_arcs:
        opts = next_arcs(spans, held, total, overlap, min_arc)
        got = next(((i, lo, hi) for _, i, lo, hi in opts[:tries] if planned(i, lo, hi)), None)
        if got is None:
            break
        spans.append(got[1:])
        out.append(got)
    return out
