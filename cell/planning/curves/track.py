"""Curved seams for an arm on a linear track: the carriage positions E1 each curve is tried from, and the curve
planned whole from one of them, the carriage standing still while its arcs burn (docs/curves-welding.md
section 11). :func:`cell.planning.track.plan_on_track` calls these.

Frames: R is the base at E1 = 0. Units: metres, radians."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import replace

import numpy as np

from cell.geometry import FloatArray
from cell.types.curve_estimate import CurveEstimate
from cell.types.plan import PlanReason, SeamOutcome, SeamTask, WeldPlan

TRIES = 3  # E1 values a curve is tried from at most (a refused curve costs a full reach map at each)
APART = 0.1  # [m] at least this far between two E1 values a curve is tried from
PROBE_STEP = 0.01  # [m] along the curve between the points whose reach is judged
SLACK = 0.05  # [m] the further E1 values tried give the curve at most this much less room than its best
_SOMEWHERE_ELSE = frozenset({PlanReason.NO_PROCEDURE})  # codes no other E1 changes


def curve_probes(curve: CurveEstimate, step: float = PROBE_STEP) -> list[SeamTask]:
    """Short chords (1 mm) along a located curve every ``step`` [m] (its ends included), each with the curve's
    faces there: the points :func:`cell.planning.track.reach_curves` judges the curve's room on."""
    p, t = np.asarray(curve.p_RS), curve.tangent_R
    k = max(2, int(np.ceil(curve.length_m / step)) + 1)
    idx = np.unique(np.linspace(0, len(p) - 1, k).round().astype(int))
    return [
        SeamTask(f"{curve.id}@{i}", p[i], p[i] + 1e-3 * t[i], curve.n_abutting_R[i], curve.n_receiving_R[i])
        for i in idx
    ]


def curve_e1s(
    room: FloatArray,
    grid: FloatArray,
    taken: Sequence[float],
    margin: float,
    sure: FloatArray | None = None,
    tries: int = TRIES,
    apart: float = APART,
) -> tuple[float, ...]:
    """The E1 values [m] a curve is tried from, in order. ``room`` (G,) [m]: the worst over the curve's points of how
    far the nominal torch's wrist lies past the arm's reach at each E1 of ``grid`` (negative: inside by that much;
    round a tube the torch leans out on the far side, so the planner's tilts may reach where this says not).
    First the one of ``taken`` (E1 = 0 and the straight seams' groups: no carriage move of its own) where the whole
    curve has ``margin`` [m] of room, the most room first; then the grid's value with the most room; then values
    ``apart`` [m] on from those, nearest it first, with at most :data:`SLACK` less room; at most ``tries`` in all.
    ``sure`` (G,): the reach pre-check's bound for every torch (> 0: out of reach for sure); a curve out of reach
    for sure everywhere gets its best E1 only (the planner refuses it there with its reason)."""
    g = np.asarray(grid, dtype=float)
    r = np.asarray(room, dtype=float)
    best = int(np.argmin(r))
    if sure is not None and float(np.min(sure)) > 0.0:
        return (float(g[best]),)
    out: list[float] = []

    def add(e: float) -> None:
        if len(out) < tries and all(abs(e - o) >= apart - 1e-9 for o in out):
            out.append(e)

    near = [int(np.argmin(np.abs(g - e))) for e in taken]
    for i in sorted({i for i in near if r[i] <= -margin}, key=lambda i: (r[i], abs(g[i]))):
        add(float(g[i]))
        break
    add(float(g[best]))
    for k in sorted(np.flatnonzero(r <= r[best] + SLACK), key=lambda i: (round(abs(g[i] - g[best]), 6), g[i])):
        add(float(g[k]))
    return tuple(out)


def retried(
    curves: Sequence[CurveEstimate],
    tries: dict[str, tuple[float, ...]],
    outcomes: dict[str, SeamOutcome],
    plan_at: Callable[[float, CurveEstimate], WeldPlan | None],
) -> list[tuple[float, WeldPlan]]:
    """Each curve refused from its first E1 for a reason another E1 may change, planned alone from its next ones
    (``plan_at(e1, curve)``: the plan of that curve alone with the base at e1, None where home collides there)
    until one welds it whole. Returns the (E1, plan) of those that did; ``outcomes`` gets their feasible outcome,
    and the others keep their first refusal, naming every E1 tried."""
    out: list[tuple[float, WeldPlan]] = []
    for c in curves:
        first = outcomes.get(c.id)
        if first is None or first.feasible or first.code in _SOMEWHERE_ELSE or len(tries[c.id]) < 2:
            continue
        for e1 in tries[c.id][1:]:
            plan = plan_at(e1, c)
            got = next((o for o in plan.seams if o.seam_id == c.id), None) if plan is not None else None
            if plan is not None and got is not None and got.feasible:
                outcomes[c.id] = got
                out.append((e1, plan))
                break
        else:
            at = ", ".join(f"{e * 1000:.0f}" for e in tries[c.id])
            outcomes[c.id] = replace(first, reason=f"{first.reason} (tried from E1 = {at} mm on the track)")
    return out


def in_part_at(
    curves: Sequence[CurveEstimate],
    tries: dict[str, tuple[float, ...]],
    outcomes: dict[str, SeamOutcome],
    plan_at: Callable[[float, CurveEstimate], WeldPlan | None],
) -> list[tuple[float, WeldPlan]]:
    """Each curve no E1 welds whole (its outcome refused for a reason another E1 may change), planned alone from its
    first E1 with the process's ``curve_remainder: manual`` (``plan_at(e1, curve)``); the (E1, plan) of those
    welded in part, ``outcomes`` getting their partial outcome; the others keep their refusal."""
    out: list[tuple[float, WeldPlan]] = []
    for c in curves:
        first = outcomes.get(c.id)
        if first is None or first.feasible or first.code in _SOMEWHERE_ELSE:
            continue
        plan = plan_at(tries[c.id][0], c)
        got = next((o for o in plan.seams if o.seam_id == c.id), None) if plan is not None else None
        if plan is not None and got is not None and got.partial:
            outcomes[c.id] = got
            out.append((tries[c.id][0], plan))
    return out
