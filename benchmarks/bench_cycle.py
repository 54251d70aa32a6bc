"""Cycle time against its bound: where each plan's robot time goes, and how far its air time is from the fastest the
arm could do between the same welds.

    .venv/bin/python benchmarks/bench_cycle.py [--scenarios fence1,fence2,ladder,brace,bracket,fence1-wps]
        [--json PATH]

Per scenario the whole job ``cell weld SCENARIO`` runs (:func:`cell.pipeline.turnover.weld_part`: side A, the turn,
side B), and every side's checked plan is taken apart (``benchmarks/cycle_bound.py``): its cycle time (home to
home), the arc time (craters and dwells in it, also given apart), the seams' own approaches and departs, the
transfers between seams, the legs from and to home, the time at rest with the arc off; and the bound of its air
time (cycle minus arc): rest-to-rest PTP moves (Ruckig, the arm's own velocity, acceleration and jerk limits,
straight in joint space, no collisions; a track's E1 as a seventh axis) from the plan's start through the plan's own
weld starts and ends to its end, over the best order and direction of the seams (exact up to 13 seams, else 2-opt
with a certified lower bound ``air_lower_s``). Both sides add up; the job's robot time (re-scans and the move from
the scan pose too), the operator's turn, the weld accuracy (worst executed TCP max against the true seam), the
planner's own time (``planning_s``, each side's last gate round) and the wall time come with each row (default
``benchmarks/results/cycle.json``). docs/cycle.md says what the figures mean.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))

from cycle_bound import Breakdown, best_tour, breakdown, nodes, with_track

from cell import scenario as sc
from cell.export.reports.report import write_json

RESULTS = Path(__file__).resolve().parent / "results"
SCENARIOS = ("fence1", "fence2", "ladder", "brace", "bracket", "fence1-wps")
Row = dict[str, Any]


def _say(msg: str) -> None:
    print(f"· {msg}", file=sys.stderr, flush=True)


def _r(v: float) -> float:
    return round(float(v), 3)


def side_row(run: Any, scenario: sc.Scenario) -> Row | None:
    """One side's plan: its breakdown and bound (None when the side planned nothing)."""
    plan = run.plan
    if plan is None or not plan.segments or run.execution is None:
        return None
    track = scenario.robot.track.track(scenario.X_WR) if scenario.robot.track is not None else None
    limits = with_track(run.arm.model.limits, track)
    b: Breakdown = breakdown(plan)
    t = time.perf_counter()
    tour = best_tour(nodes(plan, track, limits), limits)
    return {
        "seams": len(plan.order),
        "cycle_time_s": _r(b.cycle_s),
        "arc_time_s": _r(b.arc_s),
        "crater_dwell_s": _r(b.crater_dwell_s),
        "air_time_s": _r(b.air_s),
        "approach_s": _r(b.approach_s),
        "depart_s": _r(b.depart_s),
        "transfer_s": _r(b.transfer_s),
        "home_s": _r(b.home_s),
        "wait_s": _r(b.wait_s),
        "track_only_s": _r(b.track_only_s),
        "air_bound_s": _r(tour.air_s),
        "air_lower_s": _r(tour.lower_s),
        "bound_exact": tour.exact,
        "bound_order": list(tour.order),
        "bound_reversed": list(tour.reversed),
        "plan_order": list(plan.order),
        "pre_move_s": _r(run.pre_move.duration if run.pre_move is not None else 0.0),
        "rescan_motion_s": _r(run.rescan.motion_s if run.rescan is not None else 0.0),
        "planning_s": _r(plan.planning_s),
        "bound_wall_s": _r(time.perf_counter() - t),
    }


_SUMMED = (
    "seams",
    "cycle_time_s",
    "arc_time_s",
    "crater_dwell_s",
    "air_time_s",
    "approach_s",
    "depart_s",
    "transfer_s",
    "home_s",
    "wait_s",
    "track_only_s",
    "air_bound_s",
    "air_lower_s",
    "pre_move_s",
    "rescan_motion_s",
    "planning_s",
)


def bench(name: str) -> Row:
    """One scenario's row: both sides summed, each side's own figures under ``sides``."""
    from cell.export.reports.turnover_report import turnover_report
    from cell.pipeline.turnover import weld_part

    _say(f"cell weld {name}")
    scenario = sc.load(name)
    t = time.perf_counter()
    run = weld_part(scenario)
    wall = time.perf_counter() - t
    sides = {"A": side_row(run.side_a, scenario)}
    if run.side_b is not None:
        sides["B"] = side_row(run.side_b, scenario)
    kept = {k: v for k, v in sides.items() if v is not None}
    row: Row = {"scenario": name}
    for key in _SUMMED:
        row[key] = _r(sum(v[key] for v in kept.values())) if key != "seams" else sum(v[key] for v in kept.values())
    row["air_over_bound"] = _r(row["air_time_s"] / row["air_bound_s"]) if row["air_bound_s"] > 0 else None
    row["bound_exact"] = all(v["bound_exact"] for v in kept.values())
    rep = turnover_report(run)
    tcp = [s["tcp_error_mm"]["max"] for s in rep["seams"] if s.get("welded") and s.get("tcp_error_mm", {}).get("max")]
    row |= {
        "welded": rep["welded"],
        "tcp_max_mm": max(tcp) if tcp else None,
        "robot_time_s": _r(run.cycle_time_s),
        "operator_s": _r(run.operator_s if run.side_b is not None else 0.0),
        "job_time_s": _r(run.job_time_s),
        "wall_s": _r(wall),
        "sides": kept,
    }
    return row


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenarios", default=",".join(SCENARIOS), help="comma-separated scenario names")
    ap.add_argument("--json", type=Path, default=RESULTS / "cycle.json", help="where the rows go")
    args = ap.parse_args(argv)
    rows = [bench(n.strip()) for n in args.scenarios.split(",") if n.strip()]
    for r in rows:
        keys = ("scenario", "seams", "cycle_time_s", "arc_time_s", "air_time_s", "air_bound_s", "air_over_bound")
        print(" ".join(f"{k}={r.get(k)}" for k in keys))
    out = {
        "benchmark": "cycle",
        "cpu_count": os.cpu_count(),
        "load_average_1_5_15": [round(x, 2) for x in os.getloadavg()],
        "rows": rows,
    }
    print(f"wrote {write_json(args.json, out)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
