"""Curved seams located on the round-part scenarios: found or not, the located curve's error against the true curve
over its length, its sigma's coverage and our locator's time per curved seam (docs/curves.md).

    .venv/bin/python benchmarks/bench_curves.py [--scenarios pipe-flange,railing,round-brace,tube-tee] [--seeds 3]
        [--repeats 5] [--json PATH]

Each scenario is captured with seeds 0 .. N-1 (realistic noise: a new seed draws new sensor noise), perceived and
aligned once, and its curved seams located by ours (:func:`cell.seams.curved.locate_curves`). Per curved seam and
seed: the status and reason code, the RMS and largest distance of the located samples to the true curve [mm], the
share of samples within 2 sigma of it, the largest ratio of error to sigma, the largest sigma, and the locator's time:
the median of ``--repeats`` runs on the same scene, perception (the dense cloud's index) made before the clock
starts, as wall time, as the process's CPU time (every thread's: a library's worker threads count too) and as the
calling thread's, with the run's involuntary and voluntary context switches (the scheduler giving the core to
another process; the locator waiting on something) and the machine's load average: on a shared machine the wall
time is the CPU time plus the time the core was given to others (docs/curves.md section 3). The rows and their
summary per seam go to ``--json`` (default ``benchmarks/results/curves.json``), which ``tools/readme_results.py``
renders into docs/results.md.
"""

from __future__ import annotations

import argparse
import os
import resource
import shlex
import statistics
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from cell import pipeline
from cell import scenario as sc
from cell.errors import CellError
from cell.export.reports.report import write_json
from cell.pipeline.evaluation import curve_truths
from cell.provenance import git_commit
from cell.seams.curved import locate_curves
from cell.seams.curved.locate import locate_curve
from cell.seams.curved.metrics import curve_error, distances_to_polyline
from cell.types import SeamStatus

RESULTS = Path(__file__).resolve().parent / "results"
SCENARIOS = ("pipe-flange", "railing", "round-brace", "tube-tee")


def rows_of(name: str, seed: int, repeats: int) -> list[dict[str, Any]]:
    """One row per curved seam of scenario ``name`` captured with ``seed``."""
    s = sc.load(name).with_noise("realistic").model_copy(update={"seed": seed})
    try:
        cap = pipeline.capture(s)
        scene = pipeline.build_scene(cap)
    except CellError as e:  # no camera left, the map not aligned: nothing located
        print(f"· {name} seed {seed}: {e.message}", file=sys.stderr)
        return []
    truths = curve_truths(cap)
    ss = scene.seam_scene
    estimates = locate_curves("ours", ss)  # what the pipeline runs (and builds the dense cloud's index first)
    # Per repeat, per curved seam: wall, process CPU, thread CPU [s], involuntary and voluntary switches.
    runs = [[_timed(ss, seam) for seam in ss.weldmap.curved] for _ in range(repeats)]
    load = os.getloadavg()[0]
    rows = []
    for k, est in enumerate(estimates):
        row: dict[str, Any] = {
            "scenario": name,
            "seed": seed,
            "seam": est.id,
            "status": est.status.value,
            "code": est.code.value if est.code is not None else None,
            "time_ms": statistics.median(r[k][0] for r in runs) * 1000.0,
            "cpu_ms": statistics.median(r[k][1] for r in runs) * 1000.0,
            "thread_cpu_ms": statistics.median(r[k][2] for r in runs) * 1000.0,
            "preempted": statistics.median(r[k][3] for r in runs),
            "waited": statistics.median(r[k][4] for r in runs),
            "load": round(load, 2),
        }
        if est.status is SeamStatus.FOUND and est.id in truths:
            m = curve_error(est, truths[est.id])
            d = distances_to_polyline(np.asarray(est.p_RS), truths[est.id], est.closed)
            row.update(
                rms_mm=m.rms_mm,
                max_mm=m.max_mm,
                within_2sigma=m.within_2sigma,
                error_over_sigma_max=float((d / est.sigma_m).max()),
                sigma_max_mm=est.sigma_max_m * 1000.0,
                sigma_min_mm=float(est.sigma_m.min()) * 1000.0,
                closed=est.closed,
                samples=m.samples,
            )
        rows.append(row)
        print(f"· {name} seed {seed} {est.id}: {row}", file=sys.stderr)
    return rows


def _timed(ss: Any, seam: Any) -> tuple[float, float, float, int, int]:
    """One run of the locator on ``seam``: wall, process CPU and thread CPU time [s], and the involuntary and
    voluntary context switches during it."""
    r0 = resource.getrusage(resource.RUSAGE_SELF)
    t0, p0, c0 = time.perf_counter(), time.process_time(), time.thread_time()
    locate_curve(ss, seam)
    t, p, c = time.perf_counter() - t0, time.process_time() - p0, time.thread_time() - c0
    r1 = resource.getrusage(resource.RUSAGE_SELF)
    return t, p, c, r1.ru_nivcsw - r0.ru_nivcsw, r1.ru_nvcsw - r0.ru_nvcsw


def summary(rows: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
    """Per scenario and curved seam, over the seeds: found of runs, the worst RMS and max error [mm], the share of
    all samples within 2 sigma, the worst sigma, the median times [ms], context switches and load average."""
    out = []
    keys = list(dict.fromkeys((r["scenario"], r["seam"]) for r in rows))
    for name, seam in keys:
        mine = [r for r in rows if (r["scenario"], r["seam"]) == (name, seam)]
        found = [r for r in mine if "rms_mm" in r]
        samples = sum(r["samples"] for r in found)
        out.append(
            {
                "scenario": name,
                "seam": seam,
                "runs": len(mine),
                "found": len(found),
                "codes": sorted({r["code"] for r in mine if r["code"]}),
                "rms_mm_worst": max((r["rms_mm"] for r in found), default=None),
                "max_mm_worst": max((r["max_mm"] for r in found), default=None),
                "within_2sigma": sum(r["within_2sigma"] * r["samples"] for r in found) / samples if samples else None,
                "sigma_max_mm": max((r["sigma_max_mm"] for r in found), default=None),
                "time_ms_median": statistics.median(r["time_ms"] for r in mine),
                "cpu_ms_median": statistics.median(r["cpu_ms"] for r in mine),
                "thread_cpu_ms_median": statistics.median(r["thread_cpu_ms"] for r in mine),
                "preempted_median": statistics.median(r["preempted"] for r in mine),
                "waited_median": statistics.median(r["waited"] for r in mine),
                "load_median": statistics.median(r["load"] for r in mine),
            }
        )
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenarios", default=",".join(SCENARIOS))
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--json", type=Path, default=RESULTS / "curves.json")
    args = ap.parse_args(argv)
    rows = []
    for name in args.scenarios.split(","):
        for seed in range(args.seeds):
            rows += rows_of(name, seed, args.repeats)
    command = " ".join(["benchmarks/bench_curves.py", *map(shlex.quote, sys.argv[1:] if argv is None else argv)])
    data = {
        "command": f".venv/bin/python {command}",
        "commit": git_commit(),
        "noise": "realistic",
        "summary": summary(rows),
        "rows": rows,
    }
    write_json(args.json, data)
    for r in data["summary"]:
        print(r)
    return 0


if __name__ == "__main__":
    sys.exit(main())
