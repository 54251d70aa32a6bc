"""``cell calibrate`` against the simulator's truth over seeds: each camera's pose error after the joint refinement and
with OpenCV's hand-eye methods alone (Park, Tsai, Daniilidis) on the same images, and how often the stated 2-sigma
bounds cover the error.

    .venv/bin/python benchmarks/bench_calibration.py --seeds 10 [--scenario fence1] [--json PATH]

Each seed is the scenario with that seed (realistic colour and depth noise, the robot's repeatability of
``calibration.repeatability_mm`` on every flange pose, the board's mount drawn anew): every camera calibrated with
the scenario's ``calibration`` settings. Rows per seed and camera; the summary per group (fixed cameras, the arm's
camera) and method: median and worst translation [mm] and rotation [deg] error, and for the refinement the share of
errors within their stated 2 sigma. Written to ``--json`` (default ``benchmarks/results/calibration.json``).
"""

from __future__ import annotations

import argparse
import json
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from cell import scenario as sc
from cell.pipeline.calibration import OPENCV_METHODS, calibrate

RESULTS = Path(__file__).resolve().parent / "results"


def rows_of(name: str, seeds: Sequence[int]) -> list[dict[str, Any]]:
    """One row per seed and camera: the truth errors of every method, the stated sigmas, the held-out residuals."""
    rows = []
    for seed in seeds:
        scn = sc.load(name).with_noise("realistic").model_copy(update={"seed": seed})
        t0 = time.perf_counter()
        run = calibrate(scn)
        seconds = time.perf_counter() - t0
        for cal in run.cameras:
            err = cal.truth_error()
            assert err is not None
            s = cal.solution
            methods = {"refined": err} | {m: cal.truth_error(X) for m, X in cal.opencv.items()}
            rows.append(
                {
                    "seed": seed,
                    "camera": cal.camera,
                    "group": "fixed" if cal.frame == "robot_base" else "arm",
                    "poses": cal.poses,
                    "errors": {
                        m: {"translation_mm": e[0] * 1e3, "rotation_deg": float(np.degrees(e[1]))}
                        for m, e in methods.items()
                        if e is not None
                    },
                    "sigma_translation_mm": s.sigma_translation_m * 1e3,
                    "sigma_rotation_deg": float(np.degrees(s.sigma_rotation_rad)),
                    "within_2_sigma": cal.within_two_sigma(),
                    "reprojection_px": s.rms_px,
                    "held_out_px": cal.held_out_px,
                    "held_out_3d_mm": cal.held_out_3d_m * 1e3,
                    "depth_scale": cal.intrinsics.depth_scale,
                    "fx_px": cal.intrinsics.fx,
                    "seconds_per_run": seconds,
                }
            )
            print(
                f"seed {seed} {cal.camera}: {err[0] * 1e3:.3f} mm / {np.degrees(err[1]):.4f} deg "
                f"(2 sigma {2e3 * s.sigma_translation_m:.3f} mm / {2 * np.degrees(s.sigma_rotation_rad):.4f} deg)",
                flush=True,
            )
    return rows


def summary(rows: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
    """Per group and method: median and worst errors; for the refinement, the 2-sigma coverage."""
    out = []
    for group in ("fixed", "arm"):
        mine = [r for r in rows if r["group"] == group]
        if not mine:
            continue
        for method in ("refined", *OPENCV_METHODS):
            t = np.array([r["errors"][method]["translation_mm"] for r in mine if method in r["errors"]])
            a = np.array([r["errors"][method]["rotation_deg"] for r in mine if method in r["errors"]])
            row: dict[str, Any] = {
                "group": group,
                "method": method,
                "n": len(t),
                "translation_mm_median": float(np.median(t)),
                "translation_mm_worst": float(np.max(t)),
                "rotation_deg_median": float(np.median(a)),
                "rotation_deg_worst": float(np.max(a)),
            }
            if method == "refined":
                row["within_2_sigma"] = float(np.mean([bool(r["within_2_sigma"]) for r in mine]))
            out.append(row)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seeds", type=int, default=10, help="seeds 0..N-1")
    ap.add_argument("--scenario", default="fence1")
    ap.add_argument("--json", type=Path, default=RESULTS / "calibration.json")
    args = ap.parse_args()
    rows = rows_of(args.scenario, range(args.seeds))
    doc = {
        "command": f".venv/bin/python benchmarks/bench_calibration.py --seeds {args.seeds} --scenario {args.scenario}",
        "scenario": args.scenario,
        "summary": summary(rows),
        "rows": rows,
    }
    args.json.write_text(json.dumps(doc, indent=1) + "\n", encoding="utf-8")
    for s in doc["summary"]:
        print(json.dumps(s))


if __name__ == "__main__":
    main()
