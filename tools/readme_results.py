"""Render the result tables from ``benchmarks/results/`` and put them between the markers of docs/results.md (every
table) and README.md (the headline figures).

Run from the repository root::

    .venv/bin/python tools/readme_results.py           # rewrite the marked blocks of docs/results.md and README.md
    .venv/bin/python tools/readme_results.py --check   # exit 1 when either differs from the results

Each block sits between ``<!-- results:NAME -->`` and ``<!-- /results:NAME -->``; :data:`BLOCKS` names the result
file each block of docs/results.md is made from, :data:`README_BLOCKS` the README's. The JSON is the truth: re-run a
benchmark with ``--json`` and then this script.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parent.parent
TOOLS = Path(__file__).resolve().parent
for _path in (REPO, TOOLS):  # run as a script from anywhere: the package is the repository's, and tools/ its own
    if str(_path) not in sys.path:
        sys.path.insert(0, str(_path))

import readme_calibration_table as calibration_tables  # noqa: E402  (after the path set-up above)
import readme_cell_tables as cell_tables  # noqa: E402  (after the path set-up above)
import readme_curve_weld_table as curve_weld_tables  # noqa: E402
import readme_journal_tables as journal_tables  # noqa: E402
import readme_positioner_table as positioner_tables  # noqa: E402
from readme_trust_table import num, pct, trust_table  # noqa: E402

from cell.bench import PAPER_TABLE1, markdown_table  # noqa: E402

README = REPO / "README.md"
RESULTS_MD = REPO / "docs" / "results.md"
RESULTS = REPO / "benchmarks" / "results"
COMMAND = ".venv/bin/python tools/readme_results.py"

Rows = list[dict[str, Any]]

# How the scaling table names a scenario (the JSON holds the name only).
SCALING_LABELS: Mapping[str, str] = {"ladder": "ladder (26 rungs)"}
# The methods of the scaling table, in its column order, and what each column shows.
SCALING_METHODS = ("ours", "paper", "ransac")


def _load(results: Path, name: str) -> Rows:
    data = json.loads((results / name).read_text(encoding="utf-8"))
    if not isinstance(data, list):
        raise ValueError(f"{results / name}: expected a JSON list of rows, got {type(data).__name__}")
    return data


def _load_object(results: Path, name: str) -> dict[str, Any]:
    data = json.loads((results / name).read_text(encoding="utf-8"))
    if not isinstance(data, dict):
        raise ValueError(f"{results / name}: expected a JSON object, got {type(data).__name__}")
    return data


def table1(results: Path) -> str:
    """Table 1, realistic noise, exact calibration: every method on every scenario."""
    return markdown_table([r for r in _load(results, "latest.json") if r["extrinsics"] == "exact"])


def table1_noise_none(results: Path) -> str:
    """Table 1 with noise-free depth (the paper's own conditions)."""
    return markdown_table(_load(results, "noise-none.json"))


def calibration(results: Path) -> str:
    """Ours under calibration error: the non-exact extrinsics rows of the same run as Table 1."""
    return markdown_table(
        [r for r in _load(results, "latest.json") if r["extrinsics"] != "exact" and r["method"] == "ours"]
    )


def _planning_cells(p: Mapping[str, Any] | None) -> str:
    """``planned / asked | CPU s per planned seam`` of a scaling row's planning (dashes without an arm)."""
    if not p:
        return "- | -"
    return f"{p['seams_planned']} / {p['seams_asked']} | {p['cpu_s_per_planned_seam']:.3f}"


def scaling_table(rows: Sequence[Mapping[str, Any]]) -> str:
    """One line per scenario: size, capture, perception and alignment [s], perceive + align + locate against
    capture (the first run), per method found and ms per seam, and planning per seam."""
    head = (
        "| scenario | seams / visible | points dense / 1 cm | capture s | perceive s | align s | "
        "perceive + align + locate / capture | ours: found, ms/seam median, lateral mm | paper: found, ms/seam | "
        "ransac: found, ms/seam | planned / found | planning CPU s / planned seam |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|\n"
    )
    lines = []
    for r in rows:
        m = r["methods"]
        ours, paper, ransac = (m[k] for k in SCALING_METHODS)
        d = r.get("detect_vs_capture")
        ratio = f"{d['perceive_align_locate_s'] / d['capture_s']:.2f}" if d else "-"
        lines.append(
            f"| {SCALING_LABELS.get(r['scenario'], r['scenario'])} | {r['seams']} / {r['visible']} | "
            f"{r['points_dense']:,} / {r['points_voxel']:,} | {r['capture_s']:.2f} | {r['perceive_s']:.2f} | "
            f"{r['align_s']:.2f} | {ratio} | "
            f"{ours['found']}, {ours['ms_per_seam_median']:.2f}, {ours['lateral_mean_mm']:.3f} | "
            f"{paper['found']}, {paper['ms_per_seam_median']:.2f} | "
            f"{ransac['found']}, {ransac['ms_per_seam_median']:.2f} | {_planning_cells(r.get('planning'))} |"
        )
    return head + "\n".join(lines) + "\n"


def scaling(results: Path) -> str:
    """The scaling table of ``scaling.json``."""
    return scaling_table(_load(results, "scaling.json"))


# How the coverage table names a group of seams (``coverage.json``'s ``group``).
COVERAGE_GROUPS: Mapping[str, str] = {"scenarios": "scenarios", "faults": "fence1's faults", "all": "all"}


def coverage(results: Path) -> str:
    """Each locator's sigma against its true errors (``coverage.json``, by ``benchmarks/bench_coverage.py``)."""
    data = _load_object(results, "coverage.json")
    lines = [
        "| method | seams | found | lateral within 2 sigma | within 3 sigma | endpoint within 2 sigma "
        "| median sigma [mm] | max lateral [mm] |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in data["coverage"]:
        lines.append(
            f"| {r['method']} | {COVERAGE_GROUPS.get(r['group'], r['group'])} | {r['found']} "
            f"| {r['lateral_2sigma']:.0%} | {r['lateral_3sigma']:.0%} | {r['endpoint_2sigma']:.0%} "
            f"| {r['sigma_median_mm']:.3f} | {r['lateral_max_mm']:.3f} |"
        )
    return "\n".join(lines) + "\n"


def weld(results: Path) -> str:
    """Welding fence1: the first run of ``weld.json``, per seam, and its cycle-time line."""
    return cell_tables.weld_table(_load(results, "weld.json")[0])


def trust(results: Path) -> str:
    """The trust benchmark's table (``trust.json``; not run yet when the file is missing)."""
    path = results / "trust.json"
    return trust_table(_load_object(results, "trust.json") if path.exists() else {})


def headline(results: Path) -> str:
    """The README's one table: fence1 located against the paper, the time per seam, fence1 welded, the faults and
    the random cells, each row linking to its section of docs/results.md."""
    rows = [r for r in _load(results, "latest.json") if r["scenario"] == "fence1" and r["extrinsics"] == "exact"]
    ours, paper = (next(r for r in rows if r["method"] == m) for m in ("ours", "paper"))
    me_paper, ms_paper = PAPER_TABLE1["fence1"]["paper"]
    w = _load(results, "weld.json")[0]
    faults = _load(results, "faults.json")
    tcp = [r["tcp_max_mm"] for r in faults if r["tcp_max_mm"] is not None]
    refused = sum(r["welded"] == 0 for r in faults)
    trust = _load_object(results, "trust.json").get("weld") if (results / "trust.json").exists() else None
    link = "docs/results.md#"
    lines = [
        "| what | ours | beside it |",
        "|---|---|---|",
        f"| [fence1, realistic depth noise]({link}table-1-reproduced-and-beaten): a seam located, paper ME / lateral, "
        f"mean | {ours['paper_me_mean_mm']:.3f} / {ours['lateral_mean_mm']:.3f} mm | the paper's method here "
        f"{paper['paper_me_mean_mm']:.3f} / {paper['lateral_mean_mm']:.3f} mm; the paper's own, noise-free, "
        f"{me_paper} mm |",
        f"| time to locate a seam, median | {ours['ms_per_seam_median']:.2f} ms | the paper's method here "
        f"{paper['ms_per_seam_median']:.2f} ms; the paper's own {ms_paper:.0f} ms |",
        f"| [`cell weld fence1`]({link}welding-fence1), both sides: welded, worst executed TCP max against the "
        f"true seam | {w['welded']}/{w['visible']}, {w['tcp_max_mm']:.2f} mm | job time {w['job_time_s']:.0f} s "
        f"with the operator's turn |",
        f"| [{len(faults)} fault scenarios]({link}faults): worst executed TCP error of a welded seam "
        f"| {max(tcp):.2f} mm | {refused} refuse to weld anything, each with its reason |",
    ]
    if trust:
        lines.append(
            f"| [{trust['cells']} random cells nobody tuned for]({link}trust-on-cells-nobody-tuned-for): welded, "
            f"worst TCP max, beads > 1 mm off a joint's end | {pct(trust['welded_share'])}, "
            f"{num(trust.get('worst_welded_tcp_max_mm'))} mm, {num(trust.get('beads_past_end'), 'd')} "
            f"| of {trust['seams_visible']} visible seams; the rest refused, each with its reason |"
        )
    return "\n".join(lines) + "\n"


def curves(results: Path) -> str:
    """Curved seams located on the round-part scenarios (``curves.json``, by ``benchmarks/bench_curves.py``): per
    seam over the seeds, found of runs, the worst RMS and max error against the true curve, the share of samples
    within 2 sigma, the largest sigma and the locator's median time (wall, and the process's CPU), with the load
    average and the context switches during a run where the results have them."""
    data = _load_object(results, "curves.json")
    lines = [
        "| scenario | curved seam | found | RMS [mm] | max [mm] | within 2 sigma | sigma max [mm] | wall [ms] "
        "| CPU [ms] |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in data["summary"]:
        found = f"{r['found']}/{r['runs']}" + (f" ({', '.join(r['codes'])})" if r["codes"] else "")
        lines.append(
            f"| {r['scenario']} | {r['seam']} | {found} | {num(r['rms_mm_worst'])} | {num(r['max_mm_worst'])} "
            f"| {pct(r['within_2sigma'])} | {num(r['sigma_max_mm'])} | {r['time_ms_median']:.1f} "
            f"| {r['cpu_ms_median']:.1f} |"
        )
    rows = data["summary"]
    note = ""
    if rows and "load_median" in rows[0]:
        loads = [r["load_median"] for r in rows]
        apart = max(abs(r["cpu_ms_median"] - r["thread_cpu_ms_median"]) for r in rows)
        note = (
            f"\n\nLoad average {min(loads):.1f}-{max(loads):.1f} on 2 cores; per run "
            f"{min(r['preempted_median'] for r in rows):.0f}-{max(r['preempted_median'] for r in rows):.0f} "
            f"involuntary context switches (the core given to another process) and "
            f"{max(r['waited_median'] for r in rows):.0f} voluntary ones (nothing waited on); the process's CPU "
            f"time equals the thread's within {apart:.1f} ms."
        )
    return "\n".join(lines) + note + f"\n\n`{data['command']}` (commit {data['commit'][:10]})\n"


BLOCKS: Mapping[str, Callable[[Path], str]] = {
    "table1": table1,
    "table1-noise-none": table1_noise_none,
    "calibration": calibration,
    "rescan": lambda results: cell_tables.rescan_table(_load(results, "rescan.json")),
    "confidence": lambda results: cell_tables.confidence_table(_load_object(results, "confidence.json")),
    "coverage": coverage,
    "weld": weld,
    "motion": lambda results: cell_tables.motion_table(_load_object(results, "motion.json")),
    "scaling": scaling,
    "faults": lambda results: cell_tables.faults_table(_load(results, "faults.json")),
    "planning": lambda results: cell_tables.planning_table(_load_object(results, "planning.json")),
    "real-scans": lambda results: cell_tables.real_scans_table(_load_object(results, "real_scans.json")),
    "weldments": lambda results: cell_tables.weldments_table(_load(results, "weldments.json")),
    "weldments-bench": lambda results: markdown_table(_load(results, "weldments-bench.json")),
    "trust": trust,
    "cell-calibration": lambda results: calibration_tables.calibration_table(_load_object(results, "calibration.json")),
    "calibration-loop": lambda results: calibration_tables.loop_table(_load_object(results, "calibration_loop.json")),
    "cycle": lambda results: cell_tables.cycle_table(
        _load_object(results, "cycle.json"),
        _load_object(results, "cycle_before.json") if (results / "cycle_before.json").is_file() else None,
    ),
    "interrupts": lambda results: journal_tables.interrupts_table(_load_object(results, "interrupts.json")),
    "curves": curves,
    "curve-weld": lambda results: curve_weld_tables.truth_table(_load_object(results, "curve_weld.json")),
    "curve-weld-located": lambda results: curve_weld_tables.located_table(
        _load_object(results, "curve_weld_located.json")
    ),
    "curve-track": lambda results: curve_weld_tables.located_table(_load_object(results, "curve_track.json")),
    "layout": lambda results: curve_weld_tables.layout_table(_load_object(results, "layout.json")),
    "positioner": lambda results: positioner_tables.positioner_table(_load_object(results, "positioner.json")),
    "coordinated": lambda results: positioner_tables.coordinated_table(_load_object(results, "coordinated.json")),
}


README_BLOCKS: Mapping[str, Callable[[Path], str]] = {"headline": headline}


def _pattern(name: str) -> re.Pattern[str]:
    return re.compile(rf"(<!-- results:{re.escape(name)} -->\n)(.*?)(<!-- /results:{re.escape(name)} -->)", re.DOTALL)


def _block(text: str, name: str) -> str:
    found = _pattern(name).search(text)
    return found.group(2) if found else ""


def _replacement(table: str) -> Callable[[re.Match[str]], str]:
    """A ``re.sub`` replacement keeping the markers around ``table`` (taken as is, no escapes)."""
    return lambda m: m.group(1) + table + m.group(3)


def render(text: str, results: Path = RESULTS, blocks: Mapping[str, Callable[[Path], str]] = BLOCKS) -> str:
    """``text`` with every block of ``blocks`` replaced by the table the results give (ValueError: a marker
    missing)."""
    out = text
    for name, make in blocks.items():
        pattern = _pattern(name)
        if len(pattern.findall(out)) != 1:
            raise ValueError(f"needs exactly one <!-- results:{name} --> ... <!-- /results:{name} --> block")
        out = pattern.sub(_replacement(make(results)), out)
    return out


def _update(path: Path, blocks: Mapping[str, Callable[[Path], str]], results: Path, check: bool) -> int:
    """Check or rewrite the marked blocks of one file; 1 when it is stale (``check``) or a marker is missing."""
    current = path.read_text(encoding="utf-8")
    try:
        text = render(current, results, blocks)
    except ValueError as e:
        print(f"error: {path}: {e}", file=sys.stderr)
        return 1
    if text == current:
        if not check:
            print(f"{path} already matches {results}")
        return 0
    if check:
        stale = [n for n in blocks if _block(text, n) != _block(current, n)]
        print(f"{path}: blocks {', '.join(stale)} differ from {results}; run {COMMAND}", file=sys.stderr)
        return 1
    path.write_text(text, encoding="utf-8")
    print(f"rewrote the result blocks of {path}")
    return 0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--check", action="store_true", help="exit 1 when a file differs from the results")
    ap.add_argument("--doc", type=Path, default=RESULTS_MD, help="the results page (every table)")
    ap.add_argument("--readme", type=Path, default=README, help="the README (the headline table)")
    ap.add_argument("--results", type=Path, default=RESULTS)
    args = ap.parse_args(argv)
    codes = [
        _update(args.doc, BLOCKS, args.results, args.check),
        _update(args.readme, README_BLOCKS, args.results, args.check),
    ]
    return max(codes)


if __name__ == "__main__":
    sys.exit(main())
