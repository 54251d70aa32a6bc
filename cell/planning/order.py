"""The welding order (step 4 of :func:`cell.planning.plan.plan_welds`): greedy nearest neighbour then 2-opt and Or-opt
on the point-to-point durations between seams, home at both ends. Joints [rad]; durations [s]."""

from __future__ import annotations

from collections.abc import Callable, Collection, Sequence

import numpy as np

from cell.geometry import FloatArray
from cell.motion.robot import RobotModel
from cell.motion.timing import ptp_duration

_PENALTY_S = 1e6  # [s] added to a transfer known to collide: used only when no order avoids it
OR_OPT_GAIN = 0.02  # the Or-opt tour is taken when its estimate is this much shorter than 2-opt's alone
_AFTER_S = 1e9  # [s] added to every step that puts a seam of ``first`` after another seam (never chosen)


def seam_order(
    ids: Sequence[str],
    entries: Sequence[FloatArray],
    exits: Sequence[FloatArray],
    q_home: FloatArray,
    robot: RobotModel,
    forbidden: Collection[tuple[str, str]] = (),
    first: Collection[str] = (),
) -> list[int]:
    """Seam order (indices into ``ids``) by point-to-point duration: greedy nearest from home, then 2-opt; then
    2-opt and Or-opt together, that tour taken where it is estimated :data:`OR_OPT_GAIN` shorter (home fixed at
    both ends; the estimates are rest-to-rest PTPs, not the true moves: a tour shorter by less is no better).

    entries, exits : (dof,) [rad] per seam, where its approach starts and its depart ends; q_home (dof,) [rad].
    forbidden : (from id, to id) transfers known to collide ("" = home); they cost a penalty, so they are used
    only when no order avoids them.
    first : ids welded before every other (tack welds): the order runs through them, then through the rest.
    """
    n = len(entries)
    if n <= 1:
        return list(range(n))
    lim = robot.limits

    def dur(a: FloatArray, b: FloatArray, edge: tuple[str, str]) -> float:
        return ptp_duration(a, b, lim) + (_PENALTY_S if edge in forbidden else 0.0)

    C = np.array([[dur(exits[i], entries[k], (ids[i], ids[k])) if i != k else 0.0 for k in range(n)] for i in range(n)])
    from_home = np.array([dur(q_home, e, ("", ids[k])) for k, e in enumerate(entries)])
    to_home = np.array([dur(x, q_home, (ids[k], "")) for k, x in enumerate(exits)])
    lead = np.array([i in first for i in ids], dtype=bool)
    if lead.any() and not lead.all():  # a seam of first after another one costs more than any valid order
        C = C + _AFTER_S * (~lead[:, None] & lead[None, :])
        from_home = from_home + _AFTER_S * ~lead
        to_home = to_home + _AFTER_S * lead

    def cost(p: list[int]) -> float:
        return float(from_home[p[0]] + sum(C[p[i], p[i + 1]] for i in range(n - 1)) + to_home[p[-1]])

    left, tour = set(range(n)), [int(np.argmin(from_home))]
    left.remove(tour[0])
    while left:
        ahead = [k for k in left if lead[k]] or left
        nxt = min(ahead, key=lambda k: C[tour[-1], k])
        tour.append(nxt)
        left.remove(nxt)
    two = _improved(tour, cost, 0)
    moved = _improved(two, cost, n)
    return moved if cost(moved) < (1.0 - OR_OPT_GAIN) * cost(two) else two


def _improved(tour: list[int], cost: Callable[[list[int]], float], longest: int) -> list[int]:
    """2-opt (a stretch reversed) and Or-opt (a stretch of up to ``longest`` seams moved elsewhere, as it is or
    reversed; 0: none) until neither shortens the tour."""
    n, best, improved = len(tour), cost(tour), True
    while improved:
        improved = False
        for i in range(n - 1):
            for k in range(i + 1, n):
                cand = tour[:i] + tour[i : k + 1][::-1] + tour[k + 1 :]
                c = cost(cand)
                if c < best - 1e-9:
                    tour, best, improved = cand, c, True
        for size in range(1, min(longest, n - 1) + 1):
            for i in range(n - size + 1):
                piece, rest = tour[i : i + size], tour[:i] + tour[i + size :]
                for j in range(len(rest) + 1):
                    if j == i:
                        continue
                    for p in (piece, piece[::-1]) if size > 1 else (piece,):
                        cand = rest[:j] + p + rest[j:]
                        c = cost(cand)
                        if c < best - 1e-9:
                            tour, best, improved = cand, c, True
                            break
                    else:
                        continue
                    break
    return tour
