"""A curved seam welded in arcs that the safety gate faults on one arc: that arc left out alone (its stretch for a
manual weld with the gate's reason), the seam's other arcs kept and planned again; ``curve_remainder: refuse``
still drops the seam whole, and a seam whose every arc is refused is refused with the gate's reason
(docs/curves-welding.md section 9)."""

from __future__ import annotations

from dataclasses import replace
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

from cell.gate.answer import gate_answer
from cell.gate.base import Violation, ViolationKind
from cell.geometry import make_pose
from cell.planning.curves import cover_curves
from cell.planning.curves.split import Split
from cell.types.plan import ArcSpan, PlanReason, Remainder, Segment, WeldPlan
from cell.types.trajectory import Trajectory

SEAM = "POST>RAIL:circle"
A1, A2, A3 = (f"{SEAM}#arc{k}" for k in (1, 2, 3))
GAP = Remainder(0.90, 1.10, PlanReason.IK_FAILED, "no torch setting holds 200 mm of it")
SPANS = ((A1, 0.10, 0.40), (A2, 0.39, 0.70), (A3, 0.69, 0.90))  # each restarting 10 mm back over the last


def _plan() -> WeldPlan:
    """A straight seam "s", then the curve's three arcs (move in, approach, weld, depart each, 1 s apiece), home."""

    def seg(kind: str, sid: str, t0: float) -> Segment:
        tr = Trajectory(np.array([0.0, 1.0]), np.zeros((2, 6)), np.zeros((2, 6)), np.zeros((2, 6)))
        return Segment(kind, sid, tr, t0, make_pose(p=[0.0, 1.0, 0.1]), arc_on=kind == "weld")  # type: ignore[arg-type]

    kinds = [("move", "s"), ("weld", "s"), ("depart", "s")]
    kinds += [(k, SEAM) for _ in range(3) for k in ("move", "approach", "weld", "depart")] + [("move", "")]
    segs = tuple(seg(k, s, float(i)) for i, (k, s) in enumerate(kinds))
    arcs = tuple(ArcSpan(a, x, y, 3.0 + 4.0 * k, 7.0 + 4.0 * k) for k, (a, x, y) in enumerate(SPANS))
    return WeldPlan(("a1", "a2", "a3", "a4", "a5", "a6"), np.zeros(6), segs, (), ("s", SEAM), arcs=arcs)


def _sing(t: float) -> Violation:
    return Violation(ViolationKind.SINGULARITY, "manipulability 0.0003 below 0.01 on the approach", t)


def test_the_gate_names_the_arc_at_fault_and_leaves_out_only_it() -> None:
    plan = _plan()
    got = gate_answer(plan, [_sing(8.5)], set(), by_arc=True)  # arc 2's approach (past the curve's first arc)
    assert got is not None and not got.drop and not got.moves and list(got.arcs) == [A2]
    r = got.arcs[A2]
    assert (r.from_m, r.to_m, r.code) == (0.39, 0.70, PlanReason.SINGULAR)
    assert r.why == "arc 2: the safety gate: singularity at t = 8.500 s: " + _sing(8.5).what
    # the first arc's move in: another order first, then (that move avoided already) the arc alone
    first = gate_answer(plan, [_sing(4.5)], set(), by_arc=True)
    assert first is not None and first.moves == {SEAM: ("s", SEAM)} and not first.arcs
    again = gate_answer(plan, [_sing(4.5)], {("s", SEAM)}, by_arc=True)
    assert again is not None and list(again.arcs) == [A1] and not again.drop
    home = gate_answer(plan, [_sing(15.5)], set(), by_arc=True)  # the move home after the last arc: its
    assert home is not None and list(home.arcs) == [A3]
    # every seam at fault: the curve still loses its arc alone, the straight seam is dropped
    both = gate_answer(plan, [_sing(1.5), _sing(9.5)], set(), by_arc=True)
    assert both is not None and list(both.arcs) == [A2] and list(both.drop) == ["s"]
    # curve_remainder: refuse (or on a track): the seam dropped whole with the gate's reason, as before
    whole = gate_answer(plan, [_sing(8.5)], set(), by_arc=False)
    assert whole is not None and not whole.arcs and list(whole.drop) == [SEAM]
    assert whole.drop[SEAM].code is PlanReason.SINGULAR and "safety gate" in whole.drop[SEAM].reason


def _covered(got: Split, refused: list[Remainder], manual: bool = True) -> tuple[Any, ...]:
    """cover_curves on one closed curve 1 m long whose reach map gives ``got``, with ``refused`` stretches."""
    import cell.planning.curves.arcs as arcs_mod

    curve = SimpleNamespace(id=SEAM, closed=True, length_m=1.0, p_RS=np.zeros((5, 3)))
    pr = SimpleNamespace(closed_overlap=0.01, curve_remainder="manual" if manual else "refuse")
    search = SimpleNamespace(process=pr)
    mp = pytest.MonkeyPatch()
    mp.setattr(arcs_mod, "plan_arcs", lambda *_a, **_k: got)
    try:
        return cover_curves([curve], {SEAM: search}, np.zeros(6), None, {SEAM: refused})  # type: ignore[list-item,dict-item]
    finally:
        mp.undo()


def _split(spans: tuple[tuple[str, float, float], ...], rest: tuple[Remainder, ...]) -> Split:
    arcs = tuple((SimpleNamespace(id=a), (f"solution {a}",)) for a, _, _ in spans)
    return Split(arcs, 0.8 if rest else 1.0, None, rest, spans)  # type: ignore[arg-type]


def test_a_partial_seam_loses_the_refused_arc_alone_its_stretch_in_the_remainder() -> None:
    gate = Remainder(0.39, 0.70, PlanReason.SINGULAR, "arc 2: the safety gate: singularity on its approach")
    arcs, still, parts, spans = _covered(_split(SPANS, (GAP,)), [gate])
    assert sorted(arcs) == [A1, A3] and not still and set(spans) == {A1, A3}
    rest = parts[SEAM].remainder
    # arc 2's stretch less what arcs 1 and 3 weld (no overlapping items), then the gap as it was
    assert [(r.from_m, r.to_m, r.code) for r in rest] == [
        pytest.approx((0.40, 0.69, PlanReason.SINGULAR)),
        (0.90, 1.10, PlanReason.IK_FAILED),
    ]
    assert rest[0].why == gate.why and parts[SEAM].share == pytest.approx(1.0 - 0.29 - 0.20, abs=0.002)


def test_a_whole_cover_is_welded_in_part_under_manual_and_refused_under_refuse() -> None:
    whole = ((A1, 0.0, 0.51), (A2, 0.50, 1.01))
    gate = Remainder(0.0, 0.51, PlanReason.SINGULAR, "arc 1: the safety gate: singularity on its approach")
    arcs, still, parts, _ = _covered(_split(whole, ()), [gate])
    assert list(arcs) == [A2] and not still
    assert [(r.from_m, r.to_m) for r in parts[SEAM].remainder] == [pytest.approx((0.01, 0.50))]
    assert parts[SEAM].share == pytest.approx(0.51, abs=0.002)
    arcs, still, parts, _ = _covered(_split(whole, ()), [gate], manual=False)
    assert not arcs and not parts and still[SEAM].code is PlanReason.SINGULAR and still[SEAM].where == gate.why


def test_a_seam_whose_every_arc_is_refused_is_refused_with_the_gates_reason() -> None:
    gates = [Remainder(a, b, PlanReason.SINGULAR, f"arc {k}: the safety gate: x") for k, (_, a, b) in enumerate(SPANS)]
    arcs, still, parts, _ = _covered(_split(SPANS, (GAP,)), gates)
    assert not arcs and not parts and still[SEAM].where == "arc 0: the safety gate: x"


def test_a_transfers_via_point_past_the_hose_window_is_taken_a_whole_turn_back_into_it() -> None:
    """A hop's via point solved by continuity from a wrist wound far round (A6 past the window) holds the same pose
    with A6 a whole turn back: the way is no longer refused for the window (railing's POST_R bottom fillet: every
    lifted way out of its arc's depart left the window by 10-33 deg)."""
    from tiny_cell import HOME, OBSTACLES, URDF

    import cell.planning.transfers as tr_mod
    from cell import scenario as sc
    from cell.config.motion import PlanOptions
    from cell.motion.collision import CollisionChecker
    from cell.motion.robot import RobotModel
    from cell.process.torch import WeldProcess

    robot = RobotModel.from_urdf(URDF)
    opt = PlanOptions()
    moves = tr_mod.Transfers(
        robot, WeldProcess.from_spec(sc.ProcessSpec()), CollisionChecker(robot, OBSTACLES), opt, OBSTACLES, HOME
    )
    q = np.asarray(HOME, dtype=float).copy()
    q[-1] = opt.a6_center - opt.a6_window + np.radians(5.0)  # inside the window, 5 deg from its edge
    wound = q.copy()
    wound[-1] -= np.radians(20.0)  # the IK's answer by continuity: 15 deg past the edge
    mp = pytest.MonkeyPatch()
    mp.setattr(tr_mod, "solve_ik", lambda *_a, **_k: wound)
    try:
        via = moves.above(q, float(robot.fk(q)[2, 3]) + 0.1)
    finally:
        mp.undo()
    assert via is not None and moves.window.excess(via) == 0.0
    assert np.degrees(via[-1] - wound[-1]) == pytest.approx(360.0) and np.allclose(via[:-1], wound[:-1])
    assert np.allclose(robot.fk(via), robot.fk(wound), atol=1e-9)


def test_a_whole_covers_arc_no_transfer_reaches_leaves_the_seam_in_part_under_manual() -> None:
    """cover_curves lists a seam covered whole in several arcs among the parts (no remainder) with
    ``curve_remainder: manual``; an arc of it that a transfer cannot reach then leaves alone (whole_or_none), its
    stretch less what the other arcs weld in the remainder, as a partial seam's; with ``refuse``: refused whole."""
    from cell.planning.curves import whole_or_none
    from cell.types.plan import SeamOutcome

    whole = ((A1, 0.0, 0.51), (A2, 0.50, 1.01))
    for manual in (True, False):
        arcs, _, parts, _ = _covered(_split(whole, ()), [], manual=manual)
        assert sorted(arcs) == [A1, A2] and (SEAM in parts) == manual
        solved = {A1: 1, "OTHER": 0}
        why = "transfer_collision: no free transfer move to the seam: ..."
        no_way = SeamOutcome(A2, False, why, np.zeros(3), code=PlanReason.TRANSFER_COLLISION)
        outcomes = {A2: no_way}
        whole_or_none(solved, outcomes, parts=parts)
        if manual:
            assert solved == {A1: 1, "OTHER": 0} and outcomes == {}
            rest = parts[SEAM].remainder
            assert [(r.from_m, r.to_m, r.code) for r in rest] == [(0.51, 1.0, PlanReason.TRANSFER_COLLISION)]
            assert rest[0].why == f"arc 2: {why}" and parts[SEAM].share == pytest.approx(0.51, abs=0.002)
        else:
            assert solved == {"OTHER": 0} and not outcomes[SEAM].feasible


def test_the_gate_says_which_end_of_the_arc_it_refuses() -> None:
    """A refusal on an arc's move in or approach is at its start, on its depart or the move home after it at its
    end, on its weld at neither (the partial cover trims the arc at that end, :func:`partial_arcs`)."""
    plan = _plan()
    again = gate_answer(plan, [_sing(4.5)], {("s", SEAM)}, by_arc=True)  # arc 1's move in, avoided already
    assert again is not None and again.arcs[A1].end == "start"
    ends = {t: gate_answer(plan, [_sing(t)], set(), by_arc=True) for t in (8.5, 9.5, 10.5, 15.5)}
    got = {t: [(a, r.end) for a, r in g.arcs.items()] for t, g in ends.items() if g is not None}
    assert got == {8.5: [(A2, "start")], 9.5: [(A2, "")], 10.5: [(A2, "end")], 15.5: [(A3, "end")]}


def test_a_seam_welded_in_part_in_one_arc_is_recorded_so_the_gate_can_refuse_that_arc() -> None:
    """arc_spans records the one arc of a seam welded in part (before: only seams of two arcs or more, so the gate
    dropped such a seam whole); a seam welded whole in one go is not recorded."""
    from cell.planning.curves import arc_spans

    plan = _plan()
    one = [replace(s, seam_id=A1 if s.seam_id == SEAM else s.seam_id) for s in plan.segments[:7]]
    assert arc_spans(one, {A1: (0.1, 0.4)}) == ()
    got = arc_spans(one, {A1: (0.1, 0.4)}, {SEAM})
    assert got == (ArcSpan(A1, 0.1, 0.4, 3.0, 7.0),)
    single = replace(plan, segments=tuple(replace(s, seam_id=SEAM if s.seam_id == A1 else s.seam_id) for s in one),
                     arcs=got, order=("s", SEAM))  # fmt: skip
    refused = gate_answer(single, [_sing(4.5)], {("s", SEAM)}, by_arc=True)
    assert refused is not None and not refused.drop and list(refused.arcs) == [A1]
    assert (refused.arcs[A1].from_m, refused.arcs[A1].to_m, refused.arcs[A1].end) == (0.1, 0.4, "start")


def test_an_arc_refused_at_an_end_and_planned_again_trimmed_is_kept() -> None:
    """cover_curves leaves out an arc a refusal names only when it is planned again on exactly the refused stretch
    (its weld refused, or a whole cover's arc); the partial cover's arc trimmed at the refused end stays."""
    gate = Remainder(0.10, 0.40, PlanReason.SINGULAR, "arc 1: the safety gate: singularity", "start")
    trimmed = ((A1, 0.115, 0.40), (A2, 0.39, 0.70), (A3, 0.69, 0.90))
    arcs, still, _, _ = _covered(_split(trimmed, (GAP,)), [gate])
    assert sorted(arcs) == [A1, A2, A3] and not still
    arcs, still, _, _ = _covered(_split(SPANS, (GAP,)), [gate])  # the same arc again: left out, as before
    assert sorted(arcs) == [A2, A3]


def test_an_exit_is_at_fault_when_the_move_out_of_an_arc_failed_towards_another_place_too() -> None:
    """The order search tries the ways out of an arc's exits (retreats) only where a move out of it failed towards
    two places or more (not where one move failed, nor out of a straight seam or a curve welded whole or refused)."""
    from cell.planning.curves.refused import exit_at_fault
    from cell.planning.curves.split import Partial

    parts = {SEAM: Partial(1.0, True, 0.8, (GAP,), {a: (x, y) for a, x, y in SPANS}, 0.01)}
    assert not exit_at_fault(A1, "TOP#arc1", {(A1, "TOP#arc1")}, parts)  # its first failure: another order first
    assert exit_at_fault(A1, "TOP#arc1", {(A1, "B1"), (A1, "TOP#arc1")}, parts)  # towards B1 too
    assert exit_at_fault(A1, "", {(A1, "B1"), (A1, "")}, parts)  # home too
    assert not exit_at_fault(A1, "TOP#arc1", {("B1", "TOP#arc1"), (A1, "TOP#arc1")}, parts)  # into it: not its exit
    assert not exit_at_fault("B1", "C1", {("B1", "X"), ("B1", "C1")}, parts)  # a straight seam: as before
    assert not exit_at_fault(A1, "B1", {(A1, "X"), (A1, "B1")}, {})  # a curve not welded in part: as before
