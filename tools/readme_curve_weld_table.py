"""docs/results.md's curved-weld blocks (``tools/readme_results.py``): the round scenarios' curved seams welded from
truth-built estimates (``benchmarks/results/curve_weld.json``) and through ``cell weld`` with the located curves
(``benchmarks/results/curve_weld_located.json``), both by ``benchmarks/bench_curve_weld.py``."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any


def _tcp(r: Mapping[str, Any]) -> str:
    return f"{r['tcp_rms_mm']:.3f} / {r['tcp_max_mm']:.3f}" if r.get("tcp_rms_mm") is not None else "-"


def _why(r: Mapping[str, Any]) -> str:
    if r.get("partial"):  # welded in part: each stretch left for a manual weld, where and why (its code)
        return "; ".join(f"{m['from_mm']:.0f}-{m['to_mm']:.0f} mm {m['code']}" for m in r["remainder"])
    return "" if r["welded"] else str(r["reason"]).replace("|", "/")


def _welded(r: Mapping[str, Any]) -> str:
    """yes (whole), partial with its share and the length left for a manual weld, or no."""
    if r.get("partial"):
        return f"partial {r['share']:.1%}, {r['remainder_mm']:.0f} mm manual"
    return "yes" if r["welded"] else "no"


def truth_table(data: Mapping[str, Any]) -> str:
    """Per curved seam from a truth-built estimate: welded whole, in part (its share, the length left for a manual
    weld and where, why) or not, in how many arcs, TCP against the true curve, the length no record reached, arc
    time, why not; the planning time per scenario."""
    lines = [
        "| scenario | curved seam | length mm | welded | arcs | TCP RMS / max mm (true curve) | unwelded mm | arc s"
        " | plan s | why not |",
        "|---|---|---:|---|---:|---|---:|---:|---:|---|",
    ]
    for row in data["rows"]:
        for r in row["seams"]:
            kind = "closed" if r["closed"] else "open"
            unw = f"{r['unwelded_mm']:.1f}" if r.get("unwelded_mm") is not None else "-"
            arc = f"{r['arc_s']:.1f}" if r.get("arc_s") is not None else "-"
            welded = _welded(r)
            lines.append(
                f"| {row['scenario']} | `{r['seam']}` ({kind}) | {r['length_mm']:.0f} | {welded}"
                f" | {r.get('arcs', 0)} | {_tcp(r)} | {unw} | {arc} | {row['plan_s']:.0f} | {_why(r)} |"
            )
    return "\n".join(lines) + f"\n\n`{data['command']}` (commit {str(data.get('commit', ''))[:10]})\n"


def located_table(data: Mapping[str, Any]) -> str:
    """Per scenario through ``cell weld NAME --sides first``: straight seams welded, and per curved seam located
    (RMS / max against the true curve), welded in how many arcs, TCP, the programs' circular moves, why not."""
    lines = [
        "| scenario | straight welded | curved seam | located RMS / max mm | welded | arcs | TCP RMS / max mm"
        " | KRL CIRC / check / RAPID ArcC | run s | why not |",
        "|---|---|---|---|---|---:|---|---|---:|---|",
    ]
    for row in data["rows"]:
        pg = row["programs"]
        prog = f"{pg['krl_circ']} / {', '.join(pg['krl_check']) or 'clean'} / {pg['rapid_arcc']}" if pg else "-"
        straight = f"{row['straight_welded']}/{row['straight_seams']}"
        for r in row["seams"]:
            loc = f"{r['located_rms_mm']:.3f} / {r['located_max_mm']:.3f}" if r["located_rms_mm"] is not None else "-"
            why = "" if r["welded"] else f"{r['code'] or 'not located'}: {r['reason']}".replace("|", "/")
            lines.append(
                f"| {row['scenario']} | {straight} | `{r['seam']}` | {loc} | {_welded(r)}"
                f" | {r['arcs']} | {_tcp(r)} | {prog} | {row['total_s']:.0f} | {why} |"
            )
    return "\n".join(lines) + f"\n\n`{data['command']}` (commit {str(data.get('commit', ''))[:10]})\n"


def layout_table(data: Mapping[str, Any]) -> str:
    """Per round scenario and curved seam, the share the fixed arm welds with its base at each distance (the shipped
    one marked), and what stops it on the rest (the remainder's codes, or the planner's code when nothing is welded)."""
    rows = data["rows"]
    dists = sorted({r["distance_m"] for r in rows}, reverse=True)
    head = " | ".join(f"{d:.2f} m" + (" (shipped)" if d == data["shipped_m"] else "") for d in dists)
    lines = [f"| scenario | curved seam | {head} |", "|---|---|" + "---|" * len(dists)]
    by = {(r["scenario"], r["distance_m"]): r for r in rows}
    for name in dict.fromkeys(r["scenario"] for r in rows):
        seams = list(dict.fromkeys(c["seam"] for d in dists for c in by[name, d]["curves"] if (name, d) in by))
        for sid in seams:
            cells = []
            for d in dists:
                row = by.get((name, d))
                c = next((c for c in row["curves"] if c["seam"] == sid), None) if row else None
                if row is not None and row["error"]:
                    cells.append(f"error: {row['error']}".replace("|", "/"))
                elif c is None or c["located"] != "found":
                    cells.append("not located" if c is not None else "-")
                elif c["welded"]:
                    cells.append("**100%**")
                else:
                    why = ", ".join(c["stops"]) if c["stops"] else (c["code"] or "")
                    cells.append(f"{c['share']:.0%} ({why})")
            lines.append(f"| {name} | `{sid}` | " + " | ".join(cells) + " |")
    commit = str(data.get("commit", ""))[:10]
    return "\n".join(lines) + f"\n\n`{data['command']}` (commit {commit}, {data['wall_min']} min)\n"
