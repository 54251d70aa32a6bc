"""A curved seam's arc whose way out fails towards two places: its exit at fault (not the arc the move leads to),
refused at its end and planned again trimmed there, kept only where the trimmed arc still welds its stretch
(docs/curves-welding.md section 9, "A failing exit planned again")."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from cell.planning.curves.exits import Replanned, exit_at_fault, exit_refusal, still_welds
from cell.planning.curves.split import Partial
from cell.planning.moves.pieces import TransferFail
from cell.types.plan import PlanReason

SEAM = "POST_L>BOTTOM_RAIL:circle"
A1, A2 = f"{SEAM}#arc1", f"{SEAM}#arc2"
PART = {SEAM: Partial(0.15, True, 0.3, (), {A1: (0.05, 0.09)}, 0.01)}


def test_an_exit_is_at_fault_when_the_move_out_of_an_arc_failed_towards_another_place_before() -> None:
    assert not exit_at_fault(A1, "TOP#arc1", set(), PART)  # its first failure: another order first
    assert exit_at_fault(A1, "TOP#arc1", {(A1, "B1")}, PART)  # out of it towards B1, now towards TOP
    assert exit_at_fault(A1, "", {(A1, "B1")}, PART)  # home too
    assert not exit_at_fault(A1, "B1", {(A1, "B1")}, PART)  # the same transfer again: not the exit's alone
    assert not exit_at_fault("B1", "C1", {("B1", "X")}, PART)  # a straight seam: as before
    assert not exit_at_fault(A1, "B1", {(A1, "X")}, {})  # a curve not welded in part (refuse): as before


def test_the_exits_refusal_names_the_arc_its_end_and_the_transfers_contact() -> None:
    fail = TransferFail("link_4 vs link_6 at t = 0.364 s", np.zeros(3))
    r = exit_refusal(A2, (0.05, 0.09), fail, home=False)
    assert (r.from_m, r.to_m, r.code, r.end) == (0.05, 0.09, PlanReason.TRANSFER_COLLISION, "end")
    assert r.why == "arc 2: no free transfer move from the seam (its way out planned again): " + fail.reason
    assert "move home from" in exit_refusal(A2, (0.05, 0.09), fail, home=True).why


def test_a_replan_is_kept_only_where_the_trimmed_arc_still_welds_most_of_its_stretch() -> None:
    curve = SimpleNamespace(length_m=0.15, closed=True)
    part = PART[SEAM]
    trimmed = Replanned({A1: ()}, {A1: (0.05, 0.07)}, part, None)
    assert still_welds(trimmed, (0.05, 0.09), curve)  # type: ignore[arg-type]
    gone = Replanned({A2: ()}, {A2: (0.10, 0.14)}, part, None)  # the arc left out: another arc to lose, not it
    assert not still_welds(gone, (0.05, 0.09), curve)  # type: ignore[arg-type]
    assert not still_welds(Replanned({}, {}, None, None), (0.05, 0.09), curve)  # type: ignore[arg-type]
    round_start = Replanned({A1: ()}, {A1: (0.14, 0.175)}, part, None)  # past a closed curve's start
    assert still_welds(round_start, (-0.01, 0.03), curve)  # type: ignore[arg-type]
