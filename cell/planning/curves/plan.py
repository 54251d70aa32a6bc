"""Located curved seams into the plan: their weld procedures, their torch searches and timed pieces, and the
planned path each curved weld segment carries for the exporters' circular moves (docs/curves-welding.md).
:func:`cell.planning.plan.plan_welds` calls these for the ``curves`` it is given.

Frames: everything in the robot base frame R [m]; joints [rad]."""

from __future__ import annotations

from collections import Counter
from collections.abc import Collection, Mapping, Sequence
from dataclasses import replace
from typing import Any

import numpy as np
import numpy.typing as npt

from cell.geometry import readonly
from cell.planning.curves.partial import welded_share
from cell.planning.curves.refused import left_over, without_refused
from cell.planning.curves.search import plan_curve
from cell.planning.curves.split import ARC_MARK, Partial, Split, arc_id, seam_of
from cell.planning.failures import SeamFailure
from cell.planning.seam_search import SeamSearch, SeamSolution
from cell.process.procedures import UP_R, select_procedure
from cell.types import SeamStatus
from cell.types.curve_estimate import CurveEstimate
from cell.types.plan import (
    ArcSpan,
    NoProcedure,
    PlanReason,
    Remainder,
    SeamOutcome,
    SeamProcedure,
    SeamTask,
    Segment,
)
from cell.types.procedure import WeldProcedure
from cell.types.run import in_part_text


def weldable(curves: Sequence[CurveEstimate]) -> list[CurveEstimate]:
    """The found curves (a locator's other answers are its report's, never the planner's)."""
    return [c for c in curves if c.status is SeamStatus.FOUND]


def curve_procedures(
    curves: Sequence[CurveEstimate],
    joint_kinds: Mapping[str, str],
    legs_mm: Mapping[str, float],
    rows: Sequence[WeldProcedure],
    up_R: npt.ArrayLike = UP_R,
) -> dict[str, SeamProcedure | NoProcedure]:
    """The weld procedure of each found curve (the first row of the WPS table that fits): its joint type
    (``joint_kinds``, from the map's curved joint; ``any`` where none), its leg [mm], and its position judged where
    it is hardest (the sample whose fillet bisector points lowest, with the tangent there). A curve's direction
    is the planner's to choose: the procedure fixes none."""
    out: dict[str, SeamProcedure | NoProcedure] = {}
    for c in weldable(curves):
        b = np.asarray(c.n_abutting_R) + np.asarray(c.n_receiving_R)
        k = int(np.argmin(b @ np.asarray(up_R, dtype=float) / np.linalg.norm(b, axis=1)))
        p, t = c.p_RS[k], c.tangent_R[k]
        probe = SeamTask(c.id, p, p + 0.01 * t, c.n_abutting_R[k], c.n_receiving_R[k])
        sel = select_procedure(probe, joint_kinds.get(c.id, "any"), legs_mm.get(c.id, 4.0), rows, up_R)
        out[c.id] = replace(sel, reverse=False, fixed_direction=False) if isinstance(sel, SeamProcedure) else sel
    return out


def with_paths(segments: Sequence[Segment], paths: Mapping[str, Sequence[npt.ArrayLike]]) -> list[Segment]:
    """The segments with each curved seam's welds carrying their planned TCP poses (``X_path``, (n, 4, 4) in R;
    ``paths``: seam id -> one per pass, the k-th weld of the seam the k-th pass's)."""
    out: list[Segment] = []
    for s in segments:
        if s.kind == "weld" and s.seam_id in paths:
            s = replace(s, X_path=readonly(np.asarray(paths[s.seam_id][s.pass_index])))
        out.append(s)
    return out


def arc_spans(
    segments: Sequence[Segment], spans: Mapping[str, tuple[float, float]], in_part: Collection[str] = ()
) -> tuple[ArcSpan, ...]:
    """The arcs of the seams welded in several or in part (``spans``: arc id -> (from, to) [m] along its curve;
    ``in_part``: the seams welded in part, whose one arc is recorded too), each with when it runs among ``segments``
    (their ids still the arcs'): from the start of the move into it to the end of its depart, in time order."""
    many = Counter(seam_of(a) for a in spans)
    runs: dict[str, tuple[float, float]] = {}
    for g in segments:
        if g.seam_id in spans and (many[seam_of(g.seam_id)] > 1 or seam_of(g.seam_id) in in_part):
            runs[g.seam_id] = (runs.get(g.seam_id, (g.t0, 0.0))[0], g.t1)
    return tuple(sorted((ArcSpan(a, *spans[a], t0, t1) for a, (t0, t1) in runs.items()), key=lambda x: x.t0))


def cover_curves(
    curves: Sequence[CurveEstimate],
    make_search: Mapping[str, SeamSearch],
    q_seed: npt.ArrayLike,
    procedures: Mapping[str, WeldProcedure] | None = None,
    refused: Mapping[str, Sequence[Remainder]] | None = None,
) -> tuple[dict[str, tuple[SeamSolution, ...]], dict[str, SeamFailure], dict[str, Partial], dict[str, Span]]:
    """Each curve planned from its reach map (:func:`cell.planning.curves.arcs.plan_arcs`: one go where a torch
    setting holds all round, else the fewest overlapping arcs; an open one welded in one pass first by the one-go
    search, :func:`cell.planning.curves.search.plan_curve`, whose ranked candidates follow it closest), with its
    own search and procedure from q_seed (dof,) [rad]. ``refused``: seam id -> stretches along it whose arc was
    refused after the search (the safety gate), each with its code and why: that arc is left out alone
    (:func:`.refused.without_refused`), its stretch joined to the remainder (a seam covered whole then welded in
    part, only with ``curve_remainder: manual``; else, or with no arc left, the seam refused with that reason).
    Returns (arc id -> its solutions, one per pass, for the seams covered whole or in part; seam id -> its
    failure, for the others: where no arc reaches, with the share of the curve the arm reaches in its words; seam
    id -> what is left for a manual weld, for the seams welded in part, and with ``curve_remainder: manual`` for
    those covered whole in several arcs too, with no remainder, so that one failing after the search leaves the
    seam in part (:func:`whole_or_none`); arc id -> its (from, to) [m] along its curve, for the seams welded in
    arcs)."""
    from cell.planning.curves.arcs import plan_arcs

    q0, procs, out = np.asarray(q_seed, dtype=float), procedures or {}, refused or {}
    arcs: dict[str, tuple[SeamSolution, ...]] = {}
    still: dict[str, SeamFailure] = {}
    parts: dict[str, Partial] = {}
    spans: dict[str, Span] = {}
    for c in curves:
        proc = procs.get(c.id)
        got: Split | None = None
        if not c.closed and (proc is None or len(proc.passes) == 1):  # an open curve: the one-go search first
            one = plan_curve(make_search[c.id], c, q0, proc)
            if isinstance(one, SeamSolution):
                aid = arc_id(c.id, 1)
                got = Split(((replace(c, id=aid), (one,)),), 1.0, None, spans=((aid, 0.0, c.length_m),))
        got = got or plan_arcs(make_search[c.id], c, q0, proc, refused=out.get(c.id, ()))
        if not got.arcs and any(r.end for r in out.get(c.id, ())):  # every arc trimmed away: the first refusal
            first = next(r for r in out[c.id] if r.end)
            still[c.id] = SeamFailure(first.code, first.why, _at(c, first.from_m), 0.0)
            continue
        left = _still_named(got, out.get(c.id, ()))
        if left and got.arcs:
            got = _without(got, c, left, make_search[c.id])
            if not got.arcs:  # every arc refused: the refusal's reason
                assert got.failure is not None
                still[c.id] = got.failure
                continue
        if got.whole or got.partial:
            arcs |= {arc.id: sol for arc, sol in got.arcs}
            spans |= {aid: (a, b) for aid, a, b in got.spans}
            pr = make_search[c.id].process
            if got.partial or (len(got.arcs) > 1 and pr.curve_remainder == "manual"):  # a whole cover: may lose one
                own = {aid: (a, b) for aid, a, b in got.spans}
                lap = pr.closed_overlap if c.closed else 0.0
                parts[c.id] = Partial(c.length_m, c.closed, got.share, got.remainder, own, lap)
            continue
        f = got.failure
        assert f is not None
        tail = "not all" if got.share < 1.0 else "but in no overlapping arcs"
        still[c.id] = replace(f, where=f"{f.where} (the arm reaches {got.share:.0%} of it, {tail})")
    return arcs, still, parts, spans


Span = tuple[float, float]  # (from, to) [m] along a curve


def _still_named(got: Split, refused: Sequence[Remainder]) -> list[Remainder]:
    """The refusals of ``refused`` that still name an arc of ``got``: one of its weld (no ``end``), or one at an end
    whose arc is planned again on exactly its stretch (the partial cover trims such an arc,
    :func:`.partial.partial_arcs`; a whole cover's, or one it did not choose again, is left out so)."""
    spans = [(a, b) for _, a, b in got.spans]
    return [r for r in refused if not r.end or any(abs(a - r.from_m) + abs(b - r.to_m) < 1e-6 for a, b in spans)]


def _without(got: Split, c: CurveEstimate, refused: Sequence[Remainder], search: SeamSearch) -> Split:
    """``got`` with its arcs that the ``refused`` stretches name left out (:func:`.refused.without_refused`); a
    seam covered whole that would be left in part without the process's ``curve_remainder: manual``, or with no
    arc left: refused, with the first refusal's reason (share 0)."""
    pr = search.process
    spans = {aid: (a, b) for aid, a, b in got.spans}
    overlap = pr.closed_overlap if c.closed else 0.0
    gone, rest, share = without_refused(spans, refused, got.remainder, c.length_m, c.closed, overlap)
    if not gone:
        return got
    left = tuple((arc, sol) for arc, sol in got.arcs if arc.id not in gone)
    first = next(iter(gone.values()))
    if not left or (rest and not got.partial and pr.curve_remainder != "manual"):
        return Split((), 0.0, SeamFailure(first.code, first.why, _at(c, first.from_m), 0.0))
    kept_spans = tuple(s for s in got.spans if s[0] not in gone)
    return Split(left, share, got.failure, rest, kept_spans)


def _at(c: CurveEstimate, s_m: float) -> npt.NDArray[np.float64]:
    """The located curve's sample (3,) in R nearest ``s_m`` [m] along it."""
    k = int(np.argmin(np.abs(np.linspace(0.0, c.length_m, len(c.p_RS)) - s_m % c.length_m)))
    return np.asarray(c.p_RS[k])


def whole_or_none(
    solved: dict[str, Any],
    outcomes: dict[str, SeamOutcome],
    *others: dict[str, Any],
    parts: dict[str, Partial] | None = None,
) -> None:
    """A seam welded in arcs is welded whole or not at all: where one of its arcs failed after the search (its
    timing, a transfer to or from it: its outcome in ``outcomes`` under the arc's id), its other arcs leave
    ``solved`` (and each of ``others``) too and the seam takes the failed arc's outcome, named by the arc. A seam
    already welded in part (in ``parts``) loses only that arc: its stretch joins the seam's remainder, with the
    failure as its reason, less what its other arcs weld or the remainder lists already
    (:func:`.refused.left_over`); the seam is refused only when no arc is left. A seam covered whole that is in
    ``parts`` (no remainder: :func:`cover_curves` puts those there with ``curve_remainder: manual``) is so left
    welded in part."""
    for aid, o in list(outcomes.items()):
        sid = seam_of(aid)
        if sid == aid or o.feasible:
            continue
        why = f"arc {aid.rsplit(ARC_MARK, 1)[1]}: {o.reason}"
        part = (parts or {}).get(sid)
        left = [a for a in solved if seam_of(a) == sid]
        if part is not None and left:
            del outcomes[aid]
            a, b = part.spans[aid]
            gone = Remainder(a, b, o.code or PlanReason.IK_FAILED, why)
            kept = [part.spans[k] for k in left if k in part.spans]
            rest = left_over(kept, [gone], part.remainder, part.length_m, part.closed, part.overlap_m)
            assert parts is not None
            parts[sid] = replace(part, remainder=rest, share=welded_share(rest, part.length_m, part.closed))
            continue
        for other in left:
            solved.pop(other)
            for d in others:
                d.pop(other, None)
        del outcomes[aid]
        outcomes[sid] = replace(o, seam_id=sid, reason=why)
        (parts or {}).pop(sid, None)


def in_part(outcome: SeamOutcome, part: Partial, n_arcs: int) -> SeamOutcome:
    """A seam's planned outcome (feasible, as its first arc) welded in part: its share, its remainder and, in words,
    how much of it the ``n_arcs`` arcs weld and each stretch they leave for a manual weld."""
    why = in_part_text(part.share, part.remainder, n_arcs)
    return replace(outcome, reason=why, remainder=part.remainder, share=part.share)
