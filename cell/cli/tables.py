"""The tables and summary lines the commands print (from the JSON reports, so screen and file agree).

``--format table`` (rich, as wide as the terminal), ``json`` (a list of rows, column name -> value, numbers as
numbers and ``-`` as null) or ``csv`` (a header row, then one row per seam); json and csv print no summary.
"""

from __future__ import annotations

import csv
import json
from collections.abc import Sequence
from typing import TYPE_CHECKING

from rich.table import Table

from cell.cli.common import TableFormat, out

if TYPE_CHECKING:
    from cell.pipeline.records import Detection


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
        f" {_fmt(rep['rescan']['motion_s'], 1)} s",
        soft_wrap=True,
    )


def _value(cell: str) -> str | float | None:
    if cell == "-":
        return None
    try:
        return float(cell)
    except ValueError:
        return cell


def _emit(t: Table, columns: Sequence[str], rows: Sequence[Sequence[str]], fmt: TableFormat) -> bool:
    """Print the rows in ``fmt``; True when it was a rich table (then the summary lines follow)."""
    if fmt == "table":
        for row in rows:
            t.add_row(*row)
        out.print(t)
        return True
    if fmt == "json":
        out.file.write(json.dumps([dict(zip(columns, map(_value, r), strict=True)) for r in rows], indent=2) + "\n")
    else:
        w = csv.writer(out.file, lineterminator="\n")
        w.writerow(columns)
        w.writerows(rows)
    out.file.flush()
    return False


def _data(rep: dict) -> str:
    """What the data were: the simulated noise, or where they came from when nothing was simulated."""
    noise = rep.get("noise")
    return f"noise {noise}" if noise is not None else f"data: {rep.get('source', 'recorded')}"


def _frame(rep: dict) -> str:
    """The frame every point of a report is in (R for a scenario run, the cloud's own for cell locate)."""
    return str(rep.get("frame", "R"))


def print_weld(rep: dict, title: str, fmt: TableFormat = "table") -> None:
    t = Table(
        title=f"{title} {rep['scenario']} · method {rep['method']} · {_data(rep)} · frame {_frame(rep)}",
        title_justify="left",
    )
    columns = (
        "seam",
        "detected",
        "paper ME mm",
        "lateral mm",
        "welded",
        "TCP rms mm",
        "TCP max mm",
        "weld s",
        "why not",
    )
    for col in columns:
        t.add_column(col, justify="left" if col in ("seam", "detected", "welded", "why not") else "right")
    rows = []
    for s in rep["seams"]:
        e = s.get("error_mm", {})
        tcp = s.get("tcp_error_mm", {})
        rows.append(
            (
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
        )
    if not _emit(t, columns, rows, fmt):
        return
    m = rep["summary"]
    cyc = rep["cycle_time_s"] if rep["cycle_time_s"] else rep["planned_cycle_time_s"]
    out.print(
        f"welded {rep['welded']}/{m['visible']} visible seams ({m['seams']} in the map) · located {m['found']} · "
        f"paper ME mean {_fmt(m['paper_me_mean_mm'])} mm · cycle time {_fmt(cyc, 1)} s"
        + ("" if rep["cycle_time_s"] else " (planned)"),
        soft_wrap=True,
    )
    print_timings(rep)


def print_timings(rep: dict) -> None:
    """The stage times of a report, one line."""
    tim = rep["timings_s"]
    out.print(
        "time: " + " · ".join(f"{k.removesuffix('_s')} {v:.2f} s" for k, v in tim.items() if v is not None),
        soft_wrap=True,
    )


def _fmt(v: float | None, nd: int = 2) -> str:
    return "-" if v is None else f"{v:.{nd}f}"


def print_detection(det: Detection | dict, fmt: TableFormat = "table") -> None:
    """The detection table of a Detection or of its report."""
    from cell.export.report import detection_report

    rep = det if isinstance(det, dict) else detection_report(det)
    t = Table(
        title=f"{rep['scenario']} · method {rep['method']} · {_data(rep)} · frame {_frame(rep)}",
        title_justify="left",
    )
    columns = ("seam", "status", "paper ME mm", "endpoint mm", "lateral mm", "conf", "ms", "reason")
    for col in columns:
        t.add_column(col, justify="right" if col not in ("seam", "status", "reason") else "left")
    rows = []
    for s in rep["seams"]:
        e = s.get("error_mm", {})
        rows.append(
            (
                s["id"],
                s["status"],
                _fmt(e.get("paper_me")),
                _fmt(e.get("endpoint")),
                _fmt(e.get("lateral")),
                _fmt(s.get("confidence")),
                _fmt(s["time_ms"], 1) if s["status"] == "found" else "-",
                s["reason"],
            )
        )
    if not _emit(t, columns, rows, fmt):
        return
    m = rep["summary"]
    out.print(
        f"found {m['found']}/{m['visible']} visible ({m['seams']} seams) · paper ME mean"
        f" {_fmt(m['paper_me_mean_mm'])} mm (p95 {_fmt(m['paper_me_p95_mm'])}) · endpoint"
        f" {_fmt(m['endpoint_mean_mm'])} mm · lateral"
        f" {_fmt(m['lateral_mean_mm'])} mm · {_fmt(m['time_ms_per_seam_median'], 1)} ms/seam (median)",
        soft_wrap=True,
    )
    print_timings(rep)
