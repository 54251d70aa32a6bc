"""A probe, by hand (not a test, not a benchmark table): a round scenario's curves planned from truth-built estimates
(:mod:`bench_curve_weld`'s; ``--located``: the curves located and re-scanned up close as ``cell weld`` locates them)
with the reach map's gap walk on (``plan_arcs(..., gap_walk=True)``), printing every
stage's stretches, every arc of every cover tried and why it failed, and the CPU time; the figures of
docs/curves-welding.md section 7 on the railing's bottom fillets.

    .venv/bin/python benchmarks/probe_gap_walk.py [--scenario railing] [--seams POST_L>BOTTOM_RAIL,...] [--located]
"""

from __future__ import annotations

import argparse
import time
from typing import Any

import cell.planning.curves.arcs as arcs_mod
from cell.planning.curves.split import Split
from cell.planning.failures import SeamFailure
from cell.types.plan import PlanReason
from cell.types.seams import SeamStatus


def _runs(label: str, runs: list[Any]) -> None:
    print(f"  {label}")
    for r in runs:
        if not r.spare:
            rows = 0 if r.track is None else len(r.track)
            print(f"    {'rev' if r.cand.reversed else 'fwd'} {r.a_m * 1e3:6.1f} -> {r.b_m * 1e3:6.1f} mm "
                  f"({r.length * 1e3:5.1f} mm, {rows} stations)")  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", default="railing")
    ap.add_argument("--seams", default="POST_L>BOTTOM_RAIL,POST_R>BOTTOM_RAIL")
    ap.add_argument("--located", action="store_true", help="the located curves, re-scanned up close, not the truth")
    args = ap.parse_args()
    import bench_curve_weld as bench

    from cell import pipeline
    from cell import scenario as sc
    from cell.pipeline.curved.rescan_all import rescan_all
    from cell.pipeline.detect import read_weldmap
    from cell.pipeline.geometry import motion_scene, open_cell
    from cell.pipeline.weld import plan_for

    captured: dict[str, tuple[Any, ...]] = {}
    plan_arcs = arcs_mod.plan_arcs

    def keep(search: Any, est: Any, q0: Any, proc: Any = None) -> Split:  # record each curve's search, plan none
        captured[est.id] = (search, est, q0, proc)
        return Split((), 0.0, SeamFailure(PlanReason.IK_FAILED, "probed apart", est.p_RS[0], 0.0))

    s = sc.load(args.scenario)
    weldmap = read_weldmap(s)
    arcs_mod.plan_arcs = keep  # type: ignore[assignment]
    try:
        with open_cell(s, weldmap) as station:
            det = pipeline.detect(s, station=station, weldmap=weldmap)
            assert det.scene is not None and station.arm is not None
            curves = bench.truth_estimates(det.scene.seam_scene.weldmap, det.curve_truths)
            if args.located:
                det = rescan_all(station, det, "low")[1]
                curves = [c for c in det.curve_estimates if c.status is SeamStatus.FOUND]
            skip = {e.id for e in det.estimates}
            plan_for(station, det, skip=skip, motion=motion_scene(station.arm, det), curves=curves)
    finally:
        arcs_mod.plan_arcs = plan_arcs
    graph_map, walked, seeded, solve = arcs_mod.graph_map, arcs_mod.walked, arcs_mod.seeded, arcs_mod.arc_solution

    def graph_map_(*a: Any, **k: Any) -> Any:
        got = graph_map(*a, **k)
        _runs(f"map, {len(a[2])} settings", got[0])
        return got

    def walked_(*a: Any, **k: Any) -> Any:
        t0 = time.process_time()
        got = walked(*a, **k)
        wins = ", ".join(f"{lo * 1e3:.0f}-{hi * 1e3:.0f}" for lo, hi in a[3])
        _runs(f"walked again (windows {wins} mm; {time.process_time() - t0:.1f} s CPU)", got)
        return got

    def seeded_(*a: Any, **k: Any) -> Any:
        t0 = time.process_time()
        got = seeded(*a, **k)
        _runs(f"walked from the gaps' middles ({time.process_time() - t0:.1f} s CPU)", got)
        return got

    def solve_(search: Any, arc: Any, run: Any, *a: Any, **k: Any) -> Any:
        got = solve(search, arc, run, *a, **k)
        why = got.where if isinstance(got, SeamFailure) else "solved"
        print(f"    arc {'rev' if run.cand.reversed else 'fwd'} {run.a_m * 1e3:.1f} -> {run.b_m * 1e3:.1f} mm: {why}")
        return got

    arcs_mod.graph_map, arcs_mod.walked, arcs_mod.seeded, arcs_mod.arc_solution = graph_map_, walked_, seeded_, solve_
    for cid, (search, est, q0, proc) in captured.items():
        if not any(cid.startswith(w) for w in args.seams.split(",")):
            continue
        print(f"{cid}: {est.length_m * 1e3:.1f} mm", flush=True)
        t0, c0 = time.perf_counter(), time.process_time()
        got = plan_arcs(search, est, q0, proc, gap_walk=True)
        where = got.failure.where if got.failure is not None else f"{len(got.arcs)} arcs"
        print(f"  whole {got.whole}, held {got.share:.0%}: {where}; {time.perf_counter() - t0:.0f} s wall, "
              f"{time.process_time() - c0:.0f} s CPU", flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
