"""A part on a positioner against the same part turned by an operator: ``cell weld fence1-positioner``
and ``cell weld fence1`` side by side (docs/positioner.md, "Figures").

    .venv/bin/python benchmarks/bench_positioner.py [--json PATH]

Per job: seams welded, operator turns, the job's time (robot time, the positioner's moves or the operator's turn),
the worst executed TCP max against the true seam, the planning's wall time in all and per seam planned (the
positioner's: choosing the poses and every pose's plan and gate, each pose's retries included, and apart from it
the checks of the positioner's moves against the arm; fence1's: both sides' plan and gate), and for the
positioner each seam's ISO 6947 position and how many in PA and PB (default
``benchmarks/results/positioner.json``). The planning's CPU time too (``plan_cpu_s``: the process's CPU seconds in
every call of the planner and gate, ``cell.pipeline.weld.plan_for``, on either side, and the positioner's choice of
its poses with their placement tests, ``choose_poses_cpu_s``), which a loaded machine stretches far less than the
wall time, and the load average before and after.
"""

from __future__ import annotations

import argparse
import importlib
import json
import os
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from cell import scenario as sc
from cell.export.reports.positioner_report import positioner_report

RESULTS = Path(__file__).resolve().parent / "results"


def _say(msg: str) -> None:
    print(f"· {msg}", file=sys.stderr, flush=True)


@contextmanager
def plan_cpu() -> Iterator[list[float]]:
    """The process's CPU seconds in ``plan_for`` while inside (summed into the one-element list yielded)."""
    weld = importlib.import_module("cell.pipeline.weld")  # the module (the package's ``weld`` is its function)
    spent, inner = [0.0], weld.plan_for

    def timed(*args: Any, **kwargs: Any) -> Any:
        t = time.process_time()
        try:
            return inner(*args, **kwargs)
        finally:
            spent[0] += time.process_time() - t

    weld.plan_for = timed
    try:
        yield spent
    finally:
        weld.plan_for = inner


def _cpu_row(run: Callable[[], dict[str, Any]]) -> dict[str, Any]:
    with plan_cpu() as spent:
        row = run()
    row["plan_cpu_s"] = round(spent[0] + row.get("choose_poses_cpu_s", 0.0), 3)  # the positioner: its poses too
    row["plan_cpu_per_seam_s"] = round(spent[0] / max(row["seams_planned"], 1), 3)
    return row


def fence1_row() -> dict[str, Any]:
    """``cell weld fence1``: side A, the operator's turn, side B."""
    from cell.pipeline.turnover import weld_part

    t = time.perf_counter()
    run = weld_part(sc.load("fence1"))
    wall = time.perf_counter() - t
    sides = [s for s in (run.side_a, run.side_b) if s is not None]
    plan_s = sum(s.timings.get("plan_s", 0.0) for s in sides)
    planned = sum(len(s.plan.order) for s in sides if s.plan is not None)
    tcp = [r.weld.quality.tcp_max_mm for r in run.records() if r.weld is not None and r.weld.quality is not None]
    return {
        "job": "cell weld fence1",
        "welded": run.welded,
        "seams": len(run.records()),
        "operator_turns": 1 if run.side_b is not None else 0,
        "job_time_s": round(run.job_time_s, 3),
        "robot_time_s": round(run.cycle_time_s, 3),
        "operator_s": run.operator_s,
        "tcp_max_mm": round(max(tcp), 3),
        "plan_s": round(plan_s, 3),
        "seams_planned": planned,
        "plan_per_seam_s": round(plan_s / max(planned, 1), 3),
        "wall_s": round(wall, 1),
    }


def positioner_row() -> dict[str, Any]:
    """``cell weld fence1-positioner``."""
    from cell.pipeline.positioned import weld_on_positioner

    t = time.perf_counter()
    run = weld_on_positioner(sc.load("fence1-positioner"))
    wall = time.perf_counter() - t
    rep = positioner_report(run)
    plan_s = sum(g.plan_wall_s for g in run.groups) + run.timings.get("choose_poses_s", 0.0)
    check_s = run.timings.get("move_check_s", 0.0)
    planned = len({i for g in run.groups for i in g.pose.seams})
    codes = [s["weld_position"]["code"] for s in rep["seams"] if s["weld_position"]]
    return {
        "job": "cell weld fence1-positioner",
        "welded": run.welded,
        "seams": len(rep["seams"]),
        "located": run.located(),
        "operator_turns": 0,
        "job_time_s": rep["totals"]["cycle_time_s"],
        "positioner_s": rep["totals"]["positioner_s"],
        "poses": len(run.groups),
        "tcp_max_mm": rep["totals"]["tcp_max_mm"],
        "plan_s": round(plan_s, 3),
        "seams_planned": planned,
        "plan_per_seam_s": round(plan_s / max(planned, 1), 3),
        "choose_poses_cpu_s": round(run.timings.get("choose_poses_cpu_s", 0.0), 3),
        "move_check_s": round(check_s, 3),
        "plan_and_move_check_per_seam_s": round((plan_s + check_s) / max(planned, 1), 3),
        "positions": {c: codes.count(c) for c in sorted(set(codes))},
        "in_tolerance": sum(bool(s["weld_position"] and s["weld_position"]["within_tolerance"]) for s in rep["seams"]),
        "wall_s": round(wall, 1),
        "seam_rows": rep["seams"],
        "pose_rows": [{k: v for k, v in p.items() if k != "seams"} for p in rep["poses"]],
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", type=Path, default=RESULTS / "positioner.json")
    args = ap.parse_args()
    load_before = os.getloadavg()[0]
    _say("cell weld fence1")
    a = _cpu_row(fence1_row)
    _say("cell weld fence1-positioner")
    b = _cpu_row(positioner_row)
    load_after = os.getloadavg()[0]
    _say("pipe-stub-positioner (coordinated: benchmarks/bench_coordinated.py)")
    from bench_coordinated import coordinated_row  # the circular fillet welded with the part turning

    c = {k: v for k, v in coordinated_row().items() if k != "waypoints"}
    out = {
        "command": "benchmarks/bench_positioner.py",
        "fence1": a,
        "fence1_positioner": b,
        "plan_per_seam_ratio": round(b["plan_per_seam_s"] / a["plan_per_seam_s"], 2),
        "plan_and_move_check_ratio": round(b["plan_and_move_check_per_seam_s"] / a["plan_per_seam_s"], 2),
        "plan_cpu_per_seam_ratio": round(b["plan_cpu_per_seam_s"] / a["plan_cpu_per_seam_s"], 2),
        "load_average_1min": [round(load_before, 2), round(load_after, 2)],
        "pipe_stub_positioner": c,
    }
    args.json.write_text(json.dumps(out, indent=1) + "\n")
    _say(f"wrote {args.json}")


if __name__ == "__main__":
    main()
