"""Placing the torch on a seam without IK, the first steps of the torch search: a candidate is placed when its torch
clears every obstacle at the weld's ends and its wrist centre stays within reach (docs/planning.md section 2).

Frames: the robot base R [m]; angles [rad]."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Protocol

import numpy as np

from cell.config.motion import PlanOptions
from cell.geometry import FloatArray, make_pose, readonly, rot_z
from cell.motion.collision import CollisionChecker, Contact
from cell.planning.failures import SeamFailure, better, mm
from cell.planning.reach import ReachModel
from cell.process.torch import WeldProcess, fillet_axes
from cell.process.torch_orientations import Candidate
from cell.types.plan import PlanReason, SeamTask

PLACED = -1e-3  # a SeamFailure's progress when the torch hit an obstacle where it was placed (below an IK failure)
BEYOND = -0.5e-3  # ... when the wrist centre is beyond reach somewhere along the seam (above a torch collision)


class TorchSearch(Protocol):
    """What placing a torch asks of the torch search (:class:`cell.planning.seam_search.SeamSearch`): its weld
    process, collision checker, options and reach model (None: no reach pre-check)."""

    @property
    def process(self) -> WeldProcess: ...

    @property
    def checker(self) -> CollisionChecker: ...

    @property
    def opt(self) -> PlanOptions: ...

    @property
    def reach(self) -> ReachModel | None: ...


Rotations = dict[tuple[bool, float, float], FloatArray]  # (reversed, work offset, travel offset) -> R_RT (3, 3)
TorchTest = tuple[FloatArray, Contact | None, Contact | None]  # R_RT (3, 3), contact at the weld start, at its end


def wording(best_fail: SeamFailure | None) -> bool:
    """Whether a torch collision found now could become the seam's failure (else only whether it collides
    matters): no failure kept yet, or one that ranks below a torch collision."""
    return best_fail is None or best_fail.progress < PLACED - 1e-9


def torch_tests(
    search: TorchSearch,
    task: SeamTask,
    cands: Sequence[Candidate],
    rotations: Rotations,
    q_seed: FloatArray,
    worded: bool = True,
) -> list[TorchTest]:
    """Per candidate: its torch rotation R_RT (3, 3) and the torch's contact with the obstacles at the weld start
    and at the weld end (placed by pose alone; all the poses in one query, the ends only of those clear at the
    start). rotations : the spin-free torch rotations so far (shared by spins and by calls). worded : the deepest
    contact of each pose (for the failure's words), else its first (enough to know that it collides)."""
    pr = search.process
    length = task.length
    Rs, tips_a, tips_b = [], [], []
    spins: dict[float, FloatArray] = {}
    for cand in cands:
        a, b = (task.p_end, task.p_start) if cand.reversed else (task.p_start, task.p_end)
        key = (cand.reversed, cand.work_offset, cand.travel_offset)
        if key not in rotations:
            rotations[key] = _rotation(
                rotations,
                (b - a) / length,
                task,
                cand.reversed,
                pr.work_angle + cand.work_offset,
                pr.travel_angle + cand.travel_offset,
            )
        if cand.spin not in spins:
            spins[cand.spin] = rot_z(cand.spin)
        Rs.append(rotations[key] @ spins[cand.spin])
        tips_a.append(a)
        tips_b.append(a + length * ((b - a) / length))  # as poses() places the last pose
    # the two end poses of every candidate, as poses() places them (wire tip standoff back along z)
    R_all = np.array(Rs)
    back = pr.standoff * R_all[:, :, 2]
    starts = np.zeros((len(cands), 4, 4))
    starts[:, :3, :3], starts[:, 3, 3] = R_all, 1.0
    ends = starts.copy()
    starts[:, :3, 3] = np.array(tips_a) - back
    ends[:, :3, 3] = np.array(tips_b) - back
    at_start = search.checker.torch_clear_many(starts, q_seed, first=not worded)
    clear = [k for k, h in enumerate(at_start) if h is None]  # the end is tested only where the start is clear
    at_end: list[Contact | None] = [None] * len(cands)
    if clear:
        for k, h in zip(clear, search.checker.torch_clear_many(ends[clear], q_seed, not worded), strict=True):
            at_end[k] = h
    return [(Rs[k], at_start[k], at_end[k]) for k in range(len(cands))]


def _rotation(
    rotations: Rotations, v: FloatArray, task: SeamTask, reverse: bool, work_angle: float, travel_angle: float
) -> FloatArray:
    """R_RT (3, 3): :func:`~cell.process.torch.torch_rotation` of the seam direction ``v`` (3,) with spin 0, the
    same arithmetic, its fillet axes computed once per weld direction (kept in ``rotations`` under the key
    ``(reverse, inf, inf)``: a seam's candidates share them)."""
    axes = (reverse, math.inf, math.inf)
    frame = rotations.get(axes)
    if frame is None:
        d = v / float(np.linalg.norm(v))
        t_b, n_b = fillet_axes(d, task.n_a, task.n_b)
        frame = rotations[axes] = np.stack([d, t_b, n_b])
    d, t_b, n_b = frame
    u = math.cos(work_angle) * t_b + math.sin(work_angle) * n_b  # out of the joint, perpendicular to d
    z = -math.cos(travel_angle) * u + math.sin(travel_angle) * d
    x = d - (d @ z) * z
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    return np.column_stack([x, y, z]) @ _SPIN_0


_SPIN_0 = rot_z(0.0)


def place(
    search: TorchSearch,
    task: SeamTask,
    cand: Candidate,
    test: TorchTest,
    best_fail: SeamFailure | None,
) -> FloatArray | SeamFailure | None:
    """The candidate's weld poses X_RT (n, 4, 4) when its torch clears the obstacles at both weld ends and its
    wrist centre is in reach all along the seam (``test`` from :func:`torch_tests`); else why not (None: a torch
    collision that would not be kept over ``best_fail``)."""
    pr, opt = search.process, search.opt
    R, hit_start, hit_end = test
    a, b = (task.p_end, task.p_start) if cand.reversed else (task.p_start, task.p_end)
    hit = hit_start or hit_end
    if hit is not None:
        if best_fail is not None and best_fail.progress >= PLACED - 1e-9:
            return None  # the failure kept so far ranks at least as high: no need to word this one
        end = "start" if hit_start is not None else "end"
        where = f"torch vs {hit.b} at the weld {end} (p_R = {mm(hit.p_R)} mm)"
        # ranks below an IK failure at the start: the pose was not even tried
        return SeamFailure(PlanReason.COLLISION, where, hit.p_R, PLACED, obstacle=hit.b)
    length = task.length
    X = poses(a, b, R, pr.standoff, max(2, math.ceil(length / opt.spacing - 1e-9) + 1))
    if search.reach is not None:
        over = search.reach.pose_excess(X)
        k = int(np.argmax(over))
        if over[k] > 0.0:
            s_k = k * length / (len(X) - 1)
            where = (
                f"beyond reach: the wrist centre lies {over[k] * 1000:.0f} mm beyond the shoulder's "
                f"reach at {s_k * 1000:.1f} mm along the seam"
            )
            return SeamFailure(PlanReason.BEYOND_REACH, where, X[k][:3, 3].copy(), BEYOND)
    return X


def sweep(
    search: TorchSearch,
    task: SeamTask,
    groups: Sequence[Sequence[Candidate]],
    q_seed: FloatArray,
    best_fail: SeamFailure | None = None,
    rotations: Rotations | None = None,
) -> tuple[int | None, SeamFailure | None]:
    """The index in ``groups`` of the first group with a candidate that can be placed on ``task`` (module
    docstring), None when none can; and the failure the group-by-group search keeps before that group (after them
    all when none), starting from ``best_fail`` (the kept failure of the groups before). q_seed (dof,) [rad] is
    carried in the contacts. Chunks of 1, 2, 4 ... groups per broad-phase query, each pose tested for a collision
    only; a torch collision kept is worded from its deepest contact, as the group-by-group search words it."""
    rotations = {} if rotations is None else rotations
    kept: tuple[Candidate, SeamFailure] | None = None  # a torch collision kept, to word at the end
    k, size = 0, 1
    while k < len(groups):
        members = [(j, c) for j in range(k, min(k + size, len(groups))) for c in groups[j]]
        k, size = k + size, 2 * size
        if not members:
            continue
        chunk = [c for _, c in members]
        at_group, current = members[0][0], best_fail  # the failure kept when each group starts
        for (j, cand), test in zip(
            members, torch_tests(search, task, chunk, rotations, q_seed, worded=False), strict=True
        ):
            if j != at_group:
                at_group, current = j, best_fail
            placed = place(search, task, cand, test, best_fail)
            if isinstance(placed, np.ndarray):
                return j, _worded(search, task, current, kept, rotations, q_seed)
            if placed is None:
                continue
            best_fail = better(best_fail, placed)
            if best_fail is placed and placed.code is PlanReason.COLLISION:
                kept = (cand, placed)
    return None, _worded(search, task, best_fail, kept, rotations, q_seed)


def _worded(
    search: TorchSearch,
    task: SeamTask,
    fail: SeamFailure | None,
    kept: tuple[Candidate, SeamFailure] | None,
    rotations: Rotations,
    q_seed: FloatArray,
) -> SeamFailure | None:
    """``fail``, worded from its deepest contact when it is the torch collision ``kept`` (candidate, failure)."""
    if kept is None or fail is not kept[1]:
        return fail
    cand = kept[0]
    worded = place(search, task, cand, torch_tests(search, task, [cand], rotations, q_seed)[0], None)
    return worded if isinstance(worded, SeamFailure) else fail


def poses(a: FloatArray, b: FloatArray, R: FloatArray, standoff: float, n: int) -> FloatArray:
    """n torch poses (n, 4, 4) of orientation R_RT (3, 3) from seam point a to b (3,) [m], evenly spaced, the wire
    tip ``standoff`` [m] back along the torch axis (as :func:`~cell.process.torch.torch_poses` places them)."""
    length = float(np.linalg.norm(b - a))
    d = (b - a) / length
    p = a + np.outer(np.linspace(0.0, length, n), d) - standoff * R[:, 2]
    out = np.repeat(make_pose(R)[None], n, axis=0)
    out[:, :3, 3] = p
    return readonly(out)
