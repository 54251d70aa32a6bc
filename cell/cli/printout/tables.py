"""The tables and summary lines the commands print (from the JSON reports, so screen and file agree).

``--format table`` (rich) keeps every seam id whole at 80 columns and in a file: short headers with a legend line
below, the reason as a code in the table and in words after it, one line per seam; ``json`` (a list of rows, column
name -> value, numbers as numbers and ``-`` as null) or ``csv`` (a header row, then one row per seam) keep the long
column names and the reasons in words; json and csv print no summary.
"""

from __future__ import annotations

import csv
import json
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

from rich import box
from rich.table import Table

from cell.cli.common import TableFormat, out
from cell.types import Unsupported
from cell.types.run import partial_text

if TYPE_CHECKING:
    from cell.pipeline.records import Detection

_LEFT = ("seam", "result", "why not")


def compact_table(title: str, headers: Sequence[str]) -> Table:
    """A compact table: no vertical rules, the seam id never wrapped (nor cut), numbers to the right."""
    t = Table(title=title, title_justify="left", box=box.SIMPLE_HEAD, pad_edge=False, collapse_padding=True)
    for h in headers:
        t.add_column(h, justify="left" if h in _LEFT else "right", no_wrap=h == "seam", overflow="fold")
    return t


def why_lines(whys: Sequence[tuple[str, str]]) -> None:
    """The reasons in words after the table, one line per seam (wrapped by the terminal, whole in a file)."""
    for sid, why in whys:
        if why:
            out.print(f"  {sid}: {why}", soft_wrap=True, markup=False, highlight=False)


LOCATED_CURVE_CODE = Unsupported.CURVED_NO_TORCH_PATH.value  # a curved seam located by a run that plans no weld


def not_supported_text(summary: Mapping[str, Any]) -> str:
    """``1 not supported: curved`` (the map's seams the cell cannot weld, by reason code), then ``2 curved located,
    not welded (curved_no_torch_path)`` (curved seams located by a run that plans no weld, a detection), or empty."""
    codes = dict(summary.get("not_supported") or {})
    located = codes.pop(LOCATED_CURVE_CODE, 0)
    n = sum(codes.values())
    out = [f"{n} not supported: " + ", ".join(c if k == 1 else f"{c} ({k})" for c, k in codes.items())] if n else []
    if located:
        out.append(f"{located} curved located, not welded ({LOCATED_CURVE_CODE})")
    curved = summary.get("curved") or {}
    tried = dict(curved.get("not_welded") or {})  # curves a weld run tried, by code
    part = tried.pop("partial", 0)
    if part:
        out.append(partial_text(part, curved.get("manual_mm")))
    if tried:
        out.append(f"{sum(tried.values())} curved not welded ({', '.join(sorted(tried))})")
    return "; ".join(out)


def print_curves(rep: Mapping[str, Any]) -> None:
    """One line per curved seam of a report: found or why not, its sigmas, its error against the true curve (in
    simulation), its time, and why it is not welded; welded in part, a line per stretch left for a manual weld
    (along the curve, and its ends on the drawing where the report has them)."""
    from cell.export.reports.curve_report import remainder_words

    for s in rep["seams"]:
        if not s.get("curved"):
            continue
        c, e = s.get("curve"), s.get("error_mm")
        line = f"curved {s['id']}: {s['status']}"
        if c is not None:
            ends = "closed" if c["closed"] else "ends +-" + "/".join(num(v) for v in c["end_sigma_mm"]) + " mm"
            line += f", {ends}, sigma max {num(c['sigma_max_mm'])} mm"
        if e is not None:
            line += f", error rms {num(e['rms'])} / max {num(e['max'])} mm"
        undone = s.get("not_welded")
        if s.get("remainder"):  # welded in part: its share, then each stretch left for a manual weld
            done = f"partly welded {s['share']:.0%}, {s['manual_mm']:.0f} mm left for a manual weld"
        else:
            done = f"not welded ({undone['code']})" if undone else "welded"
        line += f", {num(s['time_ms'], 1)} ms; {done}"
        out.print(line, soft_wrap=True, markup=False)
        for r in s.get("remainder") or ():
            out.print(f"  manual weld: {remainder_words(r)}", soft_wrap=True, markup=False, highlight=False)


def _value(cell: str) -> str | float | None:
    if cell == "-":
        return None
    try:
        return float(cell)
    except ValueError:
        return cell


def _emit(columns: Sequence[str], rows: Sequence[Sequence[str]], fmt: TableFormat) -> None:
    """Print the rows as data in ``fmt`` (json or csv), with the long column names."""
    if fmt == "json":
        out.file.write(json.dumps([dict(zip(columns, map(_value, r), strict=True)) for r in rows], indent=2) + "\n")
    else:
        w = csv.writer(out.file, lineterminator="\n")
        w.writerow(columns)
        w.writerows(rows)
    out.file.flush()


def _data(rep: dict) -> str:
    """What the data were: the simulated noise, or where they came from when nothing was simulated."""
    noise = rep.get("noise")
    return f"noise {noise}" if noise is not None else f"data: {rep.get('source', 'recorded')}"


def _frame(rep: dict) -> str:
    """The frame every point of a report is in (R for a scenario run, the cloud's own for cell locate)."""
    return str(rep.get("frame", "R"))


WELD_COLUMNS = (
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
WELD_LEGEND = (
    "ME: the paper's error measure, lat: lateral error of the located seam, rms and max: the executed TCP against the"
    " true seam [mm]; s: weld time; result: welded, planned, or why not (in words below)"
)


def _result(s: Mapping[str, Any]) -> str:
    """What became of a seam in one word: welded, partial (a curve welded in part), planned, or the code of why
    not."""
    if s["welded"]:
        return "welded"
    if s.get("weld_reason_code") == "partial":  # a curve's arcs welded, the rest left for a manual weld
        return "partial"
    if s.get("planned"):
        return "planned"
    return str(s.get("weld_reason_code") or "not welded")


def print_weld(rep: dict, title: str, fmt: TableFormat = "table") -> None:
    if fmt != "table":
        rows = []
        for s in rep["seams"]:
            e, tcp = s.get("error_mm", {}), s.get("tcp_error_mm", {})
            welded = (
                "yes" if s["welded"] else "partial" if s.get("remainder") else "planned" if s.get("planned") else "no"
            )
            rows.append(
                (s["id"], s["status"], num(e.get("paper_me")), num(e.get("lateral")), welded, num(tcp.get("rms")),
                 num(tcp.get("max")), num(s.get("weld_time_s"), 1), s.get("weld_reason", ""))
            )  # fmt: skip
        _emit(WELD_COLUMNS, rows, fmt)
        return
    t = compact_table(
        f"{title} {rep['scenario']} · method {rep['method']} · {_data(rep)} · frame {_frame(rep)}",
        ("seam", "ME", "lat", "result", "rms", "max", "s"),
    )
    whys = []
    for s in rep["seams"]:
        e, tcp = s.get("error_mm", {}), s.get("tcp_error_mm", {})
        t.add_row(
            s["id"],
            num(e.get("paper_me")),
            num(e.get("lateral")),
            _result(s),
            num(tcp.get("rms")),
            num(tcp.get("max")),
            num(s.get("weld_time_s"), 1),
        )
        if not s["welded"] and s.get("weld_reason_code") != "preview":
            whys.append((s["id"], s.get("weld_reason", "")))
    out.print(t)
    out.print(WELD_LEGEND, soft_wrap=True, markup=False)
    why_lines(whys)
    print_curves(rep)
    out.print(weld_summary(rep), soft_wrap=True)
    print_timings(rep)


def weld_summary(rep: Mapping[str, Any]) -> str:
    """The summary line of a weld (or preview): welded of every seam in the map, the seams the cell cannot weld,
    how many were visible and located, the mean error and the cycle time."""
    m = rep["summary"]
    cyc = rep["cycle_time_s"] if rep["cycle_time_s"] else rep["planned_cycle_time_s"]
    unsupported = not_supported_text(m)
    preview = any(s.get("weld_reason_code") == "preview" for s in rep["seams"])  # a dry run plans, welds nothing
    done = f"planned {sum(bool(s.get('planned')) for s in rep['seams'])}" if preview else f"welded {rep['welded']}"
    return (
        f"{done} of {m['seams']} seams in the map" + (f"; {unsupported}" if unsupported else "")
        + f" · visible {m['visible']} · located {m['found']} · paper ME mean {num(m['paper_me_mean_mm'])} mm"
        + f" · cycle time {num(cyc, 1)} s" + ("" if rep["cycle_time_s"] else " (planned)")
    )  # fmt: skip


def print_timings(rep: dict) -> None:
    """The stage times of a report, one line."""
    tim = rep["timings_s"]
    out.print(
        "time: " + " · ".join(f"{k.removesuffix('_s')} {v:.2f} s" for k, v in tim.items() if v is not None),
        soft_wrap=True,
    )


def num(v: float | None, nd: int = 2) -> str:
    """``v`` with ``nd`` decimals, or ``-`` where there is none."""
    return "-" if v is None else f"{v:.{nd}f}"


DETECT_COLUMNS = ("seam", "status", "paper ME mm", "endpoint mm", "lateral mm", "conf", "ms", "reason")
DETECT_LEGEND = (
    "ME: the paper's error measure, end: endpoint error, lat: lateral error [mm]; conf: confidence; ms: time to"
    " locate; result: found, or the reason's code (in words below)"
)


def print_detection(det: Detection | dict, fmt: TableFormat = "table") -> None:
    """The detection table of a Detection or of its report."""
    from cell.export.reports.report import detection_report

    rep = det if isinstance(det, dict) else detection_report(det)
    rows = []
    for s in rep["seams"]:
        e = s.get("error_mm", {})
        found = s["status"] == "found"
        rows.append(
            (s["id"], s["status"], num(e.get("paper_me")), num(e.get("endpoint")), num(e.get("lateral")),
             num(s.get("confidence")), num(s["time_ms"], 1) if found else "-", s["reason"])
        )  # fmt: skip
    if fmt != "table":
        _emit(DETECT_COLUMNS, rows, fmt)
        return
    t = compact_table(
        f"{rep['scenario']} · method {rep['method']} · {_data(rep)} · frame {_frame(rep)}",
        ("seam", "ME", "end", "lat", "conf", "ms", "result"),
    )
    for s, row in zip(rep["seams"], rows, strict=True):
        t.add_row(row[0], *row[2:7], "found" if s["status"] == "found" else str(s.get("reason_code") or s["status"]))
    out.print(t)
    out.print(DETECT_LEGEND, soft_wrap=True, markup=False)
    why_lines([(s["id"], s["reason"]) for s in rep["seams"] if s["status"] != "found"])
    print_curves(rep)
    m = rep["summary"]
    unsupported = not_supported_text(m)
    out.print(
        f"found {m['found']}/{m['visible']} visible ({m['seams']} seams in the map"
        + (f"; {unsupported}" if unsupported else "")
        + f") · paper ME mean {num(m['paper_me_mean_mm'])} mm (p95 {num(m['paper_me_p95_mm'])}) · endpoint"
        f" {num(m['endpoint_mean_mm'])} mm · lateral"
        f" {num(m['lateral_mean_mm'])} mm · {num(m['time_ms_per_seam_median'], 1)} ms/seam (median)",
        soft_wrap=True,
    )
    print_timings(rep)
