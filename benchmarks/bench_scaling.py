"""Scaling benchmark: how the detection stages grow with the number of seams and points (fence1 vs ladder).

    .venv/bin/python benchmarks/bench_scaling.py [--scenarios fence1,ladder] [--methods paper,ransac,ours]
        [--noise realistic|none] [--repeat N] [--json PATH]

Issue "scaling": a generated larger fence (dozens of junctions, 100 seams or more) shows how time grows with the
number of seams and points; our locator's time per seam stays flat (within 20 % from 16 to 100+ seams).
Each scenario is captured and perceived once (through :mod:`cell.pipeline`, as ``cell detect`` does); every
method then locates every seam of it on that same scene. Per method: the median wall time per visible seam over
``--repeat`` runs of the locator (the fastest run of each seam, as in ``cell bench``), the total locate time (the
fastest run), how many seams
it found and its mean paper ME / lateral error against the simulator's ground truth; and what perception makes
for the locators (outside every locate time): the voxel grid and the voxel order. Single thread, wall clock.
A locator that finds a scene's seams together (ours) charges each seam an equal share of the whole batch; its
seams are also located one by one (``ms_per_seam_alone_median``: the median seam alone, fastest run).
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path
from typing import Any

from cell import pipeline
from cell import scenario as sc
from cell.export.report import write_json
from cell.perception.preprocess import downsample
from cell.seams.base import BatchSeamLocator
from cell.seams.registry import make_locator
from cell.types import SeamEstimate, SeamStatus
from cell.voxels import voxel_order


def bench(name: str, methods: list[str], noise: str, repeat: int) -> dict[str, Any]:
    """One row: the scenario's size, its stage times [s] and, per method, ms per seam and accuracy."""
    s = sc.load(name).with_noise("none" if noise == "none" else "realistic")
    cap = pipeline.capture(s)
    t = time.perf_counter()
    scene = pipeline.build_scene(cap)
    build_s = time.perf_counter() - t
    truth = pipeline.truths(cap, scene.seam_scene.weldmap)
    ss = scene.seam_scene
    row: dict[str, Any] = {
        "scenario": name,
        "noise": s.noise,
        "cameras": len(s.cameras),
        "seams": len(ss.weldmap.seams),
        "points_dense": len(ss.dense),
        "points_voxel": len(ss.cloud),
        "capture_s": cap.seconds,
        "perceive_s": scene.timings.get("perceive_s", float("nan")),
        "align_s": scene.timings.get("align_s", float("nan")),
        "build_scene_s": build_s,
        "methods": {},
    }
    # What perception makes for the locators (in no locate time): the paper's and RANSAC's voxel cloud, the
    # voxel-ordered dense cloud ours reads.
    per = scene.perceived
    voxel_grid, ordering = [], []
    for _ in range(max(1, repeat)):
        t = time.perf_counter()
        downsample(per.dense, s.perception.voxel_m)
        voxel_grid.append(time.perf_counter() - t)
        t = time.perf_counter()
        voxel_order(per.registered, s.perception.voxel_m)
        ordering.append(time.perf_counter() - t)
    row["voxel_grid_ms"], row["voxel_order_ms"] = 1000.0 * min(voxel_grid), 1000.0 * min(ordering)
    all_runs: dict[str, list[tuple[SeamEstimate, ...]]] = {method: [] for method in methods}
    for _ in range(max(1, repeat)):
        for method in methods:  # taking turns, each from a cold cache, as in cell bench
            scene.seam_scene.cache.clear()
            all_runs[method].append(pipeline.locate(scene, s, method))
    for method in methods:
        runs = all_runs[method]
        est = runs[0]
        visible = [i for i, e in enumerate(est) if e.status is not SeamStatus.NOT_VISIBLE]
        row["visible"] = len(visible)
        per_seam, summary = pipeline.evaluate(est, truth)
        ms = [min(r[i].time_s for r in runs) * 1000.0 for i in visible]
        row["methods"][method] = {
            "found": len(per_seam),
            "ms_per_seam_median": statistics.median(ms) if ms else float("nan"),
            "locate_s": min(sum(e.time_s for e in r) for r in runs),
            "paper_me_mean_mm": summary.paper_me_mean_mm,
            "lateral_mean_mm": statistics.fmean(m.lateral_mm for m in per_seam.values()) if per_seam else float("nan"),
        }
        locator = make_locator(method, s)
        if isinstance(locator, BatchSeamLocator):
            # Its seams one by one as well: the median seam alone, from a cold cache each run (is there global
            # work per seam that the batch hides?).
            seams = [ss.weldmap.seams[i] for i in visible]
            alone = []
            for _ in range(max(1, repeat)):
                ss.cache.clear()
                times = []
                for seam in seams:
                    t = time.perf_counter()
                    locator.locate(ss, seam, s.rng(f"locator/{method}"))
                    times.append(time.perf_counter() - t)
                alone.append(statistics.median(times) * 1000.0)
            row["methods"][method]["ms_per_seam_alone_median"] = min(alone)
    return row


def table(rows: list[dict[str, Any]]) -> str:
    """Markdown: one line per scenario and method."""
    head = (
        "| scenario | seams | visible | points dense / voxel | capture s | perceive s | align s | method | found | "
        "locate s | ms/seam median | paper ME mm | lateral mm |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n"
    )
    lines = []
    for r in rows:
        for m, v in r["methods"].items():
            lines.append(
                f"| {r['scenario']} | {r['seams']} | {r['visible']} | {r['points_dense']} / {r['points_voxel']} | "
                f"{r['capture_s']:.2f} | {r['perceive_s']:.2f} | {r['align_s']:.2f} | {m} | {v['found']} | "
                f"{v['locate_s']:.3f} | {v['ms_per_seam_median']:.2f} | {v['paper_me_mean_mm']:.3f} | "
                f"{v['lateral_mean_mm']:.3f} |"
            )
    return head + "\n".join(lines) + "\n"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenarios", default="fence1,ladder", help="comma-separated scenario names")
    ap.add_argument("--methods", default="paper,ransac,ours", help="comma-separated locator methods")
    ap.add_argument("--noise", choices=("realistic", "none"), default="realistic")
    ap.add_argument("--repeat", type=int, default=3, help="locator runs per scene (fastest run per seam)")
    ap.add_argument("--json", type=Path, default=None, help="write the rows as JSON here")
    args = ap.parse_args()
    methods = [m.strip() for m in args.methods.split(",") if m.strip()]
    rows = [bench(n.strip(), methods, args.noise, args.repeat) for n in args.scenarios.split(",") if n.strip()]
    print(table(rows))
    for r in rows:
        print(
            f"{r['scenario']}: perception's voxel grid (paper, ransac) {r['voxel_grid_ms']:.1f} ms, "
            f"voxel order of the dense cloud (ours) {r['voxel_order_ms']:.1f} ms"
        )
    if "ours" in methods and len(rows) >= 2:
        small, large = rows[0], rows[-1]
        a = small["methods"]["ours"]["ms_per_seam_median"]
        b = large["methods"]["ours"]["ms_per_seam_median"]
        print(
            f"ours ms/seam: {small['visible']} -> {large['visible']} visible seams: {a:.2f} -> {b:.2f} ms "
            f"({(b / a - 1.0) * 100.0:+.0f} %)"
        )
        a = small["methods"]["ours"]["ms_per_seam_alone_median"]
        b = large["methods"]["ours"]["ms_per_seam_alone_median"]
        print(f"ours ms/seam one by one (median seam): {a:.2f} -> {b:.2f} ms ({(b / a - 1.0) * 100.0:+.0f} %)")
    if args.json is not None:
        print(f"wrote {write_json(args.json, rows)}")


if __name__ == "__main__":
    main()
