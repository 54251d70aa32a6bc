"""The table stand-off: a seam that ends on the table, refused because the torch meets the table there, is welded
shortened at that end by the least stand-off at which some torch clears it (docs/track.md, "The table stand-off").
Frames: R [m]."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Literal

import numpy as np
import numpy.typing as npt

from cell.config.motion import PlanOptions
from cell.planning.failures import SeamFailure
from cell.planning.seam_search import SeamSearch, SeamSolution
from cell.types import Part
from cell.types.plan import PlanReason, SeamProcedure, SeamTask

_STEP = 0.002  # [m] the stand-off grows in these steps
_NEAR = 0.002  # [m] a seam end this near the table top (or below it) lies on the table
_MAX_SHARE = 1.0 / 3.0  # the stand-off takes at most this share of the seam
_PLACED = -1e-3  # a SeamFailure's progress when the torch hit an obstacle where it was placed (candidates.py)


def table_top(obstacles: Sequence[Part], table_name: str) -> float | None:
    """Height [m] in R of the table's top (the highest vertex of the obstacle named ``table_name``), None when
    there is no such obstacle."""
    tops = [float(np.max(p.vertices()[:, 2])) for p in obstacles if p.name == table_name]
    return max(tops) if tops else None


def table_end(task: SeamTask, table_z: float) -> Literal["start", "end"] | None:
    """Which end of the task lies on the table (within ``_NEAR`` of ``table_z``) with the seam climbing away from
    it (the other end more than ``_NEAR`` higher); None if neither does."""
    z0, z1 = float(task.p_start[2]), float(task.p_end[2])
    if z0 <= table_z + _NEAR and z1 > z0 + _NEAR:
        return "start"
    if z1 <= table_z + _NEAR and z0 > z1 + _NEAR:
        return "end"
    return None


def shortened(task: SeamTask, end: Literal["start", "end"], d: float) -> SeamTask:
    """The task with ``d`` [m] taken off at ``end`` (along the seam line)."""
    u = (task.p_end - task.p_start) / task.length
    if end == "start":
        return SeamTask(task.id, task.p_start + d * u, task.p_end, task.n_a, task.n_b)
    return SeamTask(task.id, task.p_start, task.p_end - d * u, task.n_a, task.n_b)


def blocked_by_table(fail: SeamFailure, table_name: str) -> bool:
    """Whether a seam's failure is the torch against the table where it is placed (every candidate hit an
    obstacle before IK, and the one named is the table)."""
    return fail.code is PlanReason.COLLISION and fail.progress <= _PLACED + 1e-9 and fail.obstacle == table_name


def stand_off(
    search: SeamSearch,
    task: SeamTask,
    table_z: float,
    max_trim: float,
    orient: Callable[[SeamTask], SeamTask],
    q_seed: np.ndarray,
) -> tuple[SeamTask, float] | None:
    """The task shortened at its table end by the least stand-off [m] at which some torch can be placed, and that
    stand-off; None when the task has no end on the table or no stand-off up to ``max_trim`` (and a third of the
    seam) clears it. orient : the task as the search sees it (a procedure's direction). A few placement tests (no
    IK): the largest stand-off first, then a bisection of the steps below it."""
    end = table_end(task, table_z)
    if end is None:
        return None
    limit = min(max_trim, _MAX_SHARE * task.length)
    k = int(np.floor(limit / _STEP + 1e-9))
    trims = [_STEP * i for i in range(1, k + 1)]
    if limit > k * _STEP + 1e-9:
        trims.append(limit)
    if not trims:
        return None

    def clear(i: int) -> bool:
        return search.placeable(orient(shortened(task, end, trims[i])), q_seed) is None

    if not clear(len(trims) - 1):
        return None
    lo, hi = 0, len(trims) - 1  # hi clears; find the least index that does
    while lo < hi:
        mid = (lo + hi) // 2
        if clear(mid):
            hi = mid
        else:
            lo = mid + 1
    return shortened(task, end, trims[hi]), trims[hi]


def shortened_plan(
    search: SeamSearch,
    task: SeamTask,
    fail: SeamFailure,
    table_z: float,
    opt: PlanOptions,
    sel: SeamProcedure | None,
    q0: npt.NDArray[np.float64],
) -> tuple[SeamSolution, float] | None:
    """The seam planned shortened at its table end (:mod:`cell.planning.stand_off`) and by how much [m], when its
    failure is the torch against the table where it is placed; None otherwise or when the shortened seam does
    not plan either (the seam keeps its failure)."""
    if not blocked_by_table(fail, opt.collision.table_name):
        return None
    orient = sel.oriented if sel else as_is
    short = stand_off(search, task, table_z, opt.table_stand_off_max, orient, q0)
    if short is None:
        return None
    again = search.plan_seam(orient(short[0]), q0)
    return None if isinstance(again, SeamFailure) else (again, short[1])


def as_is(task: SeamTask) -> SeamTask:
    """The task unchanged (where a seam has no procedure to orient it)."""
    return task
