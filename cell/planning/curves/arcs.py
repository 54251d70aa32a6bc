"""A curved seam planned from its reach map: the fewest arcs that cover it whole with their overlaps (one, when a
torch setting holds all round), each solved along its whole length with its approach and depart; or the share of
it the arm can reach (docs/curves-welding.md section 10).

Frames: everything in the robot base frame R [m]; joints [rad]."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from cell.geometry import FloatArray
from cell.planning.curves.arc_solve import TRIES, arc_solution, same_stretch, trimmed, why_stopped
from cell.planning.curves.gapseed import seeded
from cell.planning.curves.gapwalk import walked
from cell.planning.curves.graph import gaps, graph_map, refined
from cell.planning.curves.partial import partial_arcs
from cell.planning.curves.path import curve_path, curve_poses
from cell.planning.curves.reach import Miss, Run, balanced, cover, pinch, settings, share, station_spacing
from cell.planning.curves.search import (
    _flange_axes,
    knot_spacing,
)
from cell.planning.curves.split import MAX_ARCS, Split, sub_arc
from cell.planning.failures import SeamFailure, better
from cell.planning.seam_search import SeamSearch, SeamSolution
from cell.process.torch_orientations import Candidate
from cell.process.weave import knot_spacing as weave_spacing
from cell.types.curve_estimate import CurveEstimate
from cell.types.plan import PlanReason, Remainder
from cell.types.procedure import WeldProcedure

SPARE_TRIES = 4  # covers tried more once the map's spare paths are added (each a full solve of its arcs)
GAP_MARGIN_M = 0.015  # [m] a gap in the map is walked again with finer settings this far either side of it


def plan_arcs(
    search: SeamSearch,
    est: CurveEstimate,
    q_seed: FloatArray,
    procedure: WeldProcedure | None = None,
    gap_walk: bool = False,
    refused: Sequence[Remainder] = (),
) -> Split:
    """The arcs that weld ``est`` whole (a closed curve all round and over its overlap; an open one end to end),
    fewest first, at most :data:`MAX_ARCS`, each solved (a :class:`SeamSolution` per pass of ``procedure``, its
    task an open arc of the curve, id ``<seam>#arcK``); else the share of the curve some torch setting reaches
    and the failure of the arc that got furthest. The map's graph (:mod:`.graph`) holds the nominal angles first,
    then the tolerance's ends too, then finer settings in its gaps; ``gap_walk``: then the gaps walked at finer
    stations (:mod:`.gapwalk`, :mod:`.gapseed`: no round scenario's curve welded by it yet, 10-60 s more per curve
    with a gap, so not in ``cell weld``; docs/curves-welding.md section 10). With no whole cover and the process's
    ``curve_remainder`` ``manual``: the arcs that weld what the arm reaches and the remainder left for a manual weld
    (:mod:`.partial`); ``refused``: arcs refused after the search at one end (the safety gate, a transfer), each
    trimmed there and the partial cover chosen again (:func:`.partial.partial_arcs`)."""
    pr, opt = search.process, search.opt
    knot = knot_spacing(est, opt.spacing)
    if procedure is not None:
        knot = weave_spacing(procedure, 0, knot)
    overlap = pr.closed_overlap if est.closed else 0.0
    probe = curve_path(est, station_spacing(est))
    flange = _flange_axes(search, q_seed, curve_poses(probe, pr)[:, :3, 2])
    runs: list[Run] = []
    misses: list[Miss] = []
    failure: SeamFailure | None = None
    stiff = pr.work_angle_tol <= 0.0 and pr.travel_angle_tol <= 0.0  # no angle to widen
    memo: dict[Candidate, list[FloatArray | None]] = {}  # each setting's joints at the stations, walked once
    for stage in range(1 if stiff else 4 if gap_walk else 3):  # nominal; tolerance's ends; finer settings, stations
        cands = settings(search, False) + (settings(search, True) if stage else [])
        windows = _windows(runs, est, overlap) if stage > 1 else []
        if stage > 1 and not windows:
            break
        cands += refined(search) if stage > 1 else []
        if stage == 3:
            got_runs = walked(search, est, runs, windows, flange, knot, overlap)
            got_runs += seeded(search, est, windows, flange, q_seed, knot, overlap)
            got_misses: list[Miss] = []
        else:
            got_runs, got_misses = graph_map(search, est, cands, flange, q_seed, knot, overlap, memo, windows)
        runs, misses = runs + [r for r in got_runs if not r.spare], misses + got_misses
        spare = sorted((r for r in got_runs if r.spare), key=_setting_changes)  # the fewest turns of the torch first
        for pool in range(2):  # the map's paths; then, once no cover of them welds, the spare paths too
            if pool and not spare:
                break
            runs = runs + spare if pool else runs
            for _ in range(SPARE_TRIES if pool else TRIES):
                chosen = cover(runs, est.length_m, est.closed, overlap, MAX_ARCS)
                if chosen is None:
                    break
                solved: list[tuple[CurveEstimate, tuple[SeamSolution, ...]]] = []
                arcs = balanced(chosen, est.length_m, est.closed, overlap)
                for k, (run, part) in enumerate(zip(chosen, arcs, strict=True), 1):
                    arc = sub_arc(est, part.a_m, part.b_m, k)
                    got = arc_solution(search, arc, part, flange, knot, procedure)
                    if isinstance(got, SeamFailure):
                        failure = better(failure, got)
                        runs = [r for r in runs if not same_stretch(r, run, est.length_m)] + trimmed(part, got, arc)
                        break
                    solved.append((arc, got))
                else:
                    spans = tuple((a.id, p.a_m, p.b_m) for (a, _), p in zip(solved, arcs, strict=True))
                    return Split(tuple(solved), 1.0, None, spans=spans)
    reached = share(runs, est.length_m, est.closed)
    if failure is None:
        failure = _gap(runs, misses, est, overlap)
    if pr.curve_remainder == "manual" and runs:  # weld what the arm reaches, the rest left for a manual weld
        got_part = partial_arcs(search, est, runs, misses, flange, knot, procedure, failure, refused)
        if got_part.partial:
            return got_part
    return Split((), reached, failure)


def _windows(runs: list[Run], est: CurveEstimate, overlap: float) -> list[tuple[float, float]]:
    """Where the map is walked again with finer settings (from, to) [m] along the located curve: its gaps, or with
    none, where every stretch through a point of a closed curve gives out short of the restart ``overlap`` [m]
    (:func:`.reach.pinch`), the overlap either side; each widened by :data:`GAP_MARGIN_M`."""
    out = gaps(runs, est.length_m, est.closed, GAP_MARGIN_M)
    at = pinch(runs, est.length_m, overlap) if est.closed and not out else None
    if at is not None:
        out.append((at[0] - overlap - GAP_MARGIN_M, at[0] + overlap + GAP_MARGIN_M))
    return out


def _setting_changes(run: Run) -> int:
    """How many times the torch's setting changes along ``run``."""
    if run.track is None:
        return 0
    return int(np.count_nonzero(np.any(np.abs(np.diff(run.track[:, 1:], axis=0)) > 1e-9, axis=1)))


def _gap(runs: list[Run], misses: list[Miss], est: CurveEstimate, overlap: float) -> SeamFailure:
    """The failure for a curve no cover of stretches welds: where its widest stretch no setting holds starts, how
    long it is (and how many such stretches, how much in all) and what stops the settings there (the commonest
    reason of the stations in it: its code); with every point held, where every stretch gives out short of the
    restart ``overlap`` [m] (:func:`.reach.pinch`, and what stops the settings there), else that no
    :data:`MAX_ARCS` arcs overlap by it all round."""
    total = est.length_m
    free = gaps(runs, total, est.closed, 0.0)
    at = pinch(runs, total, overlap) if est.closed and not free else None
    if at is not None:
        code, why = why_stopped(misses, at[0] - overlap, at[0] + overlap, total, est.closed)
        where = (f"every point is held, but every stretch through {at[0] * 1000:.0f} mm along it gives out within "
                 f"{at[1] * 1000:.1f} mm of it: no arc passes there to restart {overlap * 1000:.0f} mm back over the "
                 f"last ({why})")  # fmt: skip
        return SeamFailure(code, where, _point(est, at[0]), 0.0)
    if not free:
        where = (f"every point is held, but no {MAX_ARCS} arcs overlap by {overlap * 1000:.0f} mm at every restart "
                 "(the torch cannot turn through where the stretches give out fast enough)")  # fmt: skip
        return SeamFailure(PlanReason.COLLISION if misses else PlanReason.IK_FAILED, where, est.p_RS[0], 0.0)
    lo, hi = max(free, key=lambda g: g[1] - g[0])
    lo, hi = lo % total if est.closed else lo, (lo % total if est.closed else lo) + (hi - lo)
    code, why = why_stopped(misses, lo - 0.01, hi + 0.01, total, est.closed)
    unheld = sum(b - a for a, b in free)
    more = f"; {len(free)} such stretches, {unheld * 1000:.0f} mm in all" if len(free) > 1 else ""
    where = f"no torch setting holds it from {lo * 1000:.0f} mm along it ({(hi - lo) * 1000:.0f} mm{more}; {why})"
    return SeamFailure(code, where, _point(est, lo), 0.0)


def _point(est: CurveEstimate, at_m: float) -> FloatArray:
    """The located curve's sample nearest ``at_m`` [m] along it (3,)."""
    k = int(np.searchsorted(np.linspace(0, est.length_m, len(est.p_RS)), at_m % est.length_m))
    return np.asarray(est.p_RS[min(k, len(est.p_RS) - 1)])
