"""Coverage of each locator's sigma: how often the true error of a found seam lies within 2 sigma.

    .venv/bin/python benchmarks/bench_coverage.py [--scenarios fence1-exact,fence1,fence2] [--seeds 3]
        [--faults faults/camera-dead,...] [--json PATH]

Each scenario is captured with seeds 0 .. N-1 (realistic noise; a new seed draws new sensor noise and, where the
scenario has them, new as-built deviations), and each fault scenario (``scenarios/faults/``, fence1 with one thing
wrong) with seed 0; every scene is perceived once and located with every registered locator. Per locator and
group (the three scenarios, the faults): the found seams, the share whose lateral error is within 2 sigma and within
3 sigma, the share whose endpoint error is within 2 sigma, the median sigma and the largest error. A sigma that
is calibrated covers about 95 % at 2 sigma. The sigma models' constants (``cell/seams/sigma.py``) cite this
benchmark. The figures and the per-seam rows go to ``--json`` (default ``benchmarks/results/coverage.json``),
which ``tools/readme_results.py`` renders into docs/results.md.
"""

from __future__ import annotations

import argparse
import math
import re
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from cell import pipeline
from cell import scenario as sc
from cell.config.seams import OursSettings
from cell.errors import CellError
from cell.export.reports.report import write_json
from cell.seams.registry import METHODS

RESULTS = Path(__file__).resolve().parent / "results"
SCENARIOS = ("fence1-exact", "fence1", "fence2")
FAULTS = (
    "faults/camera-bumped",
    "faults/camera-dead",
    "faults/camera-frozen",
    "faults/camera-random",
    "faults/camera-salt",
    "faults/displaced",
    "faults/extrinsics-fixed-off",
    "faults/extrinsics-off",
    "faults/missing-part",
    "faults/occluded",
    "faults/two-cameras-dead",
)


def seams(names: Sequence[str], seeds: int, group: str, methods: Sequence[str]) -> list[dict[str, Any]]:
    """One row per found seam and locator: group, scenario, seed, method, seam id, sigma, confidence, lateral and
    endpoint error [mm], the locator's reason."""
    rows = []
    for name in names:
        for seed in range(seeds):
            s = sc.load(name).with_noise("realistic").model_copy(update={"seed": seed})
            try:
                cap = pipeline.capture(s)
                scene = pipeline.build_scene(cap)
            except CellError:  # no camera left, the map not aligned: no seam to cover
                continue
            truth = pipeline.truths(cap, scene.seam_scene.weldmap)
            for method in methods:
                scene.seam_scene.cache.clear()
                estimates = pipeline.locate(scene, s, method)
                per_seam, _ = pipeline.evaluate(estimates, truth)
                for e in estimates:
                    m = per_seam.get(e.id)
                    if m is None or not m.found:
                        continue
                    rows.append(
                        {
                            "group": group,
                            "scenario": name,
                            "seed": seed,
                            "method": method,
                            "seam": e.id,
                            "sigma_mm": e.sigma_m * 1000.0,
                            "confidence": e.confidence,
                            "lateral_mm": m.lateral_mm,
                            "endpoint_mm": m.endpoint_mm,
                            "reason": e.reason,
                        }
                    )
    return rows


def coverage(rows: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
    """Per method and group (and every group together): found seams, the shares within 2 and 3 sigma (lateral),
    within 2 sigma (endpoint), the median sigma [mm] and the largest lateral and endpoint errors [mm]."""
    out = []
    methods = sorted({r["method"] for r in rows})
    present = {r["group"] for r in rows}
    groups = [*(g for g in ("scenarios", "faults") if g in present), "all"]
    for method in methods:
        for group in groups:
            sel = [r for r in rows if r["method"] == method and (group == "all" or r["group"] == group)]
            if not sel:
                continue
            sig = np.array([r["sigma_mm"] for r in sel])
            lat = np.array([r["lateral_mm"] for r in sel])
            end = np.array([r["endpoint_mm"] for r in sel])
            out.append(
                {
                    "method": method,
                    "group": group,
                    "found": len(sel),
                    "lateral_2sigma": float(np.mean(lat <= 2.0 * sig)),
                    "lateral_3sigma": float(np.mean(lat <= 3.0 * sig)),
                    "endpoint_2sigma": float(np.mean(end <= 2.0 * sig)),
                    "sigma_median_mm": float(np.median(sig)),
                    "lateral_max_mm": float(lat.max()),
                    "endpoint_max_mm": float(end.max()),
                }
            )
    return out


def calibration(rows: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """The figures the sigma models were chosen from (cell/seams/sigma.py), per group: the 95th percentile of each
    locator's lateral error [mm]; ours' coverage at 2 sigma with its statistical standard error alone (no floor);
    the paper's 95th percentile per confidence; Spearman's rank correlation of RANSAC's run spread with its error."""
    from scipy.stats import spearmanr

    floor_mm = OursSettings().sigma_floor_m * 1000.0
    out: dict[str, Any] = {"ours_floor_mm": floor_mm}
    for group in ("scenarios", "faults"):
        g = [r for r in rows if r["group"] == group]
        if not g:
            continue
        fig: dict[str, Any] = {}
        for method in sorted({r["method"] for r in g}):
            lat = np.array([r["lateral_mm"] for r in g if r["method"] == method])
            fig[f"{method}_lateral_p95_mm"] = float(np.percentile(lat, 95))
        ours = [r for r in g if r["method"] == "ours"]
        if ours:
            se = np.sqrt(np.maximum(np.array([r["sigma_mm"] for r in ours]) ** 2 - floor_mm**2, 0.0))
            fig["ours_se_alone_lateral_2sigma"] = float(np.mean(np.array([r["lateral_mm"] for r in ours]) <= 2 * se))
        paper = [r for r in g if r["method"] == "paper"]
        for conf in sorted({round(r["confidence"], 2) for r in paper}, reverse=True):
            lat = np.array([r["lateral_mm"] for r in paper if round(r["confidence"], 2) == conf])
            fig[f"paper_confidence_{conf:.2f}_lateral_p95_mm"] = float(np.percentile(lat, 95))
        spread = [
            (float(m.group(1)), r["lateral_mm"])
            for r in g
            if r["method"] == "ransac" and (m := re.search(r"spread ([0-9.]+) mm", r["reason"]))
        ]
        if len(spread) > 2:
            fig["ransac_spearman_spread_lateral"] = float(spearmanr(*zip(*spread, strict=True))[0])
        out[group] = fig
    return out


def summary(table: Sequence[dict[str, Any]]) -> str:
    """The coverage table of :func:`coverage`, as Markdown."""
    lines = [
        "| method | seams | found | lateral within 2 sigma | within 3 sigma | endpoint within 2 sigma "
        "| median sigma [mm] "
        "| max lateral [mm] |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in table:
        sigma = r["sigma_median_mm"]
        sigma_s = "inf" if not math.isfinite(sigma) else f"{sigma:.3f}"
        lines.append(
            f"| {r['method']} | {r['group']} | {r['found']} | {r['lateral_2sigma']:.0%} | {r['lateral_3sigma']:.0%} "
            f"| {r['endpoint_2sigma']:.0%} | {sigma_s} | {r['lateral_max_mm']:.3f} |"
        )
    return "\n".join(lines) + "\n"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenarios", default=",".join(SCENARIOS), help="comma-separated scenario names")
    ap.add_argument("--seeds", type=int, default=3, help="seeds 0 .. N-1 per scenario")
    ap.add_argument("--faults", default=",".join(FAULTS), help="comma-separated fault scenarios (seed 0 each)")
    ap.add_argument("--json", type=Path, default=RESULTS / "coverage.json", help="write the figures as JSON here")
    args = ap.parse_args()
    methods = list(METHODS)
    names = [n.strip() for n in args.scenarios.split(",") if n.strip()]
    faults = [n.strip() for n in args.faults.split(",") if n.strip()]
    rows = seams(names, args.seeds, "scenarios", methods) + seams(faults, 1, "faults", methods)
    table = coverage(rows)
    print(summary(table))
    data = {"scenarios": names, "seeds": args.seeds, "faults": faults, "coverage": table}
    write_json(args.json, {**data, "calibration": calibration(rows), "rows": rows})


if __name__ == "__main__":
    main()
