"""Interrupt ``cell weld fence1`` at every stage, then resume it: what the report and the journal say against what
was welded, and whether the resume welds exactly the rest.

    .venv/bin/python benchmarks/bench_interrupts.py [--scenario fence1] [--quick] [--json PATH]

Each case runs ``cell weld SCENARIO --json r.json --krl k/`` in a fresh folder and stops it: by a signal sent
from outside after a wall time (SIGINT, SIGTERM, SIGHUP at 5, 10, 15 s; SIGKILL at 10 s: these vary with the
machine's load) or, deterministically, by the journal's test hook at a named record (``CELL_JOURNAL_SIGNAL``,
docs/journal.md: after side A is located, planned, at a seam's arc on, after the turn, during the writes; a
SIGKILL at an arc on, the bead never finished). Then ``cell weld SCENARIO --resume r.journal.jsonl`` with the
same outputs. Checked per case: the stopped run's exit code (128 + the signal), its report parses, lists as welded
exactly the seams whose arc went off in the journal and each with the arc times and TCP error an uninterrupted run
measured for it (the same plan executed: the simulator's execution); the resume exits 0, the job's seams are all
welded, none twice (one completed arc per seam in the whole journal), the TCP within the scenario's bars. Results
to ``--json`` (default ``benchmarks/results/interrupts.json``); docs/journal.md quotes them.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from cell.journal import read_journal

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results"
CELL = str(Path(sys.executable).with_name("cell"))
TCP_RMS_BAR_MM, TCP_MAX_BAR_MM = 0.3, 0.5  # fence1's bars (tests/scenario/test_turnover.py: rms measured <= 0.09)

WALL = [(s, t) for s in ("SIGINT", "SIGTERM", "SIGHUP") for t in (5.0, 10.0, 15.0)] + [("SIGKILL", 10.0)]
HOOKS = [
    ("SIGINT", "located"),  # side A located, nothing planned
    ("SIGTERM", "planned"),  # side A planned, no arc yet
    ("SIGHUP", "arc_on@3"),  # during side A's third weld: the seam is finished, then the job stops
    ("SIGTERM", "arc_off@12"),  # side A done, before the turn
    ("SIGINT", "turned"),  # the part turned, side B not captured
    ("SIGHUP", "arc_on@14"),  # during side B's second weld
    ("SIGINT", "output@1"),  # during the writes: the report written, the programs not yet
    ("SIGTERM", "output@2"),  # during the writes: the programs written
    ("SIGHUP", "output@1"),
    ("SIGKILL", "arc_on@5"),  # killed with the arc on: the seam's bead never finished
]
QUICK_WALL, QUICK_HOOKS = [("SIGTERM", 10.0)], [("SIGHUP", "arc_on@3"), ("SIGINT", "turned"), ("SIGKILL", "arc_on@5")]


def _weld(folder: Path, scenario: str, *more: str, env: dict[str, str] | None = None) -> subprocess.Popen[bytes]:
    cmd = [CELL, "weld", scenario, "--json", "r.json", "--krl", "k/", *more]
    return subprocess.Popen(cmd, cwd=folder, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)


def _last_line(p: subprocess.Popen[bytes]) -> str:
    err = p.stderr.read().decode(errors="replace") if p.stderr is not None else ""
    lines = [ln for ln in err.strip().splitlines() if ln.strip()]
    return lines[-1] if lines else ""


def _arcs(path: Path) -> dict[str, dict[str, Any]]:
    """Per seam, its completed weld in a journal: run, side, arc times, TCP error."""
    st = read_journal(path)
    return {k: {"run": w.run, "side": w.side, "on": w.t_on_s, "off": w.t_off_s, "rms": w.tcp_rms_mm,
                "max": w.tcp_max_mm} for k, w in st.welds.items()}  # fmt: skip


def _reference(scenario: str) -> tuple[dict[str, dict[str, Any]], float]:
    with tempfile.TemporaryDirectory() as d:
        t = time.perf_counter()
        p = _weld(Path(d), scenario)
        p.wait()
        if p.returncode != 0:
            raise SystemExit(f"the uninterrupted run failed (exit {p.returncode}): {_last_line(p)}")
        return _arcs(Path(d) / "r.journal.jsonl"), time.perf_counter() - t


def _case(scenario: str, sig: str, when: float | str, ref: dict[str, dict[str, Any]]) -> dict[str, Any]:
    with tempfile.TemporaryDirectory() as d:
        folder = Path(d)
        env = dict(os.environ)
        if isinstance(when, str):
            env["CELL_JOURNAL_SIGNAL"] = f"{when}={sig}"
        t0 = time.perf_counter()
        p = _weld(folder, scenario, env=env)
        if isinstance(when, float):
            try:
                p.wait(timeout=when)
            except subprocess.TimeoutExpired:
                p.send_signal(getattr(signal, sig))
        p.wait()
        out: dict[str, Any] = {"signal": sig, "at": when, "exit": p.returncode, "last_line": _last_line(p)}
        out["stopped_s"] = round(time.perf_counter() - t0, 2)
        journal = folder / "r.journal.jsonl"
        if not journal.exists():  # stopped before the command began its job (Python still starting): nothing done
            out.update(before_job=True, welded_before_resume=0, resume=None, journal_matches_execution=True)
            out["exit_ok"] = p.returncode in (128 + getattr(signal, sig), -getattr(signal, sig))
            return out
        st = read_journal(journal)
        out["stages"] = [r["kind"] for r in st.records if r["kind"] not in ("journal", "arc_on", "arc_off")]
        out["journal_warnings"] = list(st.warnings)
        welded = set(st.welds)
        out["welded_before_resume"] = len(welded)
        out["interrupted_seams"] = sorted(st.interrupted)
        out["finished_before_signal"] = p.returncode == 0
        out["exit_ok"] = p.returncode in (0, 128 + getattr(signal, sig), -getattr(signal, sig))
        out["journal_matches_execution"] = all(
            all(w[k] == ref[s][k] for k in ("on", "off", "rms", "max")) for s, w in _arcs(journal).items()
        )
        rep_path = folder / "r.json"
        if sig != "SIGKILL":
            try:
                rep = json.loads(rep_path.read_text())
                listed = {s["id"] for s in rep["seams"] if s.get("welded")}
                out["report_parses"] = True
                out["report_matches_journal"] = listed == welded and rep.get("welded") == len(welded)
                out["report_last_line_names_signal"] = sig in out["last_line"] or out["finished_before_signal"]
            except (OSError, ValueError, KeyError) as e:
                out["report_parses"], out["report_matches_journal"] = False, False
                out["report_error"] = str(e)
        if not st.resumable:
            out["resume"] = None
            return out
        t1 = time.perf_counter()
        r = _weld(folder, scenario, "--resume", "r.journal.jsonl")
        r.wait()
        res: dict[str, Any] = {
            "exit": r.returncode,
            "last_line": _last_line(r),
            "time_s": round(time.perf_counter() - t1, 2),
        }
        st2 = read_journal(journal)
        offs: dict[str, int] = {}
        for rec in st2.records:
            if rec["kind"] == "arc_off" and rec.get("complete", True):
                offs[rec["seam"]] = offs.get(rec["seam"], 0) + 1
        res["welded_total"] = len(st2.welds)
        res["welded_twice"] = sorted(k for k, n in offs.items() if n > 1)
        res["welded_by_resume"] = sorted(k for k, w in st2.welds.items() if w.run != "r1")
        res["rest_exactly"] = set(res["welded_by_resume"]) == set(ref) - welded
        rms = [w.tcp_rms_mm for w in st2.welds.values() if w.tcp_rms_mm is not None]
        mx = [w.tcp_max_mm for w in st2.welds.values() if w.tcp_max_mm is not None]
        res["tcp_rms_max_mm"], res["tcp_max_max_mm"] = max(rms, default=None), max(mx, default=None)
        res["tcp_within_bars"] = bool(rms) and max(rms) <= TCP_RMS_BAR_MM and max(mx) <= TCP_MAX_BAR_MM
        try:
            final = json.loads(rep_path.read_text())
            res["report_welded"] = final.get("welded")
            res["report_runs"] = sorted({str(s.get("run")) for s in final["seams"] if s.get("welded")})
        except (OSError, ValueError) as e:
            res["report_welded"], res["report_error"] = None, str(e)
        out["resume"] = res
        return out


def _ok(case: dict[str, Any], n: int) -> bool:
    res = case.get("resume")
    stopped_ok = case["exit_ok"] and case["journal_matches_execution"]
    if case["signal"] != "SIGKILL":
        stopped_ok = stopped_ok and case.get("report_parses", False) and case.get("report_matches_journal", False)
    if case.get("before_job"):
        return bool(case["exit_ok"])
    if res is None:
        return stopped_ok and case["finished_before_signal"]
    return (
        stopped_ok
        and res["exit"] == 0
        and res["welded_total"] == n
        and not res["welded_twice"]
        and res["rest_exactly"]
        and res["tcp_within_bars"]
        and res["report_welded"] == n
    )


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", default="fence1")
    ap.add_argument("--quick", action="store_true", help="three hook cases and one wall-time case")
    ap.add_argument("--only", choices=("all", "hooks", "wall"), default="all", help="which cases")
    ap.add_argument("--json", type=Path, default=RESULTS / "interrupts.json")
    args = ap.parse_args()
    ref, ref_s = _reference(args.scenario)
    n = len(ref)
    print(f"uninterrupted: {n} seams welded in {ref_s:.1f} s", flush=True)
    cases = []
    hooks = (QUICK_HOOKS if args.quick else HOOKS) if args.only != "wall" else []
    wall = (QUICK_WALL if args.quick else WALL) if args.only != "hooks" else []
    for sig, when in [*hooks, *wall]:
        c = _case(args.scenario, sig, when, ref)
        c["ok"] = _ok(c, n)
        cases.append(c)
        res = c.get("resume") or {}
        print(f"{sig:8s} at {when!s:10s} exit {c['exit']:4d} welded {c['welded_before_resume']:2d} "
              f"resume exit {res.get('exit')} total {res.get('welded_total')} twice {res.get('welded_twice')} "
              f"ok {c['ok']}", flush=True)  # fmt: skip
    out = {
        "command": " ".join(["benchmarks/bench_interrupts.py", *sys.argv[1:]]),
        "scenario": args.scenario,
        "seams": n,
        "uninterrupted_s": round(ref_s, 2),
        "bars_mm": {"tcp_rms": TCP_RMS_BAR_MM, "tcp_max": TCP_MAX_BAR_MM},
        "cases": cases,
        "all_ok": all(c["ok"] for c in cases),
        "passed": sum(c["ok"] for c in cases),
    }
    args.json.parent.mkdir(parents=True, exist_ok=True)
    args.json.write_text(json.dumps(out, indent=1) + "\n")
    print(f"{out['passed']}/{len(cases)} cases ok -> {args.json}")
    return 0 if out["all_ok"] else 1


if __name__ == "__main__":
    raise SystemExit(main())
