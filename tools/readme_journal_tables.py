"""The interrupts table of docs/results.md, from ``benchmarks/results/interrupts.json``
(benchmarks/bench_interrupts.py): one row per way ``cell weld`` was stopped, what its report and journal said,
and what ``--resume`` welded."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

Row = Mapping[str, Any]


def _at(case: Row) -> str:
    at = case["at"]
    return f"{at:g} s" if isinstance(at, int | float) else f"record `{at}`"


def _stopped(case: Row) -> str:
    if case.get("before_job"):
        return "before the job began"
    if case["signal"] == "SIGKILL":
        return "no report (killed); journal whole" + ("" if not case["journal_warnings"] else ", torn last line")
    ok = case.get("report_parses") and case.get("report_matches_journal")
    return "parses, = journal" if ok else "WRONG"


def interrupts_table(data: Row) -> str:
    """Markdown: per case the signal, when, the exit code, seams welded when stopped (and interrupted mid-bead),
    the report against the journal, the resume's exit, the seams it welded, the total, any welded twice, the worst
    TCP RMS; then a line with the count of cases that held."""
    lines = [
        "| signal | at | exit | welded when stopped | report | resume exit | resume welded | total | twice | "
        "worst TCP rms [mm] | holds |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for c in data["cases"]:
        r = c.get("resume") or {}
        mid = f" ({len(c.get('interrupted_seams', []))} mid-bead)" if c.get("interrupted_seams") else ""
        rms = r.get("tcp_rms_max_mm")
        lines.append(
            f"| {c['signal']} | {_at(c)} | {c['exit']} | {c['welded_before_resume']}{mid} | {_stopped(c)} | "
            f"{r.get('exit', '-')} | {len(r.get('welded_by_resume', []))} | {r.get('welded_total', '-')} | "
            f"{len(r.get('welded_twice', [])) if r else '-'} | {'-' if rms is None else f'{rms:.3f}'} | "
            f"{'yes' if c['ok'] else 'no'} |"
        )
    bars = data["bars_mm"]
    lines.append("")
    lines.append(
        f"{data['passed']} of {len(data['cases'])} cases hold every check ({data['scenario']}, {data['seams']} seams; "
        f"the uninterrupted run {data['uninterrupted_s']:.0f} s; TCP bars {bars['tcp_rms']} mm "
        f"rms, {bars['tcp_max']} mm max)."
    )
    return "\n".join(lines) + "\n"
