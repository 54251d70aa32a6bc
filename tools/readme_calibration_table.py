"""The table of ``cell calibrate`` against the simulator's truth (``benchmarks/results/calibration.json``, written by
``benchmarks/bench_calibration.py``), for docs/results.md."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

METHODS = {
    "refined": "joint refinement (ours)",
    "park": "OpenCV Park alone",
    "tsai": "OpenCV Tsai alone",
    "daniilidis": "OpenCV Daniilidis alone",
}
GROUPS = {"fixed": "fixed cameras (board on the flange)", "arm": "arm camera (board on the table)"}


def calibration_table(data: Mapping[str, Any]) -> str:
    """One row per camera group and method: median and worst errors, and the 2-sigma coverage of the refinement."""
    lines = [
        f"`{data['command']}`",
        "",
        "| cameras | method | n | translation median / worst mm | rotation median / worst deg | within 2 sigma |",
        "|---|---|---|---|---|---|",
    ]
    for s in data["summary"]:
        cover = s.get("within_2_sigma")
        lines.append(
            f"| {GROUPS[s['group']]} | {METHODS[s['method']]} | {s['n']} "
            f"| {s['translation_mm_median']:.3f} / {s['translation_mm_worst']:.3f} "
            f"| {s['rotation_deg_median']:.4f} / {s['rotation_deg_worst']:.4f} "
            f"| {'' if cover is None else f'{100.0 * cover:.0f} %'} |"
        )
    return "\n".join(lines) + "\n"


LOOP_RUNS = {
    "exact": "fence1: the cameras where the scenario says",
    "told_wrong": "faults/extrinsics-off: told poses 1 mm / 0.1 deg off (stated: the splice's prior)",
    "told_wrong_no_prior": "the same, the residual not stated (no prior: the splice never moves a camera)",
    "calibrated": "faults/extrinsics-off with cell calibrate's file (its `calibration:` block the prior)",
    "calibrated_no_prior": "the same file, its `calibration:` block zeroed (no prior)",
}


def _mm(v: float | None) -> str:
    return "-" if v is None else f"{v:.3f}"


def loop_table(data: Mapping[str, Any]) -> str:
    """The loop closed: the same cell welded as told exactly, told wrong, and told what cell calibrate measured."""
    lines = [
        f"`{data['command']}`",
        "",
        "| run | welded | not welded | located ME mean / max mm | executed TCP max mm | worst end mm |",
        "|---|---|---|---|---|---|",
    ]
    for key, label in LOOP_RUNS.items():
        if key not in data["runs"]:
            continue
        r = data["runs"][key]
        why = ", ".join(f"{k}: {n}" for k, n in sorted(r["not_welded"].items())) or "-"
        lines.append(
            f"| {label} | {r['welded']}/{r['seams']} | {why} | {_mm(r['paper_me_mean_mm'])} / "
            f"{_mm(r['paper_me_max_mm'])} | {_mm(r['tcp_max_mm'])} | {_mm(r['ends_max_mm'])} |"
        )
    return "\n".join(lines) + "\n"
