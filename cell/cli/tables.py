"""The tables and summary lines the commands print (from the JSON reports, so screen and file agree)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from rich.table import Table

from cell.cli.common import out

if TYPE_CHECKING:
    from cell.pipeline import Detection


def print_rescan(rep: dict) -> None:
    t = Table(title=f"re-scan {rep['scenario']} · method {rep['method']} · frame R", title_justify="left")
    for col in ("seam", "lateral before", "lateral after", "endpoint before", "endpoint after", "weight", "why not"):
        t.add_column(col, justify="left" if col in ("seam", "why not") else "right")
    for s in rep["seams"]:
        b, a = s.get("error_mm_before", {}), s.get("error_mm", {})
        t.add_row(
            s["id"],
            _fmt(b.get("lateral")),
            _fmt(a.get("lateral")),
            _fmt(b.get("endpoint")),
            _fmt(a.get("endpoint")),
            _fmt(s["rescan"]["weight"]),
            s["rescan"]["reason"],
        )
    out.print(t)
    b, a = rep["summary_before_rescan"], rep["summary"]
    out.print(
        f"{rep['rescan']['seams']} seams re-scanned ({rep['rescan']['used']} used) · mean lateral"
        f" {_fmt(b['lateral_mean_mm'], 3)} -> {_fmt(a['lateral_mean_mm'], 3)} mm · mean endpoint"
        f" {_fmt(b['endpoint_mean_mm'], 3)} -> {_fmt(a['endpoint_mean_mm'], 3)} mm · robot time"
        f" {_fmt(rep['rescan']['motion_s'], 1)} s"
    )


def print_weld(rep: dict, title: str) -> None:
    t = Table(
        title=f"{title} {rep['scenario']} · method {rep['method']} · noise {rep['noise']} · frame R",
        title_justify="left",
    )
    for col in (
        "seam",
        "detected",
        "paper ME mm",
        "lateral mm",
        "welded",
        "TCP rms mm",
        "TCP max mm",
        "weld s",
        "why not",
    ):
        t.add_column(col, justify="left" if col in ("seam", "detected", "welded", "why not") else "right")
    for s in rep["seams"]:
        e = s.get("error_mm", {})
        tcp = s.get("tcp_error_mm", {})
        t.add_row(
            s["id"],
            s["status"],
            _fmt(e.get("paper_me")),
            _fmt(e.get("lateral")),
            "yes" if s["welded"] else ("planned" if s.get("planned") else "no"),
            _fmt(tcp.get("rms")),
            _fmt(tcp.get("max")),
            _fmt(s.get("weld_time_s"), 1),
            s.get("weld_reason", ""),
        )
    out.print(t)
    m = rep["summary"]
    cyc = rep["cycle_time_s"] if rep["cycle_time_s"] else rep["planned_cycle_time_s"]
    out.print(
        f"welded {rep['welded']}/{m['visible']} visible seams ({m['seams']} in the map) · located {m['found']} · "
        f"paper ME mean {_fmt(m['paper_me_mean_mm'])} mm · cycle time {_fmt(cyc, 1)} s"
        + ("" if rep["cycle_time_s"] else " (planned)")
    )
    print_timings(rep)


def print_timings(rep: dict) -> None:
    """The stage times of a report, one line."""
    tim = rep["timings_s"]
    out.print("time: " + " · ".join(f"{k.removesuffix('_s')} {v:.2f} s" for k, v in tim.items() if v is not None))


def _fmt(v: float | None, nd: int = 2) -> str:
    return "-" if v is None else f"{v:.{nd}f}"


def print_detection(det: Detection) -> None:
    from cell.export.report import detection_report

    rep = detection_report(det)
    t = Table(
        title=f"{rep['scenario']} · method {rep['method']} · noise {rep['noise']} · frame R",
        title_justify="left",
    )
    for col in ("seam", "status", "paper ME mm", "endpoint mm", "lateral mm", "conf", "ms", "reason"):
        t.add_column(col, justify="right" if col not in ("seam", "status", "reason") else "left")
    for s in rep["seams"]:
        e = s.get("error_mm", {})
        t.add_row(
            s["id"],
            s["status"],
            _fmt(e.get("paper_me")),
            _fmt(e.get("endpoint")),
            _fmt(e.get("lateral")),
            _fmt(s.get("confidence")),
            _fmt(s["time_ms"], 1) if s["status"] == "found" else "-",
            s["reason"],
        )
    out.print(t)
    m = rep["summary"]
    out.print(
        f"found {m['found']}/{m['visible']} visible ({m['seams']} seams) · paper ME mean"
        f" {_fmt(m['paper_me_mean_mm'])} mm (p95 {_fmt(m['paper_me_p95_mm'])}) · endpoint"
        f" {_fmt(m['endpoint_mean_mm'])} mm · lateral"
        f" {_fmt(m['lateral_mean_mm'])} mm · {_fmt(m['time_ms_per_seam_median'], 1)} ms/seam (median)"
    )
    print_timings(rep)
