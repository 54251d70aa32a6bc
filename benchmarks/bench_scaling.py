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

Perception per stage (``row["perception"]``, the fastest of ``--repeat`` runs of each on the same capture, wall
and CPU seconds; the CPU of open3d's threads counts too): ``perceive``'s own steps (``clouds``: deproject, crop
and the camera checks; ``splice``; ``preprocess``: Z passthrough and the isolated-point filter; ``downsample``),
the map alignment (``align_map``) and its two checks (``check_unique``, ``check_parts_seen``; side by side as the
pipeline runs them, ``check_alignment``), and loading
open3d's core (``open3d_import_s``, once per process: the first scenario's). ``detect_vs_capture`` says whether
perception keeps up with the capture, from the first (cold) run: perceive + align + locate (ours) against capture,
where locate is the wall time of ``pipeline.locate`` as ``cell detect`` runs it (the locator and the screen after
it, which the per-seam times leave out; ``locate_wall_s``, also per method: the fastest run).

Planning (``row["planning"]``): the seams ours found are planned and gated as ``cell weld`` does
(``pipeline.weld.plan_for`` on the same station: torch search, IK, timing, order, transfers, the safety gate), once;
seams asked for, planned and refused per reason code, planning CPU and wall seconds in all, per planned seam and per
seam asked for. Each row also keeps the machine's load average when it was measured (the machine may be shared).
"""

from __future__ import annotations

import argparse
import collections
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

from cell import pipeline
from cell import scenario as sc
from cell.export.reports.report import write_json
from cell.geometry import invert
from cell.perception import align_map, check_alignment, check_alignment_unique, check_parts_seen, perceive
from cell.perception.preprocess import downsample
from cell.pipeline.detect import read_weldmap
from cell.pipeline.geometry import motion_scene, open_cell
from cell.pipeline.weld import plan_for
from cell.scenario import Scenario
from cell.seams.base import BatchSeamLocator
from cell.seams.registry import make_locator
from cell.station import Station
from cell.types import SeamEstimate, SeamStatus, WeldMap
from cell.voxels import voxel_order


def _fastest(run: Any, repeat: int) -> tuple[Any, float, float]:
    """(result, fastest wall [s], fastest CPU [s]) of ``repeat`` calls of ``run()``."""
    wall, cpu, out = [], [], None
    for _ in range(max(1, repeat)):
        t, c = time.perf_counter(), time.process_time()
        out = run()
        wall.append(time.perf_counter() - t)
        cpu.append(time.process_time() - c)
    return out, min(wall), min(cpu)


def open3d_import_s() -> float:
    """Seconds to load open3d as the cell does (:mod:`cell.perception._open3d`), in a fresh interpreter with
    numpy already imported (in this process it is loaded once, inside the first ``perceive``)."""
    code = (
        "import time, numpy\nfrom cell.perception import _open3d\n"
        "t = time.perf_counter(); _open3d._o3d(); print(time.perf_counter() - t)"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return float(done.stdout.strip().splitlines()[-1])


def perception_stages(cap: pipeline.Capture, repeat: int) -> dict[str, Any]:
    """Wall and CPU seconds of each perception stage on one capture (module docstring), fastest of ``repeat``."""
    s = cap.scenario
    out: dict[str, Any] = {"open3d_import_s": open3d_import_s()}
    runs = []
    for _ in range(max(1, repeat)):
        c = time.process_time()
        per = perceive(cap.images, s.X_WR, s.perception, s.perception.health)
        runs.append((per.timings, time.process_time() - c))
    for key in runs[0][0]:
        out[key] = {"wall_s": min(r[0][key] for r in runs)}
    out["perceive"] = {"wall_s": min(sum(r[0].values()) for r in runs), "cpu_s": min(r[1] for r in runs)}
    weldmap = cap.weldmap.transformed(invert(s.X_WR) @ s.X_WM, "R")
    alignment, wall, cpu = _fastest(lambda: align_map(weldmap, per.registered, s.perception), repeat)
    out["align_map"] = {"wall_s": wall, "cpu_s": cpu}
    aligned = cap.weldmap.transformed(alignment.X_RR_corr @ invert(s.X_WR) @ s.X_WM, "R")
    checks = {
        "check_unique": lambda: check_alignment_unique(aligned, per.registered, alignment, s.perception.symmetry),
        "check_parts_seen": lambda: check_parts_seen(aligned, per.registered, s.perception, s.perception.coverage),
        "check_alignment": lambda: check_alignment(aligned, per.registered, alignment, s.perception),
    }
    for key, check in checks.items():
        _, wall, cpu = _fastest(check, repeat)
        out[key] = {"wall_s": wall, "cpu_s": cpu}
    out["points"] = {"registered": len(per.registered), "dense": len(per.dense), "voxel": len(per.downsampled)}
    return out


def planning(
    station: Station, cap: pipeline.Capture, scene: pipeline.Scene, estimates: tuple[SeamEstimate, ...]
) -> Any:
    """Plan and gate the found seams of ``estimates`` (ours) as ``cell weld`` does: counts and CPU / wall [s]
    (module docstring); None when the station has no arm."""
    if station.arm is None:
        return None
    s = cap.scenario
    truth = pipeline.truths(cap, scene.seam_scene.weldmap)
    metrics, summary = pipeline.evaluate(estimates, truth)
    det = pipeline.Detection(
        s, "ours", scene.seam_scene.weldmap, estimates, truth, metrics, summary, scene=scene, joints=cap.joints
    )
    t, c = time.perf_counter(), time.process_time()
    plan, _, problems = plan_for(station, det, motion=motion_scene(station.arm, det))
    cpu, wall = time.process_time() - c, time.perf_counter() - t
    planned = sum(1 for o in plan.seams if o.feasible)
    asked = len(plan.seams)
    return {
        "seams_asked": asked,
        "seams_planned": planned,
        "refused_by_code": dict(sorted(collections.Counter(str(o.code) for o in plan.seams if not o.feasible).items())),
        "gate_problems": len(problems),
        "cpu_s": cpu,
        "wall_s": wall,
        "cpu_s_per_planned_seam": cpu / max(planned, 1),
        "wall_s_per_planned_seam": wall / max(planned, 1),
        "cpu_s_per_seam_asked": cpu / max(asked, 1),
    }


def bench(name: str, methods: list[str], noise: str, repeat: int) -> dict[str, Any]:
    """One row: the scenario's size, its stage times [s], per method ms per seam and accuracy, and planning."""
    s = sc.load(name).with_noise("none" if noise == "none" else "realistic")
    weldmap = read_weldmap(s)
    with open_cell(s, weldmap) as station:
        return _bench(name, station, s, weldmap, methods, repeat)


def _bench(
    name: str, station: Station, s: Scenario, weldmap: WeldMap, methods: list[str], repeat: int
) -> dict[str, Any]:
    """:func:`bench` on a running station built around ``weldmap``."""
    cap = pipeline.capture(s, station=station, weldmap=weldmap)
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
    row["perception"] = perception_stages(cap, repeat)
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
    walls: dict[str, list[float]] = {method: [] for method in methods}
    for _ in range(max(1, repeat)):
        for method in methods:  # taking turns, each from a cold cache, as in cell bench
            scene.seam_scene.cache.clear()
            t = time.perf_counter()
            all_runs[method].append(pipeline.locate(scene, s, method))
            walls[method].append(time.perf_counter() - t)
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
            "locate_wall_s": min(walls[method]),
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
    if "ours" in row["methods"]:
        # The first run of pipeline.locate as cell detect runs it: the locator and the screen after it.
        first = walls["ours"][0]
        row["detect_vs_capture"] = {
            "capture_s": row["capture_s"],
            "perceive_align_locate_s": row["perceive_s"] + row["align_s"] + first,
            "locate_wall_s": first,
        }
        row["planning"] = planning(station, cap, scene, all_runs["ours"][0])
    row["load_average_1_5_15"] = [round(x, 2) for x in os.getloadavg()]
    return row


def perception_table(rows: list[dict[str, Any]]) -> str:
    """Markdown: per scenario, each perception stage's fastest wall (and CPU) time [ms]."""
    keys = (
        "clouds",
        "splice",
        "preprocess",
        "downsample",
        "perceive",
        "align_map",
        "check_unique",
        "check_parts_seen",
        "check_alignment",
    )
    head = "| scenario | open3d import | " + " | ".join(keys) + " |\n|---|---|" + "---|" * len(keys) + "\n"
    lines = []
    for r in rows:
        p = r["perception"]
        cells = []
        for k in keys:
            v = p.get(k, {})
            cpu = f" ({v['cpu_s'] * 1000:.0f})" if "cpu_s" in v else ""
            cells.append(f"{v.get('wall_s', float('nan')) * 1000:.0f}{cpu}")
        lines.append(f"| {r['scenario']} | {p['open3d_import_s'] * 1000:.0f} | " + " | ".join(cells) + " |")
    return head + "\n".join(lines) + "\n"


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
    print("perception per stage, fastest wall ms (CPU ms):")
    print(perception_table(rows))
    for r in rows:
        if "detect_vs_capture" in r:
            d = r["detect_vs_capture"]
            print(
                f"{r['scenario']}: perceive + align + locate (ours) {d['perceive_align_locate_s']:.2f} s "
                f"against capture {d['capture_s']:.2f} s"
            )
    for r in rows:
        p = r.get("planning")
        if p:
            print(
                f"{r['scenario']}: planned {p['seams_planned']}/{p['seams_asked']} found seams, planning CPU "
                f"{p['cpu_s']:.2f} s (wall {p['wall_s']:.2f} s), {p['cpu_s_per_planned_seam']:.3f} s CPU per planned "
                f"seam; refused {p['refused_by_code']}"
            )
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
