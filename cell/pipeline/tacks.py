"""Tack welds before the turn (docs/flip.md): short welds on the seam line that hold the parts together
while the operator turns the part over. Side A's plan welds them first (:func:`cell.pipeline.gated.plan_for`'s
``tacks``), each as its own task ``<seam id>~tack<k>`` with its seam's procedure (one pass, no weave); the full
welds then run over them. Lengths in metres inside, millimetres in :class:`TackRecord`."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Literal

import numpy as np

from cell.types.plan import NoProcedure, SeamProcedure, SeamTask, WeldPlan
from cell.types.procedure import Weave, WeldPass

TACK_MARK = "~tack"  # a tack's task id: <seam id>~tack<k>
End = Literal["start", "end"]


@dataclass(frozen=True)
class Tack:
    """One tack chosen: its task (on the seam line, ``length_m`` long from the seam's ``end``) and its seam."""

    task: SeamTask
    seam_id: str
    end: End
    length_m: float


@dataclass(frozen=True)
class TackRecord:
    """What became of one tack: welded (or planned, in a preview) or why not."""

    id: str
    seam_id: str
    end: End
    length_mm: float
    planned: bool
    welded: bool
    reason: str = ""


def is_tack(task_id: str) -> bool:
    """Whether a task id (a plan's seam id) names a tack."""
    return TACK_MARK in task_id


def choose_tacks(
    tasks: Sequence[SeamTask], count: int, length_m: float, joints: Mapping[str, str] | None = None
) -> tuple[Tack, ...]:
    """``count`` tacks of ``length_m`` on the seams of ``tasks``: the longest seams first, alternating their ends
    (the longest's start, the next one's end, ...), then the other ends in the same order; one tack per seam end
    at most, and a second one on a seam only where the two do not overlap. Fewer when the seams run out.

    joints : seam id -> the pair of parts it joins; every pair gets its first tack (on its longest seam) before
    any pair gets a second: the tacks hold every part."""
    pair = joints or {}
    fit = sorted((t for t in tasks if t.length >= length_m), key=lambda t: (-t.length, t.id))
    rank: dict[str, int] = {}
    seen: dict[str, int] = {}
    for t in fit:
        key = pair.get(t.id, t.id)
        rank[t.id] = seen.get(key, 0)
        seen[key] = rank[t.id] + 1
    seams = sorted(fit, key=lambda t: (rank[t.id], -t.length, t.id))
    slots: list[tuple[SeamTask, End]] = []
    for rnd in range(2):
        for k, t in enumerate(seams):
            first: End = "start" if k % 2 == 0 else "end"
            other: End = "end" if first == "start" else "start"
            if rnd == 0:
                slots.append((t, first))
            elif t.length >= 2.0 * length_m:
                slots.append((t, other))
    out: list[Tack] = []
    taken: dict[str, int] = {}
    for t, end in slots[:count]:
        taken[t.id] = taken.get(t.id, 0) + 1
        d = (t.p_end - t.p_start) / t.length
        a, b = (t.p_start, t.p_start + length_m * d) if end == "start" else (t.p_end - length_m * d, t.p_end)
        task = SeamTask(f"{t.id}{TACK_MARK}{taken[t.id]}", a, b, t.n_a, t.n_b)
        out.append(Tack(task, t.id, end, length_m))
    return tuple(out)


def tack_procedures(
    procedures: Mapping[str, SeamProcedure | NoProcedure], tacks: Sequence[SeamTask]
) -> dict[str, SeamProcedure | NoProcedure]:
    """Per tack task: its seam's procedure (its travel speed, torch angles, direction and craters) with one pass
    on the seam line and no weave; a seam with no procedure leaves its tacks to the process alone."""
    out: dict[str, SeamProcedure | NoProcedure] = {}
    for t in tacks:
        sel = procedures.get(t.id.split(TACK_MARK)[0])
        if sel is None:
            continue
        if isinstance(sel, SeamProcedure):
            out[t.id] = replace(
                sel, seam_id=t.id, procedure=replace(sel.procedure, weave=Weave(), passes=(WeldPass(),))
            )
        else:
            out[t.id] = replace(sel, seam_id=t.id)
    return out


def tack_records(
    tacks: Sequence[Tack], plan: WeldPlan | None, executed: bool, refused: str = ""
) -> tuple[TackRecord, ...]:
    """Per tack chosen: planned and welded (the plan executed), or the planner's reason (``refused``: why the
    plan as a whole did not run)."""
    outcomes = {o.seam_id: o for o in plan.seams} if plan is not None else {}
    out = []
    for t in tacks:
        o = outcomes.get(t.task.id)
        planned = o is not None and o.feasible
        why = (o.reason if o is not None and not o.feasible else "") or ("" if planned else refused or "not planned")
        if planned and not executed:
            why = refused or "planned, not executed (preview)"
        mm = round(t.length_m * 1000.0, 3)
        out.append(TackRecord(t.task.id, t.seam_id, t.end, mm, planned, planned and executed, why))
    return tuple(out)


def tacks_time_s(plan: WeldPlan | None) -> float:
    """The tacks' robot time in a plan [s]: the moves to them, their approaches, welds and departs."""
    if plan is None:
        return 0.0
    return float(np.sum([g.trajectory.duration for g in plan.segments if is_tack(g.seam_id)]))
