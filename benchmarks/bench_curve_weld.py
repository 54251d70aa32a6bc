"""Curved seams welded from truth-built estimates: the torch along each curved seam of the round scenarios, planned,
gated, executed in the simulator and measured against the TRUE curve (not against what was planned).

    .venv/bin/python benchmarks/bench_curve_weld.py [--scenarios pipe-flange,railing,round-brace,tube-tee]
        [--json benchmarks/results/curve_weld.json]
    .venv/bin/python benchmarks/bench_curve_weld.py --located [--json benchmarks/results/curve_weld_located.json]
    .venv/bin/python tools/readme_results.py   # their tables in docs/results.md

``--located``: the real pipeline, as ``cell weld NAME --sides first`` runs it (the curves LOCATED, re-scan, plan with
the straight seams, gate, execute), per curved seam: welded (in how many arcs) or why not, the TCP against the true
curve; the KRL program's CIRC moves and ``cell krl check``'s findings, the RAPID program's ArcC.

Until the curve locator lands, the planner is fed estimates built from the truth (:func:`truth_estimates`: the true
curve of the as-built part in R, sampled every 2 mm, with the two faces' normals from the aligned map and a 0.1 mm
sigma); so these figures measure the torch path, its timing and its execution, not the location. Per scenario the
cell is captured and perceived once (no close-up re-scan), the curves are planned with the found straight seams left
out (``plan_for(..., skip=all, curves=...)``), gated and executed; per curved seam: planned or why not, the weld's
length, its arc time, and the TCP's distance to the true curve while the arc burns (RMS and max).
"""

from __future__ import annotations

import argparse
import json
import math
import time
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from cell.geometry import FloatArray
from cell.types import CurvedSeam, Part, SeamStatus, Surface, WeldMap
from cell.types.curve_estimate import CurveEstimate

if TYPE_CHECKING:
    from cell.types.execution import Execution
    from cell.types.plan import SeamOutcome, WeldPlan

STEP_M = 0.002  # [m] the truth-built estimate's samples
SIGMA_M = 0.0001  # [m] its sigma across the seam
SCENARIOS = ("pipe-flange", "railing", "round-brace", "tube-tee")
OUT = Path(__file__).resolve().parent / "results" / "curve_weld.json"
OUT_LOCATED = Path(__file__).resolve().parent / "results" / "curve_weld_located.json"


def _normals(part: Part, surface: Surface, p_R: FloatArray) -> FloatArray:
    """(n, 3) the outward unit normals of ``part``'s surface (its cylinder's side, or its flat face holding the
    points) at p_R (n, 3)."""
    from cell.weldmap.curved_joints import holding_face, surface_normals

    face = None if surface is Surface.CYLINDER else holding_face(part, p_R)
    if surface is not Surface.CYLINDER and face is None:
        raise ValueError(f"no face of {part.name} holds the curve")
    return surface_normals(part, surface, face, p_R)


def truth_estimate(
    seam_R: CurvedSeam, weldmap_R: WeldMap, truth_R: FloatArray, step_m: float = STEP_M
) -> CurveEstimate:
    """A found :class:`CurveEstimate` built from the true curve truth_R (n, 3) in R: samples ``step_m`` apart along
    it (a closed curve's last point dropped), the faces' normals of the aligned map's parts at them."""
    joint = seam_R.joint
    assert joint is not None
    p = np.asarray(truth_R, dtype=float)
    closed = bool(seam_R.curve.closed)
    if closed and np.linalg.norm(p[-1] - p[0]) < 1e-6:
        p = p[:-1]
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))])
    total = s[-1] + (float(np.linalg.norm(p[0] - p[-1])) if closed else 0.0)
    n = max(3, math.ceil(total / step_m))
    u = np.linspace(0.0, total, n, endpoint=not closed)
    loop = np.vstack([p, p[:1]]) if closed else p
    s_loop = np.concatenate([s, [total]]) if closed else s
    q = np.column_stack([np.interp(u, s_loop, loop[:, j]) for j in range(3)])
    n_a = _normals(weldmap_R.part(joint.abutting), joint.abutting_surface, q)
    n_b = _normals(weldmap_R.part(joint.receiving), joint.receiving_surface, q)
    return CurveEstimate(
        seam_R.id, SeamStatus.FOUND, "built from the truth", None, q, n_a, n_b, closed, np.full(len(q), SIGMA_M),
        (0.0, 0.0) if closed else (SIGMA_M, SIGMA_M), 1.0,
    )  # fmt: skip


def truth_estimates(weldmap_R: WeldMap, truths_R: Mapping[str, FloatArray]) -> list[CurveEstimate]:
    """:func:`truth_estimate` of every curved seam of the aligned map with a truth."""
    return [truth_estimate(c, weldmap_R, truths_R[c.id]) for c in weldmap_R.curved if c.id in truths_R]


def bench(name: str) -> dict[str, Any]:
    """One scenario: each curved seam planned, executed and measured against its true curve."""
    from cell import pipeline
    from cell import scenario as sc
    from cell.pipeline.detect import read_weldmap
    from cell.pipeline.geometry import motion_scene, open_cell
    from cell.pipeline.outcomes import curve_welds
    from cell.pipeline.weld import execute, plan_for

    s = sc.load(name)
    weldmap = read_weldmap(s)
    with open_cell(s, weldmap) as station:
        det = pipeline.detect(s, station=station, weldmap=weldmap)
        assert det.scene is not None and station.arm is not None
        curves = truth_estimates(det.scene.seam_scene.weldmap, det.curve_truths)
        t0 = time.perf_counter()
        plan, pre, problems = plan_for(
            station, det, skip={e.id for e in det.estimates}, motion=motion_scene(station.arm, det), curves=curves
        )
        plan_s = time.perf_counter() - t0
        ex = execute(station, plan, pre) if not problems and plan.segments else None
    closed, ests = {c.id: c.closed for c in curves}, {c.id: c for c in curves}
    welds = curve_welds(plan, ex, pre.duration, det.curve_truths, closed, s.X_WR, ests)
    rows = []
    for c in curves:
        o = plan.outcome(c.id)
        q = welds.get(c.id)
        rows.append(
            {
                "seam": c.id,
                "closed": c.closed,
                "length_mm": round(c.length_m * 1000.0, 1),
                "planned": o.feasible,
                "arcs": sum(1 for g in plan.segments if g.arc_on and g.seam_id == c.id),
                "reason": o.reason,
                "welded": q is not None and not o.partial,  # whole: a curve welded in part is ``partial``
                "tcp_rms_mm": round(q.tcp_rms_mm, 3) if q else None,
                "tcp_max_mm": round(q.tcp_max_mm, 3) if q else None,
                "weld_length_mm": round(q.length_mm, 1) if q else None,
                "arc_s": round(q.weld_time_s, 2) if q else None,
                "speed_mm_s": round(q.speed_mm_s, 2) if q else None,
                "unwelded_mm": round(q.short_start_mm + q.short_end_mm, 2) if q else None,
                **_in_part(o, _root_stretches(plan, ex, pre.duration, c.id, det.curve_truths.get(c.id), s.X_WR)),
            }
        )
    return {
        "scenario": name,
        "gate": [str(v) for v in problems],
        "plan_s": round(plan_s, 2),
        "seams": rows,
    }


def _root_stretches(
    plan: WeldPlan, ex: Execution | None, pre_s: float, sid: str, truth_R: FloatArray | None, X_WR: FloatArray
) -> list[tuple[float, float]] | None:
    """The stretches along the true curve the executed root pass of seam ``sid`` leaves unwelded (from, to) [m]
    (:func:`cell.process.curve_quality.unwelded_stretches`); None where nothing of it was welded."""
    from cell.geometry import invert, transform_points
    from cell.process.curve_quality import unwelded_stretches

    welds = [g for g in plan.segments if g.arc_on and g.seam_id == sid and g.pass_index == 0]
    if ex is None or truth_R is None or not welds:
        return None
    on = np.zeros(len(ex.times), dtype=bool)
    for g in welds:
        on |= (ex.times >= pre_s + g.t0 - 1e-9) & (ex.times <= pre_s + g.t1 + 1e-9)
    tcp_R = transform_points(invert(np.asarray(X_WR, dtype=float)), ex.tcp_W[on])
    truth = np.asarray(truth_R, dtype=float)
    closed = bool(np.linalg.norm(truth[0] - truth[-1]) < 0.01)
    return unwelded_stretches(tcp_R, truth, closed)


def _in_part(o: SeamOutcome, measured: list[tuple[float, float]] | None) -> dict[str, Any]:
    """A curved seam's share welded, its planned remainder (each stretch [mm] along the located curve, its code
    and why) and the stretches the executed root pass left unwelded along the true curve [mm]."""
    return {
        "partial": o.partial,
        "share": round(o.share, 4) if o.feasible else 0.0,
        "remainder_mm": round(sum(r.length_m for r in o.remainder) * 1000.0, 1) if o.feasible else None,
        "remainder": [
            {
                "from_mm": round(r.from_m * 1000.0, 1),
                "to_mm": round(r.to_m * 1000.0, 1),
                "code": r.code.value,
                "why": r.why,
            }
            for r in o.remainder
        ],
        "measured_unwelded_mm": None
        if measured is None
        else [[round(a * 1000.0, 1), round(b * 1000.0, 1)] for a, b in measured],
    }


def bench_located(name: str) -> dict[str, Any]:
    """One scenario through ``cell weld NAME --sides first``'s pipeline: each curved seam located, planned with the
    rest, executed and measured against its true curve; the programs' circular moves and the KRL check."""
    import re

    from cell import scenario as sc
    from cell.export.checks.program import Program, check_program
    from cell.export.checks.read import read_krl
    from cell.export.krl import krl_program
    from cell.export.program import ProgramJob
    from cell.export.rapid import rapid_text
    from cell.pipeline.job import WeldJob
    from cell.pipeline.weld import weld

    t0 = time.perf_counter()
    run = weld(sc.load(name), WeldJob(sides="first"))
    total_s = time.perf_counter() - t0
    det, plan = run.detection, run.plan
    rows = []
    for c in det.curve_estimates:
        w = det.curve_welds.get(c.id)
        m = det.curve_metrics.get(c.id)
        q = w.quality if w is not None else None
        arcs = sum(1 for g in plan.segments if g.arc_on and g.seam_id == c.id) if plan is not None else 0
        o = plan.outcome(c.id) if plan is not None and any(x.seam_id == c.id for x in plan.seams) else None
        rows.append(
            {
                "seam": c.id,
                "closed": c.closed,
                "located": c.status is SeamStatus.FOUND,
                "located_rms_mm": round(m.rms_mm, 3) if m else None,
                "located_max_mm": round(m.max_mm, 3) if m else None,
                "length_mm": round(c.length_m * 1000.0, 1) if c.status is SeamStatus.FOUND else None,
                "planned": bool(w and w.planned),
                "welded": bool(w and w.welded),
                "arcs": arcs,
                "reason": (o.reason if o is not None and not o.feasible else (w.reason if w else c.reason)),
                "code": (str(w.plan_code or w.code) if w is not None and not w.welded else None),
                "partial": bool(w and w.partial),  # welded in part: its share and the length left for a manual weld
                "share": round(w.share, 4) if w is not None and w.partial else None,
                "remainder_mm": round(w.manual_m * 1000.0, 1) if w is not None and w.partial else None,
                "tcp_rms_mm": round(q.tcp_rms_mm, 3) if q else None,
                "tcp_max_mm": round(q.tcp_max_mm, 3) if q else None,
                "unwelded_mm": round(q.short_start_mm + q.short_end_mm, 2) if q else None,
                "arc_s": round(q.weld_time_s, 2) if q else None,
            }
        )
    programs: dict[str, Any] = {}
    if plan is not None and run.arm is not None and plan.segments:
        src, dat = krl_program(plan, run.arm.model, "CURVE")
        p = Program("CURVE", read_krl(src, "src"), read_krl(dat, "dat"), "CURVE.src", "CURVE.dat")
        rapid = rapid_text(ProgramJob(plan, run.arm.model, "CURVE"))
        programs = {
            "krl_circ": len(re.findall(r"^CIRC ", src, re.M)),
            "krl_check": sorted({f.code for f in check_program(p)}),
            "rapid_arcc": len(re.findall(r"^\s+ArcC(End)? ", rapid, re.M)),
        }
    straight = [w for w in run.seams]
    return {
        "scenario": name,
        "straight_welded": sum(w.welded for w in straight),
        "straight_seams": len(straight),
        "error": run.error.message if run.error is not None else None,
        "total_s": round(total_s, 1),
        "programs": programs,
        "seams": rows,
    }


def main(argv: Sequence[str] | None = None) -> None:
    from cell.provenance import git_commit

    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scenarios", default=",".join(SCENARIOS))
    ap.add_argument("--json", type=Path, default=None)
    ap.add_argument("--located", action="store_true", help="through cell weld's pipeline, the curves located")
    args = ap.parse_args(argv)
    args.json = args.json or (OUT_LOCATED if args.located else OUT)
    rows = [(bench_located if args.located else bench)(n) for n in args.scenarios.split(",")]
    command = "benchmarks/bench_curve_weld.py" + (" --located" if args.located else "")
    command += f" --scenarios {args.scenarios}" if args.scenarios != ",".join(SCENARIOS) else ""
    out = {"command": f".venv/bin/python {command}", "commit": git_commit(), "rows": rows}
    args.json.write_text(json.dumps(out, indent=2) + "\n")
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
