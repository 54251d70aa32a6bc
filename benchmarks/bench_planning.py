"""Planning benchmark: how the planner's time grows with the part (fence1, fence2, the 208-seam ladder).

    .venv/bin/python benchmarks/bench_planning.py [--scenarios fence1,fence2,ladder] [--weld ladder]
        [--json PATH]

Per scenario the cell is captured and perceived once (``pipeline.detect``, no close-up re-scan), then the found
seams are planned and gated as ``cell weld`` does (``pipeline.weld.plan_for``: torch search, IK, timing, order,
transfers, the safety gate). Reported: seams asked for, planned, refused per reason code, the plan's cycle time,
planning CPU time (``time.process_time``: the machine is shared, wall time is given too) in all, per planned seam
and per seam asked for, and the reach pre-check's time per seam (``cell.planning.reach.seam_reach`` on every task,
the median of five runs). The figure to watch: ladder planning CPU per planned seam against fence1's (the goal: at
most 1.5 x). With ``--weld NAME`` the whole ``cell weld NAME`` (capture, perception, re-scan, plan, gate, execute) is
run too: its wall time per stage and how many seams it welded.
"""

from __future__ import annotations

import argparse
import collections
import os
import statistics
import time
from pathlib import Path
from typing import Any

from cell import pipeline
from cell import scenario as sc
from cell.export.reports.report import write_json
from cell.pipeline.detect import read_weldmap
from cell.pipeline.geometry import motion_scene, open_cell
from cell.pipeline.weld import plan_for


def bench(name: str) -> dict[str, Any]:
    """One row: the scenario's seams, what the planner made of them and what it cost."""
    from cell.pipeline.placeable import seam_procedures
    from cell.planning.plan import reach_model
    from cell.planning.reach import seam_reach
    from cell.planning.seam_search import seam_process
    from cell.planning.tasks import seam_tasks
    from cell.process.torch import WeldProcess
    from cell.types.plan import SeamProcedure

    s = sc.load(name)
    weldmap = read_weldmap(s)
    with open_cell(s, weldmap) as station:
        det = pipeline.detect(s, station=station, weldmap=weldmap)
        arm = station.arm
        assert arm is not None
        t_wall, t_cpu = time.perf_counter(), time.process_time()
        motion = motion_scene(arm, det)
        plan, _, problems = plan_for(station, det, motion=motion)
        cpu, wall = time.process_time() - t_cpu, time.perf_counter() - t_wall
        assert det.scene is not None
        ss = det.scene.seam_scene
        tasks = seam_tasks(det.estimates, ss.weldmap, ss.joints, ss.table_z)
        reach = reach_model(arm.model)
        process = WeldProcess.from_spec(s.process, s.robot.stickout_mm)
        procs = seam_procedures(s, det, tasks)
        runs = []
        if reach is not None:
            for _ in range(5):
                t = time.perf_counter()
                for task in tasks:
                    sel = procs.get(task.id)
                    proc = sel if isinstance(sel, SeamProcedure) else None
                    seam_reach(reach, proc.oriented(task) if proc else task, seam_process(process, proc))
                runs.append((time.perf_counter() - t) / max(len(tasks), 1))
    planned = [o for o in plan.seams if o.feasible]
    refused = collections.Counter(str(o.code) for o in plan.seams if not o.feasible)
    return {
        "scenario": name,
        "seams_in_map": len(weldmap.seams),
        "seams_asked": len(plan.seams),
        "seams_planned": len(planned),
        "refused_by_code": dict(sorted(refused.items())),
        "gate_problems": len(problems),
        "cycle_time_s": round(plan.cycle_time, 3),
        "planning_cpu_s": round(cpu, 3),
        "planning_wall_s": round(wall, 3),
        "cpu_s_per_planned_seam": round(cpu / max(len(planned), 1), 4),
        "cpu_s_per_seam_asked": round(cpu / max(len(plan.seams), 1), 4),
        "reach_precheck_us_per_seam": round(1e6 * statistics.median(runs), 1) if runs else None,
    }


def weld_run(name: str) -> dict[str, Any]:
    """The whole ``cell weld NAME``: wall time per stage [s], welded seams, the plan's refusals."""
    t = time.perf_counter()
    run = pipeline.weld(sc.load(name))
    wall = time.perf_counter() - t
    welded = sum(1 for w in run.seams if w.welded)
    reasons = collections.Counter(str(w.code) for w in run.seams if not w.welded)
    return {
        "scenario": name,
        "wall_s": round(wall, 2),
        "timings_s": {k: round(v, 2) for k, v in run.timings.items()},
        "welded": welded,
        "visible": sum(1 for w in run.seams if str(w.code) != "not_visible"),
        "not_welded_by_code": dict(sorted(reasons.items())),
        "error": run.error.message if run.error is not None else None,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scenarios", default="fence1,fence2,ladder")
    ap.add_argument("--weld", default="", help="scenarios to run `cell weld` on end to end (comma separated)")
    ap.add_argument("--json", type=Path, default=None)
    args = ap.parse_args()
    rows = [bench(n) for n in args.scenarios.split(",") if n]
    for r in rows:
        print(
            f"{r['scenario']:8s} planned {r['seams_planned']:3d}/{r['seams_asked']:3d}  planning CPU "
            f"{r['planning_cpu_s']:7.2f} s (wall {r['planning_wall_s']:7.2f} s)  {r['cpu_s_per_planned_seam']:.3f} s"
            f" per planned seam  reach pre-check {r['reach_precheck_us_per_seam']} us a seam  refused "
            f"{r['refused_by_code']}"
        )
    by = {r["scenario"]: r for r in rows}
    ratio = None
    if "ladder" in by and "fence1" in by:
        ratio = by["ladder"]["cpu_s_per_planned_seam"] / by["fence1"]["cpu_s_per_planned_seam"]
        print(f"ladder / fence1 planning CPU per planned seam: {ratio:.2f} (the goal: at most 1.5)")
    welds = [weld_run(n) for n in args.weld.split(",") if n]
    for w in welds:
        print(f"cell weld {w['scenario']}: {w['wall_s']} s wall, welded {w['welded']}/{w['visible']}, {w['timings_s']}")
    if args.json is not None:
        load = os.getloadavg()
        write_json(
            args.json,
            {
                "benchmark": "planning",
                "cpu_count": os.cpu_count(),
                "load_average_1_5_15": [round(x, 2) for x in load],
                "rows": rows,
                "ladder_over_fence1_per_planned_seam": round(ratio, 3) if ratio is not None else None,
                "weld_runs": welds,
            },
        )


if __name__ == "__main__":
    main()
