"""A loop the coordinated weld cannot weld whole, welded in part: the longest stretch of knots the arm holds, where
it lies on the located curve, what it leaves for a manual weld, and how the positioner's exit line says it."""

from __future__ import annotations

import pytest

from cell.coordinated.partial import leftover, on_curve, stretches
from cell.planning.curves.reach import Miss
from cell.types.plan import PlanReason


def test_the_longest_held_stretch_is_chosen_and_a_joint_jump_breaks_one() -> None:
    ok = [True, True, False, True, True, True, True, False, True]
    assert stretches(ok, [True] * 9)[0] == (3, 6)  # four knots held between two the arm does not
    # A joint jump (a flip) between knots 4 and 5 cuts that stretch: the first two knots, as long, come first.
    link = [True] * 9
    link[5] = False
    assert stretches(ok, link)[:3] == [(0, 1), (3, 4), (5, 6)]
    assert stretches([False] * 4, [True] * 4) == []


def test_a_stretch_welded_against_the_curve_and_over_its_start_lies_where_it_is_on_the_curve() -> None:
    total = 0.36
    # Welded along the curve from 0.30 m: 0.02 to 0.10 m on from there is 0.32 m round to 0.40 m (past its length).
    assert on_curve(0.30, False, 0.02, 0.10, total, True) == pytest.approx((0.32, 0.40))
    # Welded against it from 0.05 m: 0.02 to 0.10 m on is 0.31 m (round the start) to 0.39 m in the curve's order.
    assert on_curve(0.05, True, 0.02, 0.10, total, True) == pytest.approx((0.31, 0.39))
    assert on_curve(0.20, True, 0.02, 0.10, 0.20, False) == pytest.approx((0.10, 0.18))  # an open one, from its end


def test_the_remainder_of_a_loop_runs_from_the_welds_end_round_to_its_start_with_what_stops_the_arm() -> None:
    total = 0.36
    misses = [Miss(0.22, PlanReason.IK_FAILED, "IK: joint_a3 at its limit")] * 3 + [
        Miss(0.25, PlanReason.COLLISION, "camera_link vs POSITIONER_CRADLE")
    ]
    (rest,) = leftover([(0.32, 0.52)], total, True, misses)  # welded 0.32 round to 0.16 m
    assert (rest.from_m, rest.to_m) == pytest.approx((0.16, 0.32))  # from 0.16 m on the curve's own lap
    assert leftover([(0.02, 0.30)], total, True, misses)[0].to_m == pytest.approx(0.38)  # round its start
    assert rest.code is PlanReason.IK_FAILED and "3 of 4 tries IK: joint_a3 at its limit" in rest.why
    assert "stops 5 mm short" in rest.why
    # An open curve: what lies before and after the weld, each on its own.
    ends = leftover([(0.03, 0.15)], 0.20, False, misses)
    assert [v for r in ends for v in (r.from_m, r.to_m)] == pytest.approx([0.0, 0.03, 0.15, 0.20])
    assert leftover([(0.0, 0.20)], 0.20, False, misses) == ()


def test_the_positioner_exit_line_says_a_curve_welded_in_part_as_the_fixed_arm_does() -> None:
    from cell.cli.positioner import partial_line

    rep = {
        "seams": [
            {"welded": True, "reason_code": None},
            {"welded": False, "reason_code": "partial"},
            {"welded": False, "reason_code": "low_confidence"},
        ],
        "totals": {"welded": 1, "seams": 3, "manual_mm": 137.0},
    }
    line = partial_line(rep)
    assert line == (
        "exit 3: 1 seam not welded (low_confidence: 1); 1 curved seam partly welded: 137 mm left for a manual weld; "
        "1/3 welded"
    )


def test_a_loop_is_welded_in_part_only_with_curve_remainder_manual(monkeypatch: pytest.MonkeyPatch) -> None:
    from types import SimpleNamespace

    import cell.coordinated.partial as partial
    import cell.coordinated.plan as plan
    from cell.errors import PlanError
    from cell.pipeline.coordinated.job import _planned

    def whole(*_a: object, **_k: object) -> None:
        raise PlanError("no coordinated motion: the torch vs POST")

    monkeypatch.setattr(plan, "plan_coordinated", whole)
    monkeypatch.setattr(plan, "candidates", lambda su, c: ["a candidate"])
    monkeypatch.setattr(partial, "plan_in_part", lambda su, c, rng: "in part")
    opt = SimpleNamespace(spacing=0.0025)

    def planned(remainder: str) -> object:
        process = SimpleNamespace(travel_speed=0.008, curve_remainder=remainder)
        c = SimpleNamespace(id="C")
        return _planned(None, None, c, process, opt, None, [0.0] * 6, None, None, lambda _: None)  # type: ignore[arg-type]

    assert planned("manual") == "in part"
    with pytest.raises(PlanError, match="torch vs POST"):  # refused whole, as before
        planned("refuse")
    monkeypatch.setattr(plan, "candidates", lambda su, c: [])  # no axes hold it in PA: nothing to weld in part
    with pytest.raises(PlanError, match="torch vs POST"):
        planned("manual")


def test_a_loop_is_covered_by_arcs_restarting_the_overlap_over_the_bead_or_left_with_the_smaller_remainder() -> None:
    from cell.coordinated.cover import cover, loop_gaps

    total, ov, arc = 0.36, 0.010, 0.02
    # Two candidates' stretches: the first arc 0.00-0.22 m; the other holds 0.21-0.37 m (round the start): it
    # reaches 10 mm back over the bead at both ends, so the loop is welded whole in two arcs.
    (i, lo, hi), *more = cover((0.0, 0.22), [(0.0, 0.22), (0.21, 0.37)], total, ov, arc)
    assert (i, more) == (1, []) and (lo, hi) == pytest.approx((0.21, 0.37))
    assert loop_gaps([(0.0, 0.22), (lo, hi)], total) == []
    # Held 5 mm short of either overlap (0.215-0.365 m): each end a free end 10 mm off the bead, 20 mm left.
    ((_, lo, hi),) = cover((0.0, 0.22), [(0.0, 0.22), (0.215, 0.365)], total, ov, arc)
    assert (lo, hi) == pytest.approx((0.23, 0.35))
    assert sum(b - a for a, b in loop_gaps([(0.0, 0.22), (lo, hi)], total)) == pytest.approx(0.02)
    # Nothing holds 0.25-0.30 m (tube-tee's end plates): two more arcs, one from each junction, 50 mm left.
    arcs = cover((0.0, 0.22), [(0.0, 0.22), (0.15, 0.25), (0.30, 0.40)], total, ov, arc)
    assert sorted((round(a, 3), round(b, 3)) for _, a, b in arcs) == [(0.21, 0.25), (0.3, 0.37)]
    left = loop_gaps([(0.0, 0.22), *((a, b) for _, a, b in arcs)], total)
    assert [v for g in left for v in g] == pytest.approx([0.25, 0.30])
    # The planner's own loop: an arc it cannot plan gives way to the next best within its tries, else ends the cover.
    held = [(0.0, 0.22), (0.15, 0.25), (0.30, 0.40)]
    assert cover((0.0, 0.22), held, total, ov, arc, planned=lambda i, lo, hi: i != 2) == []
    got = cover((0.0, 0.22), held, total, ov, arc, planned=lambda i, lo, hi: i != 2, tries=3)
    assert [(i, round(a, 3), round(b, 3)) for i, a, b in got] == [(1, 0.21, 0.25)]
    # What the arcs leave for a manual weld, with the first arc's words: that stretch alone.
    misses = [Miss(0.27, PlanReason.IK_FAILED, "IK: joint_a3 at its limit")]
    (rest,) = leftover([(0.0, 0.22), *((a, b) for _, a, b in arcs)], total, True, misses)
    assert (rest.from_m, rest.to_m) == pytest.approx((0.25, 0.30)) and rest.code is PlanReason.IK_FAILED
