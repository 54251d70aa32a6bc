"""Coverage of the seams' end sigmas: how often each located end lies within 2 of its sigmas of the true end, along
the seam.

    .venv/bin/python benchmarks/bench_ends.py [--scenarios fence1,fence2,brace,bracket,rhs] [--faults ...]
        [--methods ours] [--json PATH] [--compare OLD.json]

Each scenario (and each fault scenario, ``scenarios/faults/``) is captured once (seed 0, realistic noise),
perceived once and located with each method. Per found seam: each end's signed error along the true seam [mm]
(positive past the true end, :func:`cell.seams.metrics.end_errors_along`), its end sigma and where the end came
from (``SeamEstimate.end_sigma_m``, ``end_source``), the lateral error and sigma, and the located ends (R, mm).
Per method and group: the share of ends within 1, 2 and 3 end sigmas, the share of seams within 2 sigma across, and
the largest end error in sigmas. ``--compare`` reads an earlier run's JSON and reports how far each seam's located
line moved across itself (the distance of the new ends from the old line) and along it. The figures and the rows go
to ``--json`` (default ``benchmarks/results/ends.json``).
"""

from __future__ import annotations

import argparse
import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from bench_coverage import FAULTS  # the same fault scenarios as the sigma across the seam is measured on

from cell import pipeline
from cell import scenario as sc
from cell.errors import CellError
from cell.export.reports.report import write_json
from cell.geometry import point_line_distance
from cell.seams.metrics import end_errors_along

RESULTS = Path(__file__).resolve().parent / "results"
SCENARIOS = ("fence1", "fence2", "brace", "bracket", "rhs")


def rows_of(names: Sequence[str], group: str, methods: Sequence[str]) -> list[dict[str, Any]]:
    """One row per found seam and method (see the module docstring)."""
    rows = []
    for name in names:
        s = sc.load(name).with_noise("realistic").model_copy(update={"seed": 0})
        try:
            cap = pipeline.capture(s)
            scene = pipeline.build_scene(cap)
        except CellError:  # no camera left, the map not aligned: no seam to cover
            continue
        truth = pipeline.truths(cap, scene.seam_scene.weldmap)
        for method in methods:
            scene.seam_scene.cache.clear()
            for e in pipeline.locate(scene, s, method):
                if e.status.value != "found" or e.id not in truth:
                    continue
                t0, t1 = truth[e.id]
                along = end_errors_along(e.p_start, e.p_end, t0, t1)
                lateral = float(np.max(point_line_distance(np.stack([e.p_start, e.p_end]), t0, t1))) * 1000.0
                # The sigmas in the true seam's order (a reversed estimate's ends swapped).
                swapped = np.linalg.norm(e.p_start - t1) + np.linalg.norm(e.p_end - t0) < np.linalg.norm(
                    e.p_start - t0
                ) + np.linalg.norm(e.p_end - t1)
                sig = [x * 1000.0 for x in getattr(e, "end_sigma_m", (e.sigma_m, e.sigma_m))]
                src = [str(x) for x in getattr(e, "end_source", ("", ""))]
                if swapped:
                    sig, src = sig[::-1], src[::-1]
                rows.append(
                    {
                        "group": group,
                        "scenario": name,
                        "method": method,
                        "seam": e.id,
                        "sigma_mm": e.sigma_m * 1000.0,
                        "lateral_mm": lateral,
                        "end_along_mm": list(along),
                        "end_sigma_mm": sig,
                        "end_source": src,
                        "p_start_mm": (e.p_start * 1000.0).tolist(),
                        "p_end_mm": (e.p_end * 1000.0).tolist(),
                        "reason": e.reason,
                    }
                )
    return rows


def coverage(rows: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
    """Per method and group (and all groups): seams found, the shares of ends within 1, 2, 3 end sigmas, the
    share within 2 sigma across, the median end sigma [mm] and the largest end error [mm] and in sigmas."""
    out = []
    present = {r["group"] for r in rows}
    groups = [*(g for g in ("scenarios", "faults") if g in present), "all"]
    for method in sorted({r["method"] for r in rows}):
        for group in groups:
            sel = [r for r in rows if r["method"] == method and (group == "all" or r["group"] == group)]
            if not sel:
                continue
            err = np.abs(np.array([r["end_along_mm"] for r in sel], float)).ravel()
            sig = np.array([r["end_sigma_mm"] for r in sel], float).ravel()
            z = err / np.where(sig > 0.0, sig, 1e-12)
            lat = np.array([r["lateral_mm"] <= 2.0 * r["sigma_mm"] for r in sel])
            out.append(
                {
                    "method": method,
                    "group": group,
                    "found": len(sel),
                    "ends_1sigma": float(np.mean(z <= 1.0)),
                    "ends_2sigma": float(np.mean(z <= 2.0)),
                    "ends_3sigma": float(np.mean(z <= 3.0)),
                    "across_2sigma": float(np.mean(lat)),
                    "end_sigma_median_mm": float(np.median(sig)),
                    "end_error_max_mm": float(err.max()),
                    "end_error_max_sigmas": float(z.max()),
                }
            )
    return out


def by_source(rows: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
    """Per method and end source: ends, share within 2 end sigmas, the 95th percentile of |error| [mm], median sigma."""
    out = []
    for method in sorted({r["method"] for r in rows}):
        ends = [
            (src, abs(e), s)
            for r in rows
            if r["method"] == method
            for src, e, s in zip(r["end_source"], r["end_along_mm"], r["end_sigma_mm"], strict=True)
        ]
        for source in sorted({x[0] for x in ends}):
            sel = np.array([(e, s) for src, e, s in ends if src == source], float)
            out.append(
                {
                    "method": method,
                    "source": source,
                    "ends": len(sel),
                    "within_2sigma": float(np.mean(sel[:, 0] <= 2.0 * sel[:, 1])),
                    "error_p95_mm": float(np.percentile(sel[:, 0], 95)),
                    "error_max_mm": float(sel[:, 0].max()),
                    "sigma_median_mm": float(np.median(sel[:, 1])),
                }
            )
    return out


def compare(rows: Sequence[dict[str, Any]], old: Sequence[dict[str, Any]]) -> dict[str, float]:
    """How far the located seams moved from an earlier run's: the largest distance [mm] of a new end from the old
    line (across the seam) and of a new end from the old end along it, over the seams found in both."""
    before = {(r["scenario"], r["method"], r["seam"]): r for r in old}
    across, along, n = 0.0, 0.0, 0
    for r in rows:
        o = before.get((r["scenario"], r["method"], r["seam"]))
        if o is None:
            continue
        n += 1
        a, b = np.array(o["p_start_mm"]), np.array(o["p_end_mm"])
        new = np.array([r["p_start_mm"], r["p_end_mm"]])
        across = max(across, float(np.max(point_line_distance(new, a, b))))
        along = max(along, float(np.max(np.linalg.norm(new - np.stack([a, b]), axis=1))))
    return {"seams_in_both": n, "across_max_mm": across, "ends_moved_max_mm": along}


def summary(table: Sequence[dict[str, Any]]) -> str:
    """The coverage table of :func:`coverage`, as Markdown."""
    lines = [
        "| method | seams | found | ends within 1 / 2 / 3 end sigmas | across within 2 sigma | median end sigma [mm] "
        "| max end error [mm] (sigmas) |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in table:
        lines.append(
            f"| {r['method']} | {r['group']} | {r['found']} | {r['ends_1sigma']:.0%} / {r['ends_2sigma']:.0%} / "
            f"{r['ends_3sigma']:.0%} | {r['across_2sigma']:.0%} | {r['end_sigma_median_mm']:.3f} "
            f"| {r['end_error_max_mm']:.2f} ({r['end_error_max_sigmas']:.1f}) |"
        )
    return "\n".join(lines) + "\n"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenarios", default=",".join(SCENARIOS), help="comma-separated scenario names")
    ap.add_argument("--faults", default=",".join(FAULTS), help="comma-separated fault scenarios")
    ap.add_argument("--methods", default="ours", help="comma-separated locators")
    ap.add_argument("--json", type=Path, default=RESULTS / "ends.json", help="write the figures as JSON here")
    ap.add_argument("--compare", type=Path, default=None, help="an earlier run's JSON: how far the seams moved")
    args = ap.parse_args()
    methods = [m.strip() for m in args.methods.split(",") if m.strip()]
    names = [n.strip() for n in args.scenarios.split(",") if n.strip()]
    faults = [n.strip() for n in args.faults.split(",") if n.strip()]
    rows = rows_of(names, "scenarios", methods) + rows_of(faults, "faults", methods)
    table = coverage(rows)
    print(summary(table))
    sources = by_source(rows)
    for s in sources:
        print(s)
    data: dict[str, Any] = {"scenarios": names, "faults": faults, "coverage": table, "by_source": sources}
    if args.compare is not None:
        data["compare"] = compare(rows, json.loads(args.compare.read_text())["rows"])
        print(data["compare"])
    write_json(args.json, {**data, "rows": rows})


if __name__ == "__main__":
    main()
