"""``cell calibrate`` against the simulator's truth over seeds: each camera's pose error after the joint refinement and
with OpenCV's hand-eye methods alone (Park, Tsai, Daniilidis) on the same images, and how often the stated 2-sigma
bounds cover the error.

    .venv/bin/python benchmarks/bench_calibration.py --seeds 10 [--scenario fence1] [--json PATH]
    .venv/bin/python benchmarks/bench_calibration.py --loop [--json PATH]

``--loop`` closes the loop instead: ``cell calibrate faults/extrinsics-off``, then ``cell weld`` of that scenario with
the file, beside ``cell weld fence1`` (the same cell, its cameras where the scenario says) and ``cell weld
faults/extrinsics-off`` told the wrong poses; each of the two told poses also with the splice's prior off (their
stated residual 0: the file's ``calibration:`` block, the scenario's ``cameras.<name>.calibration``); per run the
seams welded and the worst located, executed and end errors (default ``benchmarks/results/calibration_loop.json``).

Each seed is the scenario with that seed (realistic colour and depth noise, the robot's repeatability of
``calibration.repeatability_mm`` on every flange pose, the board's mount drawn anew): every camera calibrated with
the scenario's ``calibration`` settings. Rows per seed and camera; the summary per group (fixed cameras, the arm's
camera) and method: median and worst translation [mm] and rotation [deg] error, and for the refinement the share of
errors within their stated 2 sigma. Written to ``--json`` (default ``benchmarks/results/calibration.json``).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from cell import scenario as sc
from cell.pipeline.calibration import OPENCV_METHODS, calibrate

RESULTS = Path(__file__).resolve().parent / "results"
_ZERO = {"translation_mm": 0.0, "rotation_deg": 0.0}
CELL = Path(__file__).resolve().parents[1] / ".venv" / "bin" / "cell"


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


def _weld(scenario: str, report: Path, *extra: str) -> dict[str, Any]:
    """``cell weld SCENARIO --json`` run as a user runs it, and the figures of its report."""
    subprocess.run([str(CELL), "-q", "weld", scenario, "--json", str(report), *extra], check=False)
    rep = json.loads(report.read_text(encoding="utf-8"))
    seams = rep["seams"]
    welded = [s for s in seams if s.get("welded")]
    ends = ("short_start", "short_end", "past_start", "past_end")
    reasons: dict[str, int] = {}
    for s in seams:
        if not s.get("welded"):
            reasons[str(s.get("weld_reason_code"))] = reasons.get(str(s.get("weld_reason_code")), 0) + 1
    located = [s["error_mm"]["paper_me"] for s in seams if s.get("error_mm")]
    name = Path(scenario).name if scenario.endswith(".yaml") else scenario
    return {
        "command": " ".join(["cell", "weld", name, *(Path(e).name if e.endswith(".yaml") else e for e in extra)]),
        "seams": len(seams),
        "welded": len(welded),
        "not_welded": reasons,
        "paper_me_mean_mm": float(np.mean(located)) if located else None,
        "paper_me_max_mm": float(np.max(located)) if located else None,
        "tcp_max_mm": max((s["tcp_error_mm"]["max"] for s in welded), default=None),
        "ends_max_mm": max((max(s["tcp_error_mm"][k] for k in ends) for s in welded), default=None),
    }


def loop(json_path: Path) -> None:
    """The loop closed (see the module docstring)."""
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        cal = folder / "cal.yaml"
        subprocess.run([str(CELL), "-q", "calibrate", "faults/extrinsics-off", "--out", str(cal)], check=True)
        calibration = yaml.safe_load(cal.read_text(encoding="utf-8"))
        # The splice's prior off: the same poses told, their stated residual 0 (the splice never moves a camera and
        # a seam seen by one camera carries no calibration term): the file's block, and the scenario's.
        cal0, off0 = folder / "cal_no_prior.yaml", folder / "extrinsics-off-no-prior.yaml"
        bare = {**calibration, "cameras": {n: {**c, "calibration": _ZERO} for n, c in calibration["cameras"].items()}}
        cal0.write_text(yaml.safe_dump(bare, sort_keys=False), encoding="utf-8")
        scenario = yaml.safe_load(sc.resolve("faults/extrinsics-off").read_text(encoding="utf-8"))
        for cam in scenario["cameras"].values():
            cam.pop("calibration", None)
        scenario["name"] = "faults/extrinsics-off-no-prior"
        off0.write_text(yaml.safe_dump(scenario, sort_keys=False), encoding="utf-8")  # the map found by its name
        runs = {
            "exact": _weld("fence1", folder / "exact.json"),
            "told_wrong": _weld("faults/extrinsics-off", folder / "off.json"),
            "told_wrong_no_prior": _weld(str(off0), folder / "off0.json"),
            "calibrated": _weld("faults/extrinsics-off", folder / "cal.json", "--calibration", str(cal)),
            "calibrated_no_prior": _weld("faults/extrinsics-off", folder / "cal0.json", "--calibration", str(cal0)),
        }
    doc = {
        "command": ".venv/bin/python benchmarks/bench_calibration.py --loop",
        "calibration": {
            n: {"calibration": c["calibration"], "truth_error": c["truth_error"]}
            for n, c in calibration["cameras"].items()
        },
        "runs": runs,
    }
    json_path.write_text(json.dumps(doc, indent=1) + "\n", encoding="utf-8")
    print(json.dumps(doc, indent=1))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seeds", type=int, default=10, help="seeds 0..N-1")
    ap.add_argument("--scenario", default="fence1")
    ap.add_argument("--loop", action="store_true", help="calibrate faults/extrinsics-off, then weld with it")
    ap.add_argument("--json", type=Path, default=None)
    args = ap.parse_args()
    if args.loop:
        loop(args.json or RESULTS / "calibration_loop.json")
        return
    args.json = args.json or RESULTS / "calibration.json"
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
