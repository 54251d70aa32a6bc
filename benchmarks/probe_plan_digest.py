"""Every plan ``cell weld fence1-positioner`` and ``cell weld fence1`` make, as a digest: per call of the planner
(``cell.pipeline.weld.plan_for``) the welding order, each seam's outcome (feasible, code, reason) and a SHA-256 of
every segment's kind, seam, timing and trajectory samples, with the gate's violations. Two checkouts that print
the same digests plan the same motions to the bit (a speed-up that must change no plan: docs/positioner.md,
"Planning time").

    PYTHONPATH=. .venv/bin/python benchmarks/probe_plan_digest.py [--json PATH] [--only fence1-positioner]
"""

from __future__ import annotations

import argparse
import hashlib
import importlib
import json
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from cell import scenario as sc


def digest(plan: Any, pre: Any, violations: Any) -> dict[str, Any]:
    """A plan's order, outcomes and SHA-256 of its segments' and the move before it's samples."""
    h = hashlib.sha256()
    for tr in [pre, *(s.trajectory for s in plan.segments)]:
        h.update(np.ascontiguousarray(tr.q, dtype=float).tobytes())
        h.update(np.ascontiguousarray(tr.times, dtype=float).tobytes())
    for s in plan.segments:
        h.update(f"{s.kind}|{s.seam_id}|{s.t0!r}|{s.speed!r}|{s.arc_on}|{s.zone_m!r}|{s.link_s!r}".encode())
    return {
        "order": list(plan.order),
        "seams": [[o.seam_id, o.feasible, str(o.code), o.reason] for o in plan.seams],
        "cycle_s": plan.cycle_time,
        "segments": len(plan.segments),
        "violations": [str(v) for v in violations],
        "sha256": h.hexdigest(),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", type=Path)
    ap.add_argument("--only", choices=("fence1-positioner", "fence1"))
    args = ap.parse_args()
    weld = importlib.import_module("cell.pipeline.weld")  # the module (the package's ``weld`` is its function)
    inner, calls, cpu = weld.plan_for, [], [0.0]

    def recorded(*a: Any, **k: Any) -> Any:
        t = time.process_time()
        out = inner(*a, **k)
        cpu[0] += time.process_time() - t
        calls.append(digest(*out))
        return out

    weld.plan_for = recorded
    out: dict[str, Any] = {}
    for name in ("fence1-positioner", "fence1"):
        if args.only not in (None, name):
            continue
        calls.clear()
        cpu[0] = 0.0
        if name == "fence1":
            from cell.pipeline.turnover import weld_part

            weld_part(sc.load(name))
        else:
            from cell.pipeline.positioned import weld_on_positioner

            weld_on_positioner(sc.load(name))
        out[name] = {"plan_cpu_s": round(cpu[0], 3), "plans": list(calls)}
        print(name, f"plan CPU {cpu[0]:.2f} s", *(c["sha256"][:12] for c in calls), file=sys.stderr)
    text = json.dumps(out, indent=1)
    if args.json:
        args.json.write_text(text + "\n")
    else:
        print(text)


if __name__ == "__main__":
    main()
