"""The tacks' choice, procedure and record (:mod:`cell.pipeline.tacks`) and the order that welds them first
(:func:`cell.planning.order.seam_order`'s ``first``), on small made-up seams."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from cell.motion.robot import RobotModel
from cell.pipeline.tacks import choose_tacks, tack_procedures, tack_records
from cell.planning.order import seam_order
from cell.types.plan import NoProcedure, SeamOutcome, SeamProcedure, SeamTask, WeldPlan
from cell.types.procedure import Weave, WeldPass, WeldProcedure

URDF = Path(__file__).resolve().parents[2] / "robots" / "kr5_arc.urdf"
NA, NB = np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.0, 1.0])


def seam(sid: str, length_m: float, y: float = 0.0) -> SeamTask:
    return SeamTask(sid, np.array([0.0, y, 0.0]), np.array([0.0, y + length_m, 0.0]), NA, NB)


def test_longest_seams_first_alternating_ends_then_the_other_ends() -> None:
    tasks = [seam("a", 0.05), seam("b", 0.10, 1.0), seam("c", 0.08, 2.0), seam("short", 0.01, 3.0)]
    got = choose_tacks(tasks, 10, 0.02)
    assert [(t.task.id, t.end) for t in got] == [
        ("b~tack1", "start"), ("c~tack1", "end"), ("a~tack1", "start"),
        ("b~tack2", "end"), ("c~tack2", "start"), ("a~tack2", "end"),
    ]  # fmt: skip
    b1, c1 = got[0].task, got[1].task
    assert np.allclose(b1.p_start, [0.0, 1.0, 0.0]) and np.allclose(b1.p_end, [0.0, 1.02, 0.0])
    assert np.allclose(c1.p_start, [0.0, 2.06, 0.0]) and np.allclose(c1.p_end, [0.0, 2.08, 0.0])
    assert all(t.task.length == pytest.approx(0.02) for t in got)
    # A seam shorter than twice the tack gets one only; none asked, none laid.
    assert [t.task.id for t in choose_tacks([seam("a", 0.03)], 4, 0.02)] == ["a~tack1"]
    assert choose_tacks(tasks, 0, 0.02) == ()


def test_every_pair_of_parts_gets_a_tack_before_any_gets_a_second() -> None:
    tasks = [seam("a1", 0.10), seam("a2", 0.09, 1.0), seam("b1", 0.05, 2.0)]
    pairs = {"a1": "A>X", "a2": "A>X", "b1": "B>X"}
    assert [t.seam_id for t in choose_tacks(tasks, 2, 0.02, pairs)] == ["a1", "b1"]
    assert [t.seam_id for t in choose_tacks(tasks, 2, 0.02)] == ["a1", "a2"]


def test_a_tack_takes_its_seams_procedure_with_one_pass_and_no_weave() -> None:
    proc = WeldProcedure("wavy", travel_speed_mm_s=6.0, weave=Weave("zigzag", 4.0, 2.0), passes=(WeldPass(),) * 3)
    sel = SeamProcedure("a", proc, "T", "PB", 4.0, reverse=True, fixed_direction=True)
    tacks = [t.task for t in choose_tacks([seam("a", 0.1), seam("n", 0.05, 1.0)], 2, 0.02)]
    got = tack_procedures({"a": sel, "n": NoProcedure("n", "no row")}, tacks)
    a = got["a~tack1"]
    assert isinstance(a, SeamProcedure) and a.seam_id == "a~tack1" and a.reverse and a.fixed_direction
    assert a.procedure.weave.pattern == "none" and len(a.procedure.passes) == 1
    assert a.procedure.travel_speed_mm_s == 6.0 and a.procedure.crater_end_s == proc.crater_end_s
    assert isinstance(got["n~tack1"], NoProcedure)


def test_the_record_says_welded_or_why_not() -> None:
    tacks = choose_tacks([seam("a", 0.1), seam("b", 0.05, 1.0)], 2, 0.015)
    outcomes = (SeamOutcome("a~tack1", True), SeamOutcome("b~tack1", False, "collision: torch against POST"))
    plan = WeldPlan(("j",), np.zeros(1), (), outcomes, ("a~tack1",), 0.0)
    welded, refused = tack_records(tacks, plan, True)
    assert (welded.welded, welded.length_mm, welded.end, welded.reason) == (True, 15.0, "start", "")
    assert (refused.planned, refused.welded, refused.reason) == (False, False, "collision: torch against POST")
    assert tack_records(tacks, plan, False)[0].reason == "planned, not executed (preview)"
    assert tack_records(tacks, None, False, "not executed: gate")[0].reason == "not executed: gate"


def test_the_order_welds_the_first_ids_first_and_is_unchanged_without() -> None:
    robot = RobotModel.from_urdf(URDF)
    rng = np.random.default_rng(3)
    lo, hi = robot.limits.q_min, robot.limits.q_max
    q = [lo + (hi - lo) * (0.3 + 0.4 * rng.random(robot.dof)) for _ in range(6)]
    ids = ["s0", "s1", "s2", "s3", "t4", "t5"]
    home = (lo + hi) / 2.0
    free = seam_order(ids, q, q, home, robot)
    assert seam_order(ids, q, q, home, robot, first=()) == free
    tacked = seam_order(ids, q, q, home, robot, first={"t4", "t5"})
    assert sorted(tacked) == list(range(6)) and {ids[k] for k in tacked[:2]} == {"t4", "t5"}
    assert {ids[k] for k in free[:2]} != {"t4", "t5"}  # the constraint changed the order
