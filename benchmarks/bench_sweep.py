"""What one run of ``cell sweep`` costs, per stage: the CPU seconds of one varied fence1 build taken to
``detect``, ``plan`` and ``weld`` in one warm process (a first run pays the imports), as a Ray worker runs it
(one OpenMP thread), and what N runs would take on C cores at that cost.

    OMP_NUM_THREADS=1 .venv/bin/python benchmarks/bench_sweep.py [--scenario fence1] [--runs 2] [--n 200]
        [--cores 2] [--json /tmp/bench_sweep.json]

The default stage of ``cell sweep`` follows from these figures (docs/sweep.md). Writes to /tmp by default, never
to benchmarks/results/.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path
from typing import Any

from cell import pipeline
from cell import scenario as sc
from cell.sweep import STAGES, VARY_WORDS, run_task, variation


def measure(name: str, runs: int) -> dict[str, Any]:
    """Per stage: the CPU [s] and wall [s] of ``runs`` varied builds (runs 1 .. runs; run 0 warms the process)."""
    s = sc.load(name)
    weldmap = pipeline.read_weldmap(s)
    run_task(s, variation(s, weldmap, 0, VARY_WORDS), "detect")  # imports, first-time set-up
    out: dict[str, Any] = {}
    for stage in STAGES:
        cpu, wall = [], []
        for k in range(1, runs + 1):
            t, c = time.perf_counter(), time.process_time()
            res = run_task(s, variation(s, weldmap, k, VARY_WORDS), stage)
            cpu.append(time.process_time() - c)
            wall.append(time.perf_counter() - t)
            if res["line"]["error"] is not None:
                print(f"{stage} run {k}: {res['line']['error']['message']}")
        out[stage] = {"cpu_s": sum(cpu) / len(cpu), "wall_s": sum(wall) / len(wall), "runs": runs}
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenario", default="fence1")
    ap.add_argument("--runs", type=int, default=2, help="varied builds per stage (after one warm-up run)")
    ap.add_argument("--n", type=int, default=200, help="the sweep size to project")
    ap.add_argument("--cores", type=int, default=2)
    ap.add_argument("--json", type=Path, default=Path("/tmp/bench_sweep.json"))
    args = ap.parse_args()
    stages = measure(args.scenario, args.runs)
    for stage, fig in stages.items():
        fig["projected_min"] = fig["cpu_s"] * args.n / args.cores / 60.0
        print(
            f"{stage:>6}: {fig['cpu_s']:.2f} s CPU, {fig['wall_s']:.2f} s wall per run;"
            f" {args.n} runs on {args.cores} cores: {fig['projected_min']:.1f} min"
        )
    args.json.write_text(json.dumps({"scenario": args.scenario, "n": args.n, "cores": args.cores, "stages": stages}))


if __name__ == "__main__":
    main()
