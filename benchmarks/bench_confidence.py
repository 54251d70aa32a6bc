"""Confidence calibration: how well our locator's confidence flags its own large errors.

    .venv/bin/python benchmarks/bench_confidence.py [--scenarios fence1-exact,fence1,fence2] [--seeds 4]
        [--big-mm 0.15] [--json PATH]

Each scenario is captured with seeds 0 .. N-1 (realistic noise; a new seed draws new sensor noise and, where the
scenario has them, new as-built deviations), perceived, and located with ``ours``. Per threshold: how many seams
fall below it (re-scanned by ``cell weld``) and how many of the seams with a lateral error over ``--big-mm`` it
catches; and the Spearman rank correlation of confidence with the lateral error. The re-scan threshold lives in
``cell.config.rescan.CONFIDENCE_THRESHOLD``. The table's figures and the per-seam rows go to ``--json`` (default
``benchmarks/results/confidence.json``), which ``tools/readme_results.py`` renders into docs/results.md.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

import numpy as np
from scipy.stats import spearmanr

from cell import pipeline
from cell import scenario as sc
from cell.config.rescan import CONFIDENCE_THRESHOLD
from cell.export.reports.report import write_json

RESULTS = Path(__file__).resolve().parent / "results"
THRESHOLDS = (0.45, 0.5, CONFIDENCE_THRESHOLD, 0.6, 0.65)


def seams(names: list[str], seeds: int) -> list[dict[str, Any]]:
    """One row per visible seam: scenario, seed, seam id, confidence, lateral and endpoint error [mm]."""
    rows = []
    for name in names:
        for seed in range(seeds):
            s = sc.load(name).with_noise("realistic").model_copy(update={"seed": seed})
            cap = pipeline.capture(s)
            scene = pipeline.build_scene(cap)
            truth = pipeline.truths(cap, scene.seam_scene.weldmap)
            estimates = pipeline.locate(scene, s, "ours")
            per_seam, _ = pipeline.evaluate(estimates, truth)
            for e in estimates:
                if e.status.value == "not_visible":
                    continue
                m = per_seam.get(e.id)
                rows.append(
                    {
                        "scenario": name,
                        "seed": seed,
                        "seam": e.id,
                        "confidence": e.confidence if m else 0.0,
                        "lateral_mm": m.lateral_mm if m else float("nan"),
                        "endpoint_mm": m.endpoint_mm if m else float("nan"),
                    }
                )
    return rows


def thresholds(rows: list[dict[str, Any]], big_mm: float) -> dict[str, Any]:
    """What the table shows: counts, the largest lateral error [mm], Spearman(confidence, lateral) and, per
    threshold, the seams below it, the seams over ``big_mm`` among them and the largest lateral error above it."""
    conf = np.array([r["confidence"] for r in rows])
    lat = np.array([r["lateral_mm"] for r in rows])
    found = np.isfinite(lat)
    big = found & (lat > big_mm)
    per_threshold = []
    for thr in THRESHOLDS:
        below = conf < thr
        above = found & ~below
        per_threshold.append(
            {
                "threshold": thr,
                "below": int(below.sum()),
                "caught": int((big & below).sum()),
                "max_lateral_above_mm": float(lat[above].max()) if above.any() else None,
            }
        )
    return {
        "seams": len(rows),
        "found": int(found.sum()),
        "big_mm": big_mm,
        "big": int(big.sum()),
        "max_lateral_mm": float(np.nanmax(lat)),
        "spearman": float(spearmanr(conf[found], lat[found])[0]),
        "thresholds": per_threshold,
    }


def summary(t: dict[str, Any]) -> str:
    """The thresholds' catch table and the rank correlation of :func:`thresholds`, as Markdown."""
    lines = [
        f"{t['seams']} seams, {t['found']} found, {t['big']} with a lateral error over {t['big_mm']} mm "
        f"(max {t['max_lateral_mm']:.3f} mm); Spearman(confidence, lateral) = {t['spearman']:.2f}",
        "",
        f"| threshold | seams below (re-scanned) | of the {t['big']} over {t['big_mm']} mm caught | "
        "max lateral above it [mm] |",
        "|---|---|---|---|",
    ]
    for r in t["thresholds"]:
        worst = r["max_lateral_above_mm"]
        lines.append(
            f"| {r['threshold']:.2f} | {r['below']} | {r['caught']} | {float('nan') if worst is None else worst:.3f} |"
        )
    return "\n".join(lines) + "\n"


def _finite(v: Any) -> Any:
    """NaN as null (JSON has no NaN)."""
    return None if isinstance(v, float) and not np.isfinite(v) else v


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenarios", default="fence1-exact,fence1,fence2", help="comma-separated scenario names")
    ap.add_argument("--seeds", type=int, default=4, help="seeds 0 .. N-1 per scenario")
    ap.add_argument("--big-mm", type=float, default=0.15, help="a lateral error over this is one to catch [mm]")
    ap.add_argument("--json", type=Path, default=RESULTS / "confidence.json", help="write the rows as JSON here")
    args = ap.parse_args()
    names = [n.strip() for n in args.scenarios.split(",") if n.strip()]
    rows = seams(names, args.seeds)
    table = thresholds(rows, args.big_mm)
    print(summary(table))
    data = {
        "scenarios": names,
        "seeds": args.seeds,
        **table,
        "per_seam": [{k: _finite(v) for k, v in r.items()} for r in rows],
    }
    print(f"wrote {write_json(args.json, data)}")


if __name__ == "__main__":
    main()
