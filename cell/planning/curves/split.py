"""A curved seam the arm cannot weld in one go, split into reachable arcs as a welder does on a fixed-arm cell:
two to four open arcs, each started and stopped with its own crater, each restarting over the previous bead by the
process's overlap, the arm re-orienting between them in the air (docs/curves-welding.md section 8).

Frames: everything in the robot base frame R [m]; joints [rad]."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from cell.geometry import FloatArray
from cell.planning.curves.path import _loop, start_order
from cell.planning.curves.search import STARTS
from cell.planning.failures import SeamFailure, better
from cell.planning.seam_search import SeamSolution
from cell.types.curve_estimate import CurveEstimate

MAX_ARCS = 4  # a seam welded in more pieces than this is refused (each stop is a crater, each restart a defect risk)
FIRST_SHARES = (0.6, 0.4)  # the first arc's length tried, as shares of the curve (longest first)
FIRST_STARTS = 4  # where the first arc may start: the first of the closed search's starts (nearest the base first)
ARC_MARK = "#arc"  # an arc's id: its seam's id, this mark and its number from 1

Planner = Callable[[CurveEstimate], SeamSolution | SeamFailure]  # one open arc's torch search


@dataclass(frozen=True)
class Split:
    """The arcs found for one curved seam: each arc's estimate (an open piece of the curve, id ``<seam>#arcK``) and
    solution, in weld order; ``share`` the part of the curve they cover (1: the whole seam); ``failure`` the
    search's word on the part no arc reaches (None when covered)."""

    arcs: tuple[tuple[CurveEstimate, SeamSolution], ...]
    share: float
    failure: SeamFailure | None

    @property
    def whole(self) -> bool:
        return self.failure is None and bool(self.arcs)


def arc_id(seam_id: str, k: int) -> str:
    """The id of a seam's k-th arc (from 1)."""
    return f"{seam_id}{ARC_MARK}{k}"


def seam_of(segment_id: str) -> str:
    """The seam an arc's id belongs to (any other id unchanged)."""
    return segment_id.split(ARC_MARK, 1)[0]


def sub_arc(est: CurveEstimate, s_a: float, s_b: float, k: int, step: float = 0.001) -> CurveEstimate:
    """The open piece of ``est`` from s_a to s_b [m] along its samples (a closed curve's taken round its start),
    sampled ``step`` [m] apart, with its normals and sigmas; its ends' sigma along it: the largest sample sigma
    (an arc's ends are where the plan puts them, not located ones)."""
    p, na, nb, s_k = _loop(est)
    sig = np.asarray(est.sigma_m)
    sig = np.concatenate([sig, sig[:1]]) if est.closed else sig
    sig = sig[: len(s_k)]
    total = float(s_k[-1])
    n = max(3, math.ceil((s_b - s_a) / step) + 1)
    u = np.linspace(s_a, s_b, n)
    u = np.mod(u, total) if est.closed else np.clip(u, 0.0, total)

    def at(v: FloatArray) -> FloatArray:
        return np.column_stack([np.interp(u, s_k, v[:, j]) for j in range(v.shape[1])])

    def unit(v: FloatArray) -> FloatArray:
        return np.asarray(v / np.linalg.norm(v, axis=1, keepdims=True))

    sigma = np.interp(u, s_k, sig)
    end = float(sigma.max())
    return replace(
        est,
        id=arc_id(est.id, k),
        p_RS=at(p),
        n_abutting_R=unit(at(na)),
        n_receiving_R=unit(at(nb)),
        closed=False,
        sigma_m=sigma,
        end_sigma_m=(end, end),
    )


def split_curve(est: CurveEstimate, plan: Planner, overlap: float, p_base_R: FloatArray) -> Split:
    """Reachable arcs covering ``est`` (closed: all round, the last arc running ``overlap`` [m] over the first
    bead's start; open: end to end), each planned by ``plan`` (an open arc's whole torch search).

    The first arc: the longest of :data:`FIRST_SHARES` of the curve that plans from one of the first
    :data:`FIRST_STARTS` of :data:`STARTS` starts (nearest the robot base ``p_base_R`` first). Then the rest,
    from ``overlap`` back on the last bead to the far end: planned whole, else halved, and so on, until
    :data:`MAX_ARCS` arcs in all; a piece still failing is the part no arc reaches (``failure``, the covered
    ``share`` of the curve)."""
    total = est.length_m
    starts = start_order(est, p_base_R, STARTS)[:FIRST_STARTS] if est.closed else [0.0]
    shares = FIRST_SHARES
    worst: SeamFailure | None = None
    first: tuple[float, float, CurveEstimate, SeamSolution] | None = None
    for share in shares:
        for s0 in starts:
            a, b = s0, s0 + share * total
            arc = sub_arc(est, a, b, 1)
            got = plan(arc)
            if isinstance(got, SeamSolution):
                first = (a, b, arc, got)
                break
            worst = better(worst, got)
        if first is not None:
            break
    if first is None:
        assert worst is not None
        return Split((), 0.0, worst)
    a0, b0, arc0, sol0 = first
    arcs = [(arc0, sol0)]
    end = a0 + total + overlap if est.closed else total
    todo = [(b0 - overlap, end)]  # the rest, each piece restarting over the last bead
    missed = 0.0
    failure: SeamFailure | None = None
    while todo:
        a, b = todo.pop(0)
        k = len(arcs) + 1
        arc = sub_arc(est, a, b, k)
        got = plan(arc)
        if isinstance(got, SeamSolution):
            arcs.append((arc, got))
            continue
        if len(arcs) + len(todo) + 2 > MAX_ARCS:  # halving would need more arcs than a welder would lay
            missed += b - a - overlap
            failure = better(failure, got)
            continue
        mid = 0.5 * (a + b)
        todo[:0] = [(a, mid + 0.5 * overlap), (mid - 0.5 * overlap, b)]
    share = max(0.0, 1.0 - missed / total) if failure is not None else 1.0
    arcs_sorted = tuple(sorted(arcs, key=lambda x: int(x[0].id.rsplit(ARC_MARK, 1)[1])))
    return Split(arcs_sorted, share, failure)
