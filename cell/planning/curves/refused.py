"""Arcs of a curved seam refused after the search (the safety gate on an arc's own moves, a transfer no way makes,
its timing): each left out alone, its stretch joined to the seam's remainder for a manual weld with the refusal as
its reason, the seam's other arcs kept (docs/curves-welding.md section 9, "Welded in part"); and whether a
failing transfer is the fault of the arc it comes out of (section 9, "A failing exit planned again").

Frames: stretches in metres along the located curve (a closed curve's ``to`` may pass its length)."""

from __future__ import annotations

from collections.abc import Collection, Mapping, Sequence

from cell.planning.curves.partial import EPS_M, shared_m, welded_share
from cell.planning.curves.split import Partial, seam_of
from cell.types.plan import Remainder


def refused_arc(spans: Mapping[str, tuple[float, float]], r: Remainder, total: float, closed: bool) -> str | None:
    """The arc (id in ``spans``: arc id -> (from, to) [m]) a refused stretch ``r`` names: the one sharing the most
    of it, at least half of the shorter of the two (None: no arc welds there any more)."""
    best, most = None, 0.0
    for aid, (a, b) in spans.items():
        got = shared_m(a, b, r.from_m, r.to_m, total, closed)
        if got > most + EPS_M:
            best, most = aid, got
    if best is None:
        return None
    a, b = spans[best]
    return best if most >= 0.5 * min(b - a, r.length_m) - EPS_M else None


def left_over(
    kept: Sequence[tuple[float, float]],
    dropped: Sequence[Remainder],
    before: Sequence[Remainder],
    total: float,
    closed: bool,
    overlap: float,
) -> tuple[Remainder, ...]:
    """The remainder of a curve ``total`` [m] long once the arcs ``dropped`` (each its stretch, code and why) are
    left out: ``before`` (what the arcs left already) and, with the reason of the dropped arc, each part of its
    stretch no ``kept`` arc (from, to) welds and ``before`` does not list; where two kept arcs now restart over each
    other inside a dropped stretch by less than ``overlap`` [m], that restart too (as :func:`.partial.remainder`
    lists one: the ``overlap`` about it). No two items overlap; in order along the curve, each from its own lap."""
    out = list(before)
    for r in dropped:
        pieces = [(r.from_m, r.to_m)]
        for c, d in [*kept, *((x.from_m, x.to_m) for x in out)]:
            pieces = [p for a, b in pieces for p in _minus(a, b, c, d, total, closed)]
        out += [Remainder(a, b, r.code, r.why) for a, b in pieces if b - a > EPS_M]
        if closed and overlap > 0.0:
            out += _short_restarts(kept, r, out, total, overlap)
    if closed:
        out = [Remainder(x.from_m % total, x.from_m % total + x.length_m, x.code, x.why) for x in out]
    return tuple(sorted(out, key=lambda x: x.from_m))


def _minus(a: float, b: float, c: float, d: float, total: float, closed: bool) -> list[tuple[float, float]]:
    """[a, b] less [c, d] (and its laps round a closed curve ``total`` long): the pieces left, in order."""
    pieces = [(a, b)]
    for k in (-total, 0.0, total) if closed else (0.0,):
        lo, hi = c + k, d + k
        pieces = [q for x, y in pieces for q in ((x, min(y, lo)), (max(x, hi), y)) if q[1] - q[0] > EPS_M]
    return pieces


def _short_restarts(
    kept: Sequence[tuple[float, float]], r: Remainder, out: Sequence[Remainder], total: float, overlap: float
) -> list[Remainder]:
    """Round a closed curve ``total`` [m] long: where a kept arc now restarts inside the dropped stretch ``r`` over
    the bead of the kept arc before it by less than ``overlap`` [m] (but by something: a gap between them is listed
    already), the ``overlap`` about that restart, unless listed already."""
    arcs = sorted((a % total, a % total + (b - a)) for a, b in kept)
    found: list[Remainder] = []
    if not arcs:
        return found
    for (_, b1), (a2, _) in zip(arcs, [*arcs[1:], (arcs[0][0] + total, 0.0)], strict=True):
        lap = b1 - a2
        if not EPS_M < lap < overlap - EPS_M or shared_m(a2, a2 + EPS_M, r.from_m, r.to_m, total, True) <= 0.0:
            continue
        mid = 0.5 * (a2 + b1)
        lo, hi = mid - 0.5 * overlap, mid + 0.5 * overlap
        if any(shared_m(lo, hi, x.from_m, x.to_m, total, True) > EPS_M for x in (*out, *found)):
            continue
        words = (f"the arcs either side restart over each other by {lap * 1000:.1f} mm < the WPS's "
                 f"{overlap * 1000:.0f} mm once it is left out ({r.why})")  # fmt: skip
        found.append(Remainder(lo, hi, r.code, words))
    return found


def without_refused(
    spans: Mapping[str, tuple[float, float]],
    refused: Sequence[Remainder],
    before: Sequence[Remainder],
    total: float,
    closed: bool,
    overlap: float,
) -> tuple[dict[str, Remainder], tuple[Remainder, ...], float]:
    """A seam's arcs (``spans``: arc id -> (from, to) [m]) with the ``refused`` stretches left out: (each arc left
    out -> its refusal, on the arc's own stretch; the remainder then, :func:`left_over`; the share welded)."""
    out: dict[str, Remainder] = {}
    for r in refused:
        aid = refused_arc({k: v for k, v in spans.items() if k not in out}, r, total, closed)
        if aid is not None:
            out[aid] = Remainder(*spans[aid], r.code, r.why)
    kept = [v for k, v in spans.items() if k not in out]
    rest = left_over(kept, list(out.values()), before, total, closed, overlap)
    return out, rest, welded_share(rest, total, closed)


def exit_at_fault(a: str, b: str, failed: Collection[tuple[str, str]], parts: Mapping[str, Partial]) -> bool:
    """Whether the failing transfer from ``a`` to ``b`` ("" = home) is ``a``'s exit's fault: ``a`` is an arc of a
    curve that may be welded in part (in ``parts``) and a move out of it towards another place than ``b`` failed
    too (in ``failed``, the transfers (from, to) the order search found no free way for)."""
    return bool(a) and seam_of(a) != a and seam_of(a) in parts and any(x == a and y != b for x, y in failed)
