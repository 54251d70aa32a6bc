"""Where the fixed arm's base stands, and how much of each round seam it welds: the round scenarios run through
``cell weld NAME --sides first`` with the robot's pedestal at several distances from the part (the cameras, the part
and everything else as shipped), per curved seam the share its arcs weld and what stops the arm on the rest.

    .venv/bin/python benchmarks/bench_layout.py [--scenarios pipe-flange,railing,round-brace,tube-tee]
        [--distances 1.05,0.9,0.8,0.65] [--workers 2] [--json benchmarks/results/layout.json]
    .venv/bin/python tools/readme_results.py   # its table in docs/results.md

The distance is the base's, along the world's y, from the map's origin (the part's middle): every round scenario
ships at 1.05 m, the pedestal at the table's near edge. Only the base's y changes (its pose stays a translation,
facing +y); a scenario whose eye-in-hand scan pose the arm no longer reaches says so in its row (``error``).
Each run is a separate process (``--workers`` at a time); the same scenario and distance give the same numbers.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing as mp
import time
from collections.abc import Sequence
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

SCENARIOS = ("pipe-flange", "railing", "round-brace", "tube-tee")
DISTANCES_M = (1.05, 0.9, 0.8, 0.65)
OUT = Path(__file__).resolve().parent / "results" / "layout.json"


def moved(name: str, distance_m: float) -> Any:
    """Scenario ``name`` with its robot base ``distance_m`` [m] from the map's origin along y (x and z as shipped)."""
    from cell import scenario as sc

    s = sc.load(name)
    x, _, z = s.robot.X_WR.xyz_m
    y = float(s.map.X_WM.xyz_m[1]) - distance_m
    pose = s.robot.X_WR.model_copy(update={"xyz_m": (x, y, z)})
    return s.model_copy(update={"robot": s.robot.model_copy(update={"X_WR": pose})})


def shipped(name: str) -> float:
    """Scenario ``name``'s own base distance [m] from the map's origin along y."""
    from cell import scenario as sc

    s = sc.load(name)
    return round(float(s.map.X_WM.xyz_m[1]) - float(s.robot.X_WR.xyz_m[1]), 6)


def run_one(name: str, distance_m: float) -> dict[str, Any]:
    """One scenario with its base at ``distance_m``: per curved seam welded whole, in part (share, length left for a
    manual weld, each stretch's code) or not (the planner's code); the straight seams welded; the run's time."""
    from cell.pipeline.job import WeldJob
    from cell.pipeline.weld import weld
    from cell.types import SeamStatus

    t0 = time.perf_counter()
    run = weld(moved(name, distance_m), WeldJob(sides="first"))
    det = run.detection
    curves = []
    for c in det.curve_estimates:
        w = det.curve_welds.get(c.id)
        share = 1.0 if w is not None and w.welded else (w.share if w is not None and w.partial else 0.0)
        curves.append(
            {
                "seam": c.id,
                "located": c.status.value,
                "length_mm": round(c.length_m * 1000.0, 1) if c.length_m else None,
                "welded": bool(w and w.welded),
                "share": round(share, 4),
                "manual_mm": round(w.manual_m * 1000.0, 1) if w is not None and w.partial else None,
                "stops": sorted({r.code.value for r in w.remainder}) if w is not None and w.partial else [],
                "code": None if w is None or w.welded else str(w.plan_code or w.code),
                "reason": c.reason if c.status is not SeamStatus.FOUND else None,  # why not located
            }
        )
    return {
        "scenario": name,
        "distance_m": distance_m,
        "straight_welded": sum(s.welded for s in run.seams),
        "straight_seams": len(run.seams),
        "error": run.error.message if run.error is not None else None,
        "total_s": round(time.perf_counter() - t0, 1),
        "curves": curves,
    }


def main(argv: Sequence[str] | None = None) -> None:
    from cell.provenance import git_commit

    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scenarios", default=",".join(SCENARIOS))
    ap.add_argument("--distances", default=",".join(f"{d:g}" for d in DISTANCES_M))
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--json", type=Path, default=OUT)
    args = ap.parse_args(argv)
    jobs = [(n, float(d)) for n in args.scenarios.split(",") for d in args.distances.split(",")]
    t0 = time.perf_counter()
    if args.workers <= 1:
        rows = [run_one(n, d) for n, d in jobs]
    else:
        with ProcessPoolExecutor(args.workers, mp_context=mp.get_context("spawn")) as pool:
            rows = list(pool.map(run_one, *zip(*jobs, strict=True)))
    command = "benchmarks/bench_layout.py"
    command += f" --scenarios {args.scenarios}" if args.scenarios != ",".join(SCENARIOS) else ""
    command += f" --distances {args.distances}" if args.distances != ",".join(f"{d:g}" for d in DISTANCES_M) else ""
    ships = {shipped(n) for n in args.scenarios.split(",")}
    out = {
        "command": f".venv/bin/python {command} --workers {args.workers}",
        "commit": git_commit(),
        "shipped_m": ships.pop() if len(ships) == 1 else None,
        "wall_min": round((time.perf_counter() - t0) / 60.0, 1),
        "rows": rows,
    }
    args.json.write_text(json.dumps(out, indent=2) + "\n")
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
