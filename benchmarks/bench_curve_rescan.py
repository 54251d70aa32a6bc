"""The close-up re-scan of doubtful curved seams, before and after: on the trust benchmark's random cells and on the
round scenarios, each curve as the fixed cameras located it and as the close-ups left it (docs/curves.md section 6).

    .venv/bin/python benchmarks/bench_curve_rescan.py [--cells 40] [--seed 0]
        [--scenarios pipe-flange,railing,round-brace,tube-tee] [--json PATH]

Random cell k is the trust benchmark's (``tools/random_cells.py`` from :func:`trust_cells.cell_seed` of the seed and
k); a cell without a curved seam is skipped. Each cell and round scenario (realistic noise, its own seed) is captured
and detected by the pipeline, then its doubtful curves re-scanned up close by the eye-in-hand camera
(:func:`cell.pipeline.curved.rescan.rescan_curves`: the call ``cell weld`` makes after the straight seams'
re-scan; planning and welding are not run). Per located curve, before and after: whether its bound passes the
weld gate (``rescan.max_sigma_m``), its largest sigma, its RMS and largest error against the true curve [mm], the
share of its samples within 2 sigma; the close-ups' robot time. Written to ``--json`` (default
``benchmarks/results/curve_rescan.json``).
"""

from __future__ import annotations

import argparse
import shlex
import sys
import time
from pathlib import Path
from typing import Any

BENCH = Path(__file__).resolve().parent
if str(BENCH) not in sys.path:
    sys.path.insert(0, str(BENCH))

import trust_cells as tc  # noqa: E402

from cell import scenario as sc  # noqa: E402
from cell.errors import CellError  # noqa: E402
from cell.export.reports.report import write_json  # noqa: E402
from cell.provenance import git_commit  # noqa: E402
from cell.types import SeamStatus  # noqa: E402

RESULTS = BENCH / "results"
SCENARIOS = ("pipe-flange", "railing", "round-brace", "tube-tee")


def _figures(c: Any, metrics: Any, limit: float) -> dict[str, Any]:
    m = metrics.get(c.id)
    return {
        "passes": bool(c.sigma_max_m <= limit),
        "sigma_max_mm": round(c.sigma_max_m * 1000.0, 4),
        "rms_mm": round(m.rms_mm, 4) if m else None,
        "max_mm": round(m.max_mm, 4) if m else None,
        "within_2sigma": round(m.within_2sigma, 4) if m else None,
        "samples": m.samples if m else None,
    }


def rows_of(scenario: Any, name: str) -> list[dict[str, Any]]:
    """One row per located curved seam of ``scenario``: before and after the close-ups."""
    from cell.pipeline.curved.rescan import rescan_curves
    from cell.pipeline.detect import detect, read_weldmap
    from cell.pipeline.geometry import motion_scene, open_cell

    wm = read_weldmap(scenario)
    if not wm.curved:
        return []
    limit = scenario.rescan.max_sigma_m
    with open_cell(scenario, wm) as station:
        det = detect(scenario, station=station, weldmap=wm)
        if det.error is not None or station.arm is None:
            print(f"· {name}: {det.error.message if det.error else 'no arm'}", file=sys.stderr)
            return []
        t = time.perf_counter()
        rs, after = rescan_curves(station, det, motion=motion_scene(station.arm, det))
        wall = time.perf_counter() - t
    out = []
    for b, a in zip(det.curve_estimates, after.curve_estimates, strict=True):
        if b.status is not SeamStatus.FOUND:
            continue
        out.append(
            {
                "scenario": name,
                "id": b.id,
                "before": _figures(b, det.curve_metrics, limit),
                "after": _figures(a, after.curve_metrics, limit),
                "reason": a.reason if a is not b else "",
                "rescan_motion_s": round(rs.motion_s, 2) if rs else 0.0,
                "rescan_wall_s": round(wall, 2),
            }
        )
    return out


def summary(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """Counts and worst figures of ``rows``, before and after."""
    out: dict[str, Any] = {"located": len(rows)}
    for when in ("before", "after"):
        f = [r[when] for r in rows]
        measured = [x for x in f if x["max_mm"] is not None]
        n = sum(x["samples"] for x in measured)
        out[when] = {
            "passing_gate": sum(x["passes"] for x in f),
            "samples_within_2sigma": round(sum(x["within_2sigma"] * x["samples"] for x in measured) / n, 4)
            if n
            else None,
            "max_error_mm": max((x["max_mm"] for x in measured), default=None),
            "max_error_of_passing_mm": max((x["max_mm"] for x in measured if x["passes"]), default=None),
            "worst_rms_mm": max((x["rms_mm"] for x in measured), default=None),
        }
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cells", type=int, default=40)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--scenarios", default=",".join(SCENARIOS))
    ap.add_argument("--work", type=Path, default=tc.REPO / "runs" / "curve_rescan", help="the random cells' folder")
    ap.add_argument("--json", type=Path, default=RESULTS / "curve_rescan.json")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    cells: list[dict[str, Any]] = []
    for k in range(args.cells):
        made = tc.generator().make_cell(tc.cell_seed(args.seed, k), args.work / str(k), kind="random")
        try:
            got = rows_of(sc.load(Path(made.scenario)), f"cell {k}")
        except CellError as e:
            print(f"· cell {k}: {e.message}", file=sys.stderr)
            continue
        cells += got
        for r in got:
            print(f"· {r['scenario']} {r['id']}: {r['before']} -> {r['after']}", file=sys.stderr)
    rounds: list[dict[str, Any]] = []
    for name in [s for s in args.scenarios.split(",") if s]:
        got = rows_of(sc.load(name).with_noise("realistic"), name)
        rounds += got
        for r in got:
            print(f"· {name} {r['id']}: {r['before']} -> {r['after']}", file=sys.stderr)
    result = {
        "command": "python " + shlex.join(["benchmarks/bench_curve_rescan.py", *(argv or sys.argv[1:])]),
        "commit": git_commit(),
        "wall_s": round(time.perf_counter() - t0, 1),
        "random_cells": {"summary": summary(cells), "rows": cells},
        "round_scenarios": {"summary": summary(rounds), "rows": rounds},
    }
    write_json(args.json, result)
    print(f"wrote {args.json}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
