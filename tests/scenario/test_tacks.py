"""Tack welds before the turn (docs/flip.md): fence1's side A planned with 4 tacks of 15 mm from
the session's weld (its detection after the re-scan, no new capture): the tacks come first, each on its seam line
at the chosen end, of the asked length, arc on; the 12 seams are still planned; the KRL program welds them; with
no tacks the plan is the one ``cell weld fence1`` ran. Then ``weld_part`` of fence1-tacked with side A stubbed
(the session's run carrying the tacked plan): the run's and the report's record of the tacks.

One module fixture plans side A with the tacks (and once without) on a fence1 cell of its own.
"""

from __future__ import annotations

import importlib
from collections.abc import Iterator
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import pytest

from cell import pipeline
from cell import scenario as sc
from cell.export.krl import krl_program
from cell.export.reports.turnover_report import turnover_report
from cell.pipeline.geometry import open_cell
from cell.pipeline.tacks import Tack, is_tack
from cell.pipeline.turnover import tack_rule, weld_part
from cell.pipeline.weld import plan_for
from cell.planning.tasks import seam_tasks
from cell.types.plan import SeamTask, WeldPlan

LENGTH_M = 0.015


@dataclass(frozen=True)
class Tacked:
    plan: WeldPlan  # side A with 4 tacks
    bare: WeldPlan  # side A with the rule asking for none
    tacks: tuple[Tack, ...]
    seams: dict[str, SeamTask]
    pairs: dict[str, str]  # seam id -> the parts it joins
    model: Any  # the arm's RobotModel


@pytest.fixture(scope="module")
def tacked(fence1_run: pipeline.WeldRun) -> Iterator[Tacked]:
    det = fence1_run.detection
    scn = det.scenario
    with open_cell(scn, pipeline.read_weldmap(scn)) as station:
        assert station.arm is not None
        chosen: list[Tack] = []
        plan, _, violations = plan_for(station, det, tacks=tack_rule(4, LENGTH_M, chosen))
        assert not violations
        tacks = tuple(chosen)
        bare, _, _ = plan_for(station, det, tacks=tack_rule(0, LENGTH_M, []))
        ss = det.scene.seam_scene if det.scene is not None else None
        assert ss is not None
        seams = {t.id: t for t in seam_tasks(det.estimates, ss.weldmap, ss.joints, ss.table_z)}
        pairs = {i: f"{j.abutting}>{j.receiving}" for i, j in det.joints.items()}
        yield Tacked(plan, bare, tacks, seams, pairs, station.arm.model)


def test_four_tacks_hold_the_four_joints_on_their_longest_seams_alternating_ends(tacked: Tacked) -> None:
    """fence1's four pairs of parts (each post on each rail) get one tack each, on the pair's longest seam."""
    assert len(tacked.tacks) == 4
    assert len({tacked.pairs[t.seam_id] for t in tacked.tacks}) == 4
    for t in tacked.tacks:
        same = [s.length for i, s in tacked.seams.items() if tacked.pairs[i] == tacked.pairs[t.seam_id]]
        assert tacked.seams[t.seam_id].length == max(same)
    assert [t.end for t in tacked.tacks] == ["start", "end", "start", "end"]
    assert all(t.task.id == f"{t.seam_id}~tack1" for t in tacked.tacks)


def test_the_tacks_are_welded_before_every_seam(tacked: Tacked) -> None:
    plan = tacked.plan
    ids = {t.task.id for t in tacked.tacks}
    assert all(o.feasible for o in plan.seams if o.seam_id in ids)
    assert set(plan.order[:4]) == ids
    welds = [g for g in plan.segments if g.arc_on]
    first_seam = min(g.t0 for g in welds if not is_tack(g.seam_id))
    assert all(g.t1 <= first_seam for g in welds if is_tack(g.seam_id))


def test_each_tack_lies_on_its_seam_at_its_end_of_the_asked_length(tacked: Tacked) -> None:
    for tack in tacked.tacks:
        segs = [g for g in tacked.plan.segments if g.seam_id == tack.task.id and g.kind == "weld"]
        assert len(segs) == 1 and segs[0].arc_on  # one pass, arc on
        p = np.array([tacked.model.fk(q)[:3, 3] for q in segs[0].trajectory.q])
        seam = tacked.seams[tack.seam_id]
        d = (seam.p_end - seam.p_start) / seam.length
        off = p - seam.p_start
        across = np.linalg.norm(off - np.outer(off @ d, d), axis=1)
        assert across.max() < 0.0005  # on the seam line within 0.5 mm
        along = off @ d
        assert along.max() - along.min() == pytest.approx(LENGTH_M, abs=0.0005)
        at = 0.0 if tack.end == "start" else seam.length
        assert min(abs(along - at)) < 0.0005  # from the chosen end


def test_every_seam_is_still_welded_and_the_krl_program_lays_the_tacks(tacked: Tacked) -> None:
    full = [o for o in tacked.plan.seams if not is_tack(o.seam_id)]
    assert len(full) == 12 and all(o.feasible for o in full)
    assert {o.seam_id for o in full} <= {g.seam_id for g in tacked.plan.segments if g.arc_on}
    src, _ = krl_program(tacked.plan, tacked.model, "WELD_TACKED")
    where = {o.seam_id: src.find(f" seam {o.seam_id} procedure ") for o in tacked.plan.seams}
    assert all(k >= 0 for k in where.values())  # every weld, tacks and seams, has its arc in the program
    assert max(where[t.task.id] for t in tacked.tacks) < min(where[o.seam_id] for o in full)  # tacks first


def test_no_tacks_change_nothing(tacked: Tacked, fence1_run: pipeline.WeldRun) -> None:
    ran = fence1_run.plan
    assert ran is not None
    assert tacked.bare.order == ran.order
    assert [(g.kind, g.seam_id) for g in tacked.bare.segments] == [(g.kind, g.seam_id) for g in ran.segments]
    assert tacked.bare.cycle_time == pytest.approx(ran.cycle_time, abs=1e-9)


def test_weld_part_records_the_tacks_side_a_laid(
    tacked: Tacked, fence1_run: pipeline.WeldRun, monkeypatch: pytest.MonkeyPatch
) -> None:
    """fence1-tacked through weld_part, side A stubbed: the rule it passes is asked, and the run and the report
    say which tacks were laid and their time (a preview: no side B)."""
    asked: list[int] = []

    def side_a(scn: sc.Scenario, *_: Any, tacks: Any = None, **__: Any) -> pipeline.WeldRun:
        det = fence1_run.detection
        assert det.scene is not None
        ss = det.scene.seam_scene
        got = tacks(det, seam_tasks(det.estimates, ss.weldmap, ss.joints, ss.table_z))
        asked.append(len(got))
        return replace(fence1_run, plan=tacked.plan)

    monkeypatch.setattr(importlib.import_module("cell.pipeline.turnover"), "weld", side_a)
    run = weld_part(sc.load("fence1-tacked"), pipeline.WeldJob(execute=False))
    assert asked == [4] and run.plan is not None and run.side_b is None
    assert [(t.seam_id, t.end, t.length_mm, t.welded) for t in run.tacks] == [
        (t.seam_id, t.end, 15.0, True) for t in tacked.tacks
    ]
    arc = sum(g.trajectory.duration for g in tacked.plan.segments if g.arc_on and is_tack(g.seam_id))
    assert arc < run.tacks_s < arc + 4 * 10.0  # their arc time and their own moves
    rep = turnover_report(run)
    assert [t["id"] for t in rep["flip"]["tacks"]] == [t.task.id for t in tacked.tacks]
    assert all(t["welded"] and t["reason"] == "" for t in rep["flip"]["tacks"])
