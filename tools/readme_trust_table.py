"""The trust benchmark's table for docs/results.md (``benchmarks/results/trust.json``, written by
``benchmarks/bench_trust.py``): one row per stage, then each stage's curved seams and its command; and the small
formatters the other result tables share."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any


def pct(v: float | None) -> str:
    return "-" if v is None else f"{v:.0%}"


def num(v: float | int | None, fmt: str = ".2f") -> str:
    return "-" if v is None else format(v, fmt)


def dist(d: Mapping[str, Any]) -> str:
    return f"{num(d['p95'])} / {num(d['max'])}"


def trust_table(data: Mapping[str, Any]) -> str:
    """One row per stage of ``trust.json`` (docs/trust.md, "The trust benchmark"), a dash where the report had no
    such figure; under the table, each stage's curved seams (:func:`curved_line`), command, commit and time."""
    lines = [
        "| stage | cells (failed) | visible seams | located | re-scanned | refused: reasons "
        "| lateral p95 / max [mm] | ends p95 / max [mm] | within 2 sigma across | ends within 2 end sigmas "
        "| splice corrections, exact cameras | welded | worst welded TCP max [mm] | beads > 1 mm off a joint's end |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    notes = []
    for stage in ("detect", "weld"):
        b = data.get(stage)
        if b is None:
            continue
        reasons = ", ".join(f"{k} {v}" for k, v in b["refused_reasons"].items())
        lines.append(
            f"| {stage} | {b['cells']} ({b['cells_failed']}) | {b['seams_visible']} | {pct(b['located_share'])} "
            f"| {pct(b.get('rescanned_share'))} | {pct(b['refused_share'])}{': ' + reasons if reasons else ''} "
            f"| {dist(b['lateral_mm'])} | {dist(b['end_mm'])} | {pct(b['coverage_2sigma_across'])} "
            f"| {pct(b['coverage_2sigma_ends'])} | {num(b['splice_corrections_exact'], 'd')} "
            f"in {b['cells_exact']} cells | {pct(b.get('welded_share'))} "
            f"| {num(b.get('worst_welded_tcp_max_mm'))} | {num(b.get('beads_past_end'), 'd')} |"
        )
        if b.get("curved", {}).get("seams"):
            notes.append(curved_line(stage, b["curved"]))
        w = b["cell_wall_s"]
        notes.append(
            f"- {stage}: `{b['command']}` (commit {b['commit'][:12]}; {b['cells_run_now']} of the {b['cells']} "
            f"cells run in the last sitting, {b['wall_s'] / 60.0:.1f} min on {b['workers']} workers; per cell "
            f"{num(w['median'], '.1f')} s median, {num(w['max'], '.1f')} s max)"
        )
    if not notes:
        return "Not run yet: `.venv/bin/python benchmarks/bench_trust.py --cells 200 --seed 0 --stage detect`.\n"
    return "\n".join(lines) + "\n\n" + "\n".join(notes) + "\n"


def curved_line(stage: str, c: Mapping[str, Any]) -> str:
    """A stage's curved seams in one line: located of visible, the error against the true curve (median / max of
    the seams' max), the samples within 2 sigma, the curves wholly within, and for a weld what was welded (whole, and
    in part with what it leaves for a manual weld)."""
    reasons = ", ".join(f"{k} {v}" for k, v in c["refused_reasons"].items())
    line = (
        f"- {stage}, curved seams: {c['located']} of {c['visible']} visible located ({pct(c['located_share'])}); "
        f"error against the true curve, each seam's max: median {num(c['max_mm']['median'])}, max "
        f"{num(c['max_mm']['max'])} mm; samples within 2 sigma {pct(c['samples_within_2sigma'])}, curves wholly "
        f"within {pct(c['curves_within_2sigma'])}"
    )
    if "welded" in c:
        line += f"; welded {c['welded']}, worst TCP max {num(c['worst_welded_tcp_max_mm'])} mm"
    if c.get("partial"):  # welded in part: the arcs' worst TCP, the length left for a manual weld
        line += (f"; welded in part {c['partial']} (worst TCP max {num(c['worst_partial_tcp_max_mm'])} mm, "
                 f"{c['manual_mm']:.0f} mm left for a manual weld)")  # fmt: skip
    return line + (f"; not {'welded' if 'welded' in c else 'located'}: {reasons}" if reasons else "")
