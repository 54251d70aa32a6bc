"""Nonsense scenarios against ``cell scenario check``: how many are refused in one line, flagged by a warning the
shipped scenario does not have, silently accepted, or end in a traceback.

    .venv/bin/python benchmarks/bench_fuzz_scenarios.py [--n 228] [--seed 0] [--json PATH]

Each of the N scenarios is a seeded mutation of a shipped one (tools/scenario_fuzz.py: every kind in turn: a camera
absurdly far, inside the table, looking away or out of range; the robot inside the table, upside down, facing away;
a scan pose out of reach; a home outside the joints' limits; a seed as text; a loose weld gate; a part drawn in the
air; random value, shape and key corruption; a deleted required key; a key given twice; broken YAML). The counts,
per kind, and every mutant not refused or flagged go to ``--json`` (default
``benchmarks/results/fuzz_scenarios.json``); docs/results.md quotes them. The suite runs a sample of 30
(tests/unit/test_fuzz_scenarios.py).
"""

from __future__ import annotations

import argparse
import resource
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tools"))

import scenario_fuzz as fuzz

from cell.export.reports.report import write_json

RESULTS = Path(__file__).resolve().parent / "results"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=12 * len(fuzz.KINDS), help="how many nonsense scenarios")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--json", type=Path, default=RESULTS / "fuzz_scenarios.json")
    args = ap.parse_args()
    t0 = time.perf_counter()
    verdicts = []
    for m in fuzz.mutants(args.seed, args.n):
        v = fuzz.judge(m)
        verdicts.append(v)
        if v.verdict in ("silent", "traceback"):
            print(f"{v.verdict}: {m.index} {m.source} {m.kind}: {m.what}", flush=True)
    s = fuzz.summary(verdicts)
    peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    out = {
        "command": f".venv/bin/python benchmarks/bench_fuzz_scenarios.py --n {args.n} --seed {args.seed}",
        "seed": args.seed,
        "sources": list(fuzz.SOURCES),
        "kinds": list(fuzz.KINDS),
        "seconds": round(time.perf_counter() - t0, 1),
        "peak_rss_mb": round(peak_mb, 0),
        **s,
    }
    write_json(args.json, out)
    print(
        f"{s['n']} nonsense scenarios: {s['refused']} refused in one line, {s['flagged']} flagged by scenario check, "
        f"{s['silent']} silently accepted, {s['traceback']} tracebacks; {out['seconds']} s, peak {peak_mb:.0f} MB"
    )
    return 0 if s["silent"] == 0 and s["traceback"] == 0 else 1


if __name__ == "__main__":
    raise SystemExit(main())
