"""The cell's own commands as benchmarks: what the welding, re-scan and fault tables of docs/results.md show.

    .venv/bin/python benchmarks/bench_cell.py weld [--scenarios fence1] [--json PATH]
    .venv/bin/python benchmarks/bench_cell.py rescan [--scenarios fence1-exact,fence1,fence2,faults/extrinsics-off]
        [--json PATH]
    .venv/bin/python benchmarks/bench_cell.py faults [--scenarios faults/NAME,...] [--json PATH]

``weld`` runs what ``cell weld SCENARIO`` runs, the whole part (:func:`cell.pipeline.turnover.weld_part`: side A, the
turn, side B; its report :func:`cell.export.reports.turnover_report.turnover_report`) and keeps per seam its side, the
located error, welded or why not, the executed TCP against the true seam, the travel speed and the weld time; per run
the cycle, arc and re-scan robot times, the job time, the turn and what side B's alignment measured, and the wall time
of each stage (default ``benchmarks/results/weld.json``). ``faults`` welds side A only (``cell weld --sides first``): a
fault's table is about what the fault does to the part as it lies. ``rescan`` runs what
``cell rescan SCENARIO --all`` runs (detect, :func:`cell.pipeline.rescan_detection` on every visible seam, its report
:func:`cell.export.reports.report.rescan_report`): the mean lateral and end point error before and after, the robot time
(``rescan.json``). ``faults`` runs ``cell weld`` on every scenario of ``scenarios/faults/`` and keeps what the
fault table of docs/results.md quotes: welded count, the worst executed TCP error, the exit code the CLI gives, the lost
cameras with their reason, the seams re-scanned (and whether a close-up escalated to every seam), the seams not
found or occluded with their reasons, and the error of a refusal (``faults.json``). Every figure is taken from
the command's own JSON report, so these rows and ``cell ... --json`` agree. Headless; one run per scenario.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections import Counter
from collections.abc import Callable
from pathlib import Path
from typing import Any

from cell import pipeline
from cell import scenario as sc
from cell.errors import EXIT_OK, EXIT_PARTIAL, CellError
from cell.export.reports.report import rescan_report, weld_report, write_json
from cell.pipeline.geometry import open_cell

RESULTS = Path(__file__).resolve().parent / "results"
RESCAN_SCENARIOS = ("fence1-exact", "fence1", "fence2", "faults/extrinsics-off")

Row = dict[str, Any]


def _say(msg: str) -> None:
    print(f"· {msg}", file=sys.stderr, flush=True)


def fault_scenarios() -> list[str]:
    """Every scenario of ``scenarios/faults/``, by name (``faults/NAME``), sorted."""
    return sorted(f"faults/{p.stem}" for p in (sc.REPO_ROOT / "scenarios" / "faults").glob("*.yaml"))


def exit_code(run: pipeline.WeldRun) -> int:
    """The exit code ``cell weld`` gives for a run it finished (cell/cli/act.py): partial unless complete."""
    return EXIT_PARTIAL if run.error is not None or not run.complete else EXIT_OK


def _seam_row(s: Row) -> Row:
    """One seam of a weld report: located error [mm], welded or why not, executed TCP error [mm], speed, time."""
    e, tcp = s.get("error_mm", {}), s.get("tcp_error_mm", {})
    return {
        "id": s["id"],
        "status": s["status"],
        "reason_code": s["reason_code"],
        "paper_me_mm": e.get("paper_me"),
        "lateral_mm": e.get("lateral"),
        "endpoint_mm": e.get("endpoint"),
        "confidence": s.get("confidence"),
        "welded": s["welded"],
        "weld_reason": s.get("weld_reason"),
        "weld_reason_code": s.get("weld_reason_code"),
        "tcp_rms_mm": tcp.get("rms"),
        "tcp_max_mm": tcp.get("max"),
        # the weld measured whole: the most of the joint left unwelded or overrun at either end
        "ends_mm": max(
            (tcp[k] for k in ("short_start", "short_end", "past_start", "past_end") if k in tcp), default=None
        ),
        "travel_speed_mm_s": s.get("travel_speed_mm_s"),
        "weld_time_s": s.get("weld_time_s"),
    }


def weld_row(name: str) -> Row:
    """``cell weld NAME --sides first``: the run's figures from its report (see the module docstring)."""
    _say(f"cell weld {name} --sides first")
    try:
        run = pipeline.weld(sc.load(name))
    except CellError as e:  # the CLI prints the message and exits with the error's code; no report
        return {"scenario": name, "exit_code": e.exit_code, "error": {"type": type(e).__name__, "message": e.message}}
    return report_row(weld_report(run), exit_code(run))


def part_row(name: str) -> Row:
    """``cell weld NAME`` (both sides): the whole part's figures from its report, with the turn's."""
    from cell.export.reports.turnover_report import turnover_report
    from cell.pipeline.turnover import weld_part

    _say(f"cell weld {name}")
    t = time.perf_counter()
    try:
        run = weld_part(sc.load(name))
    except CellError as e:
        return {"scenario": name, "exit_code": e.exit_code, "error": {"type": type(e).__name__, "message": e.message}}
    wall_s = time.perf_counter() - t
    rep = turnover_report(run)
    row = report_row(rep, EXIT_OK if run.complete else EXIT_PARTIAL)
    for seam, entry in zip(row["seams"], rep["seams"], strict=True):
        seam["side"] = entry.get("side", "A")
    flip = rep.get("flip") or {}
    keep = ("axis", "rotation_deg", "tilt_deg", "placement_error_mm", "placement_rotation_deg", "fitness", "operator_s")
    row["flip"] = {k: flip.get(k) for k in keep} if flip else None
    row["job_time_s"] = rep.get("job_time_s")
    row["sides"] = {
        k: {"welded": v["welded"], "seams": v["seams"], "cycle_time_s": v["cycle_time_s"], "timings_s": v["timings_s"]}
        for k, v in rep.get("sides", {}).items()
    }
    row["wall_s"] = wall_s
    return row


def report_row(rep: Row, code: int) -> Row:
    """The row of one ``cell weld`` report ``rep`` (its JSON as a dict) whose command exited with ``code``."""
    seams = [_seam_row(s) for s in rep["seams"]]
    rescan = rep["rescan"]
    tcp_max = [s["tcp_max_mm"] for s in seams if s["welded"] and s["tcp_max_mm"] is not None]
    ends = [s["ends_mm"] for s in seams if s["welded"] and s["ends_mm"] is not None]
    return {
        "scenario": rep["scenario"],
        "method": rep["method"],
        "noise": rep["noise"],
        "exit_code": code,
        "seams_in_map": rep["summary"]["seams"],
        "visible": rep["summary"]["visible"],
        "found": rep["summary"]["found"],
        "lateral_mean_mm": rep["summary"].get("lateral_mean_mm"),
        "endpoint_mean_mm": rep["summary"].get("endpoint_mean_mm"),
        "ms_per_seam_median": rep["summary"].get("time_ms_per_seam_median"),
        "welded": rep["welded"],
        "status_counts": dict(Counter(s["status"] for s in seams)),
        "weld_reason_counts": dict(Counter(s["weld_reason_code"] for s in seams if not s["welded"])),
        "tcp_max_mm": max(tcp_max) if tcp_max else None,
        "ends_max_mm": max(ends) if ends else None,
        "cycle_time_s": rep["cycle_time_s"],
        "arc_time_s": rep["arc_time_s"],
        "rescan": rescan,
        "lost_cameras": rep["lost_cameras"],
        "not_found_reasons": sorted({s["reason"] for s in rep["seams"] if s["status"] == "not_found"}),
        "occluded_reasons": sorted({s["reason"] for s in rep["seams"] if s["status"] == "occluded"}),
        "error": rep["error"],
        "timings_s": rep["timings_s"],
        "seams": seams,
    }


def fault_row(name: str) -> Row:
    """``cell weld faults/NAME``: the weld row without the per-seam rows (the fault table shows none)."""
    row = weld_row(name)
    row.pop("seams", None)
    return row


def rescan_row(name: str) -> Row:
    """``cell rescan NAME --all``: mean errors before and after [mm], seams re-scanned and used, robot time [s]."""
    _say(f"cell rescan {name} --all")
    scn = sc.load(name)
    weldmap = pipeline.read_weldmap(scn)
    with open_cell(scn, weldmap) as station:
        det = pipeline.detect(scn, None, station=station, weldmap=weldmap)
        if det.error is not None:
            raise det.error
        rs, after = pipeline.rescan_detection(station, det, "all")
    return rescan_report_row(rescan_report(det, after, rs))


def rescan_report_row(rep: Row) -> Row:
    """The row of one ``cell rescan`` report ``rep`` (its JSON as a dict)."""
    b, a = rep["summary_before_rescan"], rep["summary"]
    return {
        "scenario": rep["scenario"],
        "method": rep["method"],
        "noise": rep["noise"],
        "seams": rep["rescan"]["seams"],
        "used": rep["rescan"]["used"],
        "lateral_mean_mm_before": b["lateral_mean_mm"],
        "lateral_mean_mm_after": a["lateral_mean_mm"],
        "endpoint_mean_mm_before": b["endpoint_mean_mm"],
        "endpoint_mean_mm_after": a["endpoint_mean_mm"],
        "motion_s": rep["rescan"]["motion_s"],
        "returned_to_scan_pose": rep["rescan"]["returned_to_scan_pose"],
        "rescan_s": rep["timings_s"].get("rescan_s"),
    }


PARTS: dict[str, tuple[Callable[[str], Row], Callable[[], list[str]], str]] = {
    "weld": (part_row, lambda: ["fence1"], "weld.json"),
    "rescan": (rescan_row, lambda: list(RESCAN_SCENARIOS), "rescan.json"),
    "faults": (fault_row, fault_scenarios, "faults.json"),
}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("part", choices=tuple(PARTS), help="which table's runs")
    ap.add_argument("--scenarios", default=None, help="comma-separated scenario names (default: the table's)")
    ap.add_argument("--json", type=Path, default=None, help="write the rows here (default: benchmarks/results/)")
    args = ap.parse_args(argv)
    make, default, filename = PARTS[args.part]
    names = [n.strip() for n in args.scenarios.split(",") if n.strip()] if args.scenarios else default()
    rows = [make(n) for n in names]
    for r in rows:
        keys = ("scenario", "exit_code", "welded", "visible", "used", "motion_s", "tcp_max_mm", "cycle_time_s")
        brief = {k: r.get(k) for k in keys}
        print(" ".join(f"{k}={v}" for k, v in brief.items() if v is not None))
    print(f"wrote {write_json(args.json or RESULTS / filename, rows)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
