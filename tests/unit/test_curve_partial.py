"""A curved seam welded in part: the arcs that weld what the reach map holds, the remainder left for a manual weld
(where, how long, why), a partial seam's failed arc, and how a run says so (docs/curves-welding.md section 10)."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest

from cell.planning.curves.partial import partial_cover, remainder, welded_share
from cell.planning.curves.reach import Miss, Run
from cell.planning.curves.split import MAX_PARTIAL_ARCS, Partial
from cell.process.torch_orientations import Candidate
from cell.types.plan import PlanReason, Remainder, SeamOutcome

OVERLAP_M = 0.01
MIN_ARC_M = 0.02
C0 = Candidate(False, 0.0, 0.0, 0.0)
C1 = Candidate(True, 0.5, 0.0, 0.0)
GUSSET = [Miss(0.95 + 0.01 * k, PlanReason.COLLISION, "torch vs GUSSET") for k in range(10)]


def _run(a: float, b: float, cand: Candidate = C0) -> Run:
    return Run(cand, a, b, np.zeros(6))


def _spans(got: list[tuple[Run, Run]]) -> list[tuple[float, float]]:
    return [(p.a_m, p.b_m) for _, p in got]


def test_a_closed_curve_with_a_gap_is_welded_up_to_its_edges_restarting_over_the_bead() -> None:
    runs = [_run(0.1, 0.5), _run(0.45, 0.9, C1), _run(0.2, 0.3)]  # nothing holds 0.9 -> 1.1 (round the start)
    got = partial_cover(runs, 1.0, True, OVERLAP_M, MIN_ARC_M)
    assert [r.cand for r, _ in got] == [C0, C1]
    (a1, b1), (a2, b2) = _spans(got)
    assert a1 == pytest.approx(0.105) and b2 == pytest.approx(0.895)  # each stops 5 mm short of the gap's edge
    assert b1 - a2 == pytest.approx(OVERLAP_M)  # the restart the WPS's overlap back, the excess shared out
    rest = remainder(_spans(got), runs, GUSSET, 1.0, True, OVERLAP_M)
    assert [(r.from_m, r.to_m) for r in rest] == [pytest.approx((0.895, 1.105))]
    assert rest[0].code is PlanReason.COLLISION and "no torch setting holds 200 mm" in rest[0].why
    assert "torch vs GUSSET" in rest[0].why
    assert welded_share(rest, 1.0, True) == pytest.approx(0.79, abs=0.002)


def test_a_pinch_is_left_for_a_manual_weld_never_restarted_with_a_shorter_overlap() -> None:
    # every point held, but both stretches through 1.0 (= 0) give out 2 mm from it: a restart there overlaps 4 mm
    runs = [_run(0.1, 1.002), _run(0.998, 1.15, C1), *(_run(0.1 * k, 0.1 * k + 0.3) for k in range(1, 7))]
    got = partial_cover(runs, 1.0, True, OVERLAP_M, MIN_ARC_M)
    spans = _spans(got)
    for (_, b), (a, _) in itertools.pairwise(spans):
        assert b - a >= OVERLAP_M - 1e-9 or b - a == pytest.approx(0.004)  # the WPS overlap, but at the pinch
    misses = [Miss(0.999, PlanReason.COLLISION, "torch vs POST")] * 3
    rest = remainder(spans, runs, misses, 1.0, True, OVERLAP_M)
    assert len(rest) == 1 and rest[0].length_m == pytest.approx(OVERLAP_M)  # the overlap about the restart
    mid = (0.5 * (rest[0].from_m + rest[0].to_m)) % 1.0
    assert min(mid, 1.0 - mid) < 0.001
    assert "restart over each other by 4.0 mm < the WPS's 10 mm" in rest[0].why and "torch vs POST" in rest[0].why
    assert welded_share(rest, 1.0, True) == pytest.approx(0.99, abs=0.002)  # never counted whole
    # a restart the overlap deep everywhere: nothing is left
    assert remainder([(0.0, 0.6), (0.5, 1.01)], runs, misses, 1.0, True, OVERLAP_M) == []


def test_an_open_curve_with_a_gap_and_an_unheld_start() -> None:
    runs = [_run(0.05, 0.4), _run(0.5, 1.0, C1)]
    got = partial_cover(runs, 1.0, False, 0.0, MIN_ARC_M)
    assert _spans(got) == [pytest.approx((0.055, 0.395)), pytest.approx((0.505, 1.0))]  # the curve's end: to it
    rest = remainder(_spans(got), runs, [Miss(0.45, PlanReason.IK_FAILED)], 1.0, False, 0.0)
    assert [(r.from_m, r.to_m) for r in rest] == [pytest.approx((0.0, 0.055)), pytest.approx((0.395, 0.505))]
    assert all(r.code is PlanReason.IK_FAILED for r in rest)


def test_short_stretches_and_arcs_beyond_the_bound_go_to_the_manual_weld() -> None:
    runs = [_run(0.1 * k, 0.1 * k + 0.05) for k in range(10)] + [_run(0.975, 0.99)]  # 10 held, one too short
    got = partial_cover(runs, 1.0, True, OVERLAP_M, MIN_ARC_M)
    assert len(got) == MAX_PARTIAL_ARCS and all(p.length >= MIN_ARC_M for _, p in got)
    rest = remainder(_spans(got), runs, [], 1.0, True, OVERLAP_M)
    assert welded_share(rest, 1.0, True) == pytest.approx(0.32, abs=0.003)  # 8 of 40 mm, each 5 mm off its gaps
    beyond = [r for r in rest if "the rest held only in stretches too short to weld or beyond the arcs' bound" in r.why]
    assert beyond and all(r.why.startswith("no torch setting holds") for r in beyond)  # with stretches nothing holds
    assert all("bound" not in r.why for r in rest if r not in beyond)


def test_a_partial_seams_failed_arc_is_dropped_alone_and_joins_the_remainder() -> None:
    from cell.planning.curves import whole_or_none

    seam = "PIPE>FLANGE:circle"
    gap = Remainder(0.9, 1.1, PlanReason.COLLISION, "no torch setting holds 200 mm of it")
    spans = {f"{seam}#arc1": (0.1, 0.48), f"{seam}#arc2": (0.47, 0.9)}
    parts = {seam: Partial(1.0, True, 0.8, (gap,), spans)}
    solved = {f"{seam}#arc1": 1, "OTHER": 0}  # arc 2 failed its timing after the search
    failed = SeamOutcome(f"{seam}#arc2", False, "A1 too fast", np.zeros(3), code=PlanReason.TIMING)
    outcomes = {f"{seam}#arc2": failed}
    whole_or_none(solved, outcomes, parts=parts)
    assert solved == {f"{seam}#arc1": 1, "OTHER": 0} and outcomes == {}
    rest = parts[seam].remainder
    # arc 2's stretch less the 10 mm arc 1 welds over it (no two items overlap), then the gap
    assert [(r.from_m, r.to_m, r.code) for r in rest] == [(0.48, 0.9, PlanReason.TIMING), (0.9, 1.1, gap.code)]
    assert rest[0].why == "arc 2: A1 too fast" and parts[seam].share == pytest.approx(0.38, abs=0.002)
    solved.pop(f"{seam}#arc1")  # its last arc fails too (out of the plan, as a timing failure takes it): refused
    outcomes = {f"{seam}#arc1": replace_id(failed, f"{seam}#arc1")}
    whole_or_none(solved, outcomes, parts=parts)
    assert solved == {"OTHER": 0} and not outcomes[seam].feasible and seam not in parts


def replace_id(o: SeamOutcome, sid: str) -> SeamOutcome:
    from dataclasses import replace

    return replace(o, seam_id=sid)


def test_a_partial_curve_is_said_apart_in_the_outcome_the_exit_line_and_the_tables() -> None:
    from cell.cli.printout.explain import weld_exit
    from cell.cli.printout.tables import not_supported_text
    from cell.planning.curves import in_part

    rest = (
        Remainder(0.167, 0.174, PlanReason.IK_FAILED, "no torch setting holds 7 mm of it"),
        Remainder(0.3, 0.314, PlanReason.COLLISION, "no torch setting holds 14 mm of it"),
    )
    o = in_part(SeamOutcome("PIPE>FLANGE:circle", True), Partial(0.688, True, 0.97, rest, {}), 3)
    assert o.feasible and o.partial and o.share == 0.97
    assert o.reason.startswith("welded in part: 97% in 3 arcs, 21 mm left for a manual weld: 167-174 mm along it")
    assert "(7 mm, ik_failed: no torch setting holds 7 mm of it)" in o.reason
    curve = {"status": "found", "curved": True, "welded": False, "planned": True, "weld_reason_code": "partial"}
    straight = {"status": "found", "welded": True, "planned": True}
    summary = {"curved": {"partial": 1, "manual_mm": 21.0, "not_welded": {"partial": 1}}, "not_supported": {}}
    rep = {"seams": [straight, curve], "lost_cameras": [], "error": None, "welded": 1, "summary": summary}
    assert weld_exit(rep) == "exit 3: 1 curved seam partly welded: 21 mm left for a manual weld; 1/2 welded"
    assert not_supported_text(summary) == "1 curved seam partly welded: 21 mm left for a manual weld"


def test_on_a_track_a_curve_no_carriage_position_welds_whole_is_welded_in_part_from_its_first() -> None:
    from types import SimpleNamespace

    from cell.planning.curves.track import in_part_at

    gap = (Remainder(0.1, 0.12, PlanReason.COLLISION, "no torch setting holds 20 mm of it"),)
    curves = [SimpleNamespace(id=k) for k in ("A", "B", "C")]
    refused = SeamOutcome("A", False, "no torch setting holds it", code=PlanReason.COLLISION)
    outcomes = {
        "A": refused,
        "B": SeamOutcome("B", True),  # welded whole from some E1: left alone
        "C": replace_id(refused, "C"),
    }
    asked: list[tuple[float, str]] = []

    def plan_at(e1: float, c: SimpleNamespace) -> SimpleNamespace:
        asked.append((e1, c.id))
        part = SeamOutcome(c.id, True, "welded in part", remainder=gap, share=0.97)
        return SimpleNamespace(seams=(part if c.id == "A" else replace_id(refused, c.id),))

    got = in_part_at(curves, {"A": (0.4, 0.0), "B": (0.0,), "C": (0.2,)}, outcomes, plan_at)  # type: ignore[arg-type]
    assert asked == [(0.4, "A"), (0.2, "C")]  # each from its first E1 only
    assert [e1 for e1, _ in got] == [0.4] and outcomes["A"].partial and outcomes["A"].share == 0.97
    assert outcomes["C"] is not refused and not outcomes["C"].feasible and outcomes["B"].feasible


def test_a_partial_curve_in_the_report_and_the_programs_header() -> None:
    from cell.cli.turnover import not_welded
    from cell.export.reports.curve_report import weld_entry
    from cell.types.run import SeamWeld, WeldReason

    rest = (Remainder(0.161, 0.179, PlanReason.IK_FAILED, "no torch setting holds 7 mm of it"),)
    w = SeamWeld("PIPE>FLANGE:circle", True, False, "welded in part: ...", code=WeldReason.PARTIAL, share=0.974,
                 remainder=rest)  # fmt: skip
    assert w.partial and w.manual_m == pytest.approx(0.018)
    entry = weld_entry(w)
    assert entry["welded"] is False and entry["planned"] is True and entry["weld_reason_code"] == "partial"
    assert entry["share"] == 0.974 and entry["manual_mm"] == 18.0
    assert entry["remainder"] == [
        {"from_mm": 161.0, "to_mm": 179.0, "length_mm": 18.0, "code": "ik_failed", "why": rest[0].why}
    ]
    rep = {"seams": [{"id": w.id, "status": "found", "reason_code": None, **entry}]}
    assert not_welded(rep) == (
        (w.id, "partial: 18 mm left for a manual weld at 161-179 mm (ik_failed) along it"),
    )  # the programs' header


def test_the_welders_list_gives_each_stretch_where_it_lies_on_the_drawing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A remainder's ends are the located curve's points that far along it, in the drawing's frame (the part's
    pose undone); the list beside the programs has one row per stretch, none when no curve is welded in part."""
    import csv

    from cell.cli.printout.tables import print_curves
    from cell.export.reports.curve_report import MANUAL_WELDS, weld_entry, write_manual_welds
    from cell.geometry import invert, make_pose
    from cell.types import SeamStatus
    from cell.types.curve_estimate import CurveEstimate
    from cell.types.run import SeamWeld, WeldReason

    r_m, n = 0.05, 400  # a 50 mm circle about the drawing's z axis, sampled from +x anticlockwise
    t = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    p_MS = np.column_stack([r_m * np.cos(t), r_m * np.sin(t), np.zeros(n)])
    X_RM = make_pose(np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]), [0.4, 0.9, 0.1])
    p_RS = p_MS @ X_RM[:3, :3].T + X_RM[:3, 3]
    est = CurveEstimate("TUBE>PLATE:circle", SeamStatus.FOUND, p_RS=p_RS, n_abutting_R=np.tile([0, 0, 1.0], (n, 1)),
                        n_receiving_R=np.tile([1.0, 0, 0], (n, 1)), closed=True, sigma_m=np.full(n, 1e-4))  # fmt: skip
    quarter = est.length_m / 4  # a quarter round from +x: the drawing's +y; the stretch passes the curve's start
    rest = (Remainder(quarter, 2 * quarter, PlanReason.COLLISION, "torch vs GUSSET_1"),
            Remainder(3.5 * quarter, 4.5 * quarter, PlanReason.IK_FAILED, "no torch setting holds it"))  # fmt: skip
    w = SeamWeld(est.id, True, False, "welded in part", code=WeldReason.PARTIAL, share=0.625, remainder=rest)
    entry = weld_entry(w, est, invert(X_RM))
    got = [(e["from_xyz_mm"], e["to_xyz_mm"]) for e in entry["remainder"]]
    s45 = 50.0 * np.sqrt(0.5)
    want = [([0.0, 50.0, 0.0], [-50.0, 0.0, 0.0]), ([s45, -s45, 0.0], [s45, s45, 0.0])]
    for (a, b), (wa, wb) in zip(got, want, strict=True):
        assert np.allclose(a, wa, atol=0.1) and np.allclose(b, wb, atol=0.1), (a, b)  # chords of a 0.8 mm step
    assert "from_xyz_mm" not in weld_entry(w)["remainder"][0]  # no pose: along the curve only

    rep = {"seams": [{"id": "PLATE>BASE:+x", "welded": True}, {"id": est.id, **entry}]}
    seam = {"curved": True, "status": "found", "curve": None, "error_mm": None, "time_ms": 9.0, "not_welded": None}
    print_curves({"seams": [{**seam, **rep["seams"][1]}]})  # the console: each stretch where it lies
    assert "from (0, 50, 0) to (-50, 0, 0) mm on the drawing: torch vs GUSSET_1" in capsys.readouterr().out
    (path,) = write_manual_welds(rep, tmp_path)
    assert path == tmp_path / MANUAL_WELDS
    rows = list(csv.DictReader(path.open()))
    assert [r["seam"] for r in rows] == [est.id, est.id] and rows[0]["why"] == "torch vs GUSSET_1"
    assert float(rows[1]["from_x_mm"]) == pytest.approx(s45, abs=0.1) and rows[1]["code"] == "ik_failed"
    assert write_manual_welds({"seams": rep["seams"][:1]}, tmp_path / "none") == []

    # The welder's sheet: each stretch drawn from the list's row's start to its end on the drawing, numbered as the
    # row; the part's outline under it; nothing drawn when no curve is welded in part.
    from test_preview import colour_fraction

    from cell.preview.curves3d import MANUAL_COLOUR
    from cell.preview.welder_sheet import SHEET, draw_sheet, stretches_M, write_welder_sheet

    rows_in = [(est.id, r) for r in entry["remainder"]]
    got_m = stretches_M(rows_in, {est.id: (est, invert(X_RM))})
    assert [n for n, _ in got_m] == [1, 2]
    for (_, p), r in zip(got_m, entry["remainder"], strict=True):
        assert np.allclose(p[0], r["from_xyz_mm"], atol=0.1) and np.allclose(p[-1], r["to_xyz_mm"], atol=0.1)
        assert np.allclose(np.hypot(p[:, 0], p[:, 1]), 50.0, atol=0.1) and np.allclose(p[:, 2], 0.0, atol=1e-6)
    plate = np.array([[[-60.0, -60.0, 0.0], [60.0, -60.0, 0.0]], [[60.0, -60.0, 0.0], [60.0, 60.0, 0.0]]])
    sheet = draw_sheet("tube-on-plate", rows_in, {est.id: (est, invert(X_RM))}, plate, tmp_path)
    assert sheet == tmp_path / SHEET and colour_fraction(sheet, MANUAL_COLOUR) > 1e-3
    assert write_welder_sheet([], rep, tmp_path / "none") == []  # no run drawn from: nothing written


def test_an_arc_the_gate_refused_at_one_end_is_trimmed_there_and_chosen_again() -> None:
    """partial_arcs fails an arc a refusal names (its stretch exactly, at its start or end) without solving it,
    trims :data:`TRIM_M` off that end (in the weld's direction: a reversed arc's start is its far end), chooses
    again (the arc then stops :data:`STOP_BACK_M` short of the stretch given up, as off any gap) and solves the
    arc left; the stretch given up is left for a manual weld with the refusal's code and words."""
    from dataclasses import dataclass
    from types import SimpleNamespace

    import cell.planning.curves.partial as partial_mod
    from cell.planning.curves.arc_solve import TRIM_M
    from cell.planning.curves.partial import STOP_BACK_M
    from cell.planning.failures import SeamFailure
    from cell.types import SeamStatus
    from cell.types.curve_estimate import CurveEstimate

    @dataclass(frozen=True)
    class Task:
        id: str

    @dataclass(frozen=True)
    class Sol:
        task: Task

    n = 201  # an open curve 200 mm long along x
    p = np.column_stack([np.linspace(0.0, 0.2, n), np.zeros(n), np.zeros(n)])
    est = CurveEstimate("POST>RAIL:circle", SeamStatus.FOUND, p_RS=p, n_abutting_R=np.tile([0, 1.0, 0], (n, 1)),
                        n_receiving_R=np.tile([0, 0, 1.0], (n, 1)), sigma_m=np.full(n, 1e-4))  # fmt: skip
    search = SimpleNamespace(process=SimpleNamespace(closed_overlap=OVERLAP_M))
    solved: list[tuple[float, float]] = []

    def solve(_s: object, arc: CurveEstimate, part: Run, *_a: object) -> tuple[Sol, ...]:
        solved.append((round(part.a_m, 6), round(part.b_m, 6)))
        return (Sol(Task(arc.id)),)

    no_cover = SeamFailure(PlanReason.IK_FAILED, "no cover", np.zeros(3), 0.0)
    mp = pytest.MonkeyPatch()
    mp.setattr(partial_mod, "arc_solution", solve)
    try:
        cut = TRIM_M + STOP_BACK_M
        cases = ((C0, "start", (cut, 0.2)), (C1, "start", (0.0, 0.2 - cut)), (C0, "end", (0.0, 0.2 - cut)))
        for cand, end, kept in cases:
            solved.clear()
            gate = Remainder(0.0, 0.2, PlanReason.SINGULAR, "arc 1: the safety gate: singularity", end)
            runs = [_run(0.0, 0.2, cand)]
            got = partial_mod.partial_arcs(search, est, runs, [], None, 0.001, None, no_cover, [gate])  # type: ignore[arg-type]
            assert solved == [pytest.approx(kept)]  # the refused arc is never solved again as it was
            assert got.spans == ((f"{est.id}#arc1", pytest.approx(kept[0]), pytest.approx(kept[1])),)
            (r,) = got.remainder
            lost = (0.0, cut) if kept[0] > 0.0 else (0.2 - cut, 0.2)
            assert (r.from_m, r.to_m) == pytest.approx(lost) and (r.code, r.why) == (gate.code, gate.why)
            assert got.share == pytest.approx(1.0 - cut / 0.2, abs=0.006)
    finally:
        mp.undo()
