"""A pipe stub's circular fillet welded on a positioner by coordinated motion: ``cell weld pipe-stub-positioner`` as
the cell runs it (the located curve re-scanned up close at home, the weld gate's word on it, the coordinated weld);
should the gate refuse it, the first located curve planned, played and measured as a study (docs/positioner.md,
"Coordinated motion"). Then the same of ``tube-tee-positioner``'s saddle (``tube_tee``: the tilt following the
seam as well), with every seam of that cell and why it was not welded; and every seam of ``round-brace-positioner``
(``round_brace``: the leaning brace's elliptical feet) welded or why not; the curves welded in part with the part
turning (``in_part``: tube-tee's end-plate circles, the brace's foot), each measured as a weld.

    .venv/bin/python benchmarks/bench_coordinated.py [--json PATH] [--noise realistic|small]

Per run: the located curve's sigma and its error against the truth, the gate's word; the coordinated weld's TCP
RMS / max against the true curve the part carries (in the part's frame), its speed along the part, the torch's
spread, the tilt and the rotate axis's sweep, every waypoint's ISO 6947 slope and rotation (worst of them), the
arc time, the job's time and the planning's wall time; the programs' moves (circular or chords, in the turning base),
the weld's knots' largest distance from them as the controller runs them and the planned axes' from the
controller's synchronous interpolation (default ``benchmarks/results/coordinated.json``).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

RESULTS = Path(__file__).resolve().parent / "results"
SCENARIO = "pipe-stub-positioner"
TEE, SADDLE = "tube-tee-positioner", "BRANCH>RUN:saddle"  # the saddle: the tilt follows its turning bisector
BRACE = "round-brace-positioner"  # the brace's foot welded in part (torch vs POST at its toe); its top refused


def _say(msg: str) -> None:
    print(f"· {msg}", file=sys.stderr, flush=True)


def _seams(run: Any) -> list[dict[str, Any]]:
    """Every seam of the cell's run (a PositionerRun): welded or why not (its code and sentence), its TCP RMS and
    max; a curve welded in part, the share welded and what is left for a manual weld [mm]."""
    welds, out = run.welds(), []
    for sid in run.seam_ids():
        w = welds.get(sid)
        q = w.quality if w is not None else None
        code = w.code if w is not None else run.unheld_codes.get(sid)
        row = {"id": sid, "welded": bool(w and w.welded), "code": code.value if code else None,
               "reason": w.reason if w is not None else run.unheld.get(sid, ""),
               "tcp_rms_mm": round(q.tcp_rms_mm, 3) if q is not None else None,
               "tcp_max_mm": round(q.tcp_max_mm, 3) if q is not None else None}  # fmt: skip
        if w is not None and w.partial:
            row |= {"share": round(w.share, 4), "manual_mm": round(w.manual_m * 1000.0, 1)}
        out.append(row)
    return out


def _in_part(run: Any) -> list[dict[str, Any]]:
    """Each curve of the cell's run welded in part with the part turning: the stretch welded (from, to along the
    located curve [mm]) and its share, the TCP RMS / max against the true curve, the weld's ISO 6947 position at
    its waypoints (worst slope, rotation off 180), the axes, the times, the programs' moves (chords or circles in
    the turning base, the knots' distance from them, E2/E3 against the controller's interpolation) and what is
    left for a manual weld (each stretch, its code and why)."""
    from cell.export.coordinated_program import coordinated_moves, program_path_off
    from cell.export.reports.positioner_report import coordinated_entry

    welds, out = run.welds(), []
    for cw in run.coordinated:
        w = welds.get(cw.seam_id)
        arcs = [a for a in run.coordinated if a.seam_id == cw.seam_id]
        if arcs[0] is not cw or (not cw.remainder and len(arcs) == 1) or w is None or w.quality is None:
            continue
        e, q, moves = coordinated_entry(cw), w.quality, coordinated_moves(cw)
        out.append({
            "curve": cw.seam_id, "span_mm": e["span_mm"], "share": round(cw.share, 4),
            "tcp_rms_mm": round(q.tcp_rms_mm, 3), "tcp_max_mm": round(q.tcp_max_mm, 3),
            "slope_worst_deg": round(float(np.abs(cw.slope_deg).max()), 3),
            "rotation_worst_off_deg": round(float(np.abs(np.asarray(cw.rotation_deg) - 180.0).max()), 3),
            "in_position": cw.in_position, "tilt_range_deg": e["tilt_range_deg"], "rotate_deg": e["rotate_deg"],
            "arc_s": e["arc_s"], "job_s": e["job_s"], "plan_wall_s": e["plan_wall_s"],
            "program_moves": {k: sum(mv.kind == k for mv in moves) for k in ("CIRC", "LIN")},
            "program_path_off_mm": round(program_path_off(cw, moves) * 1000.0, 4),
            "program_axes_off_deg": round(math.degrees(max(mv.axes_dev for mv in moves)), 4),
            "arcs": [_arc_row(a, aq) for a, aq in zip(arcs, w.arc_quality or (q,), strict=False)],
            "remainder": [{"from_mm": round(r.from_m * 1000.0, 1), "to_mm": round(r.to_m * 1000.0, 1),
                           "code": r.code.value, "why": r.why} for r in cw.remainder],
        })  # fmt: skip
    return out


def _arc_row(cw: Any, q: Any) -> dict[str, Any]:
    """One coordinated arc of a curve welded in several (the first's figures above are its own; the TCP there the
    seam's over all its arcs): its stretch along the located curve [mm], its TCP against the true curve, its times
    and its program's moves."""
    from cell.export.coordinated_program import coordinated_moves, program_path_off
    from cell.export.reports.positioner_report import coordinated_entry

    e, moves = coordinated_entry(cw), coordinated_moves(cw)
    return {"span_mm": e["span_mm"], "tcp_rms_mm": round(q.tcp_rms_mm, 3), "tcp_max_mm": round(q.tcp_max_mm, 3),
            "tilt_range_deg": e["tilt_range_deg"], "rotate_deg": e["rotate_deg"], "arc_s": e["arc_s"],
            "job_s": e["job_s"], "plan_wall_s": e["plan_wall_s"],
            "program_moves": {k: sum(mv.kind == k for mv in moves) for k in ("CIRC", "LIN")},
            "program_path_off_mm": round(program_path_off(cw, moves) * 1000.0, 4)}  # fmt: skip


def coordinated_row(
    noise: str | None = None, program: Path | None = None, scenario: str = SCENARIO, curve: str | None = None
) -> dict[str, Any]:
    """The located curve (``curve``, default the first), the gate's word and the coordinated weld measured (a study
    when the gate refuses); ``program``: a folder for its KRL program (``krl/``) and RAPID module (``rapid/``)."""
    from cell import scenario as sc
    from cell.export.coordinated_program import coordinated_moves, program_path_off
    from cell.export.reports.positioner_report import coordinated_entry
    from cell.pipeline.coordinated import weld_curves_coordinated
    from cell.pipeline.curved.welds import curve_doubt
    from cell.pipeline.detect import detect, read_weldmap
    from cell.pipeline.geometry import open_cell
    from cell.pipeline.positioned import weld_on_positioner
    from cell.seams.curved.metrics import curve_error

    s = sc.load(scenario)
    s = s.with_noise(noise) if noise else s
    assert s.robot.positioner is not None
    pos = s.robot.positioner.positioner(s.X_WR)
    pick = lambda cs: next(c for c in cs if curve is None or c.id == curve)  # noqa: E731
    t = time.perf_counter()
    run = weld_on_positioner(s)  # what `cell weld` runs: detect, the close-ups at home, the coordinated weld
    det = run.detection
    c = pick(det.curve_estimates)
    doubt = curve_doubt(c, s)
    err = curve_error(c, np.asarray(det.curve_truths[c.id]))
    welds = [w for g in run.groups for w in g.seams if w.id == c.id and w.welded]
    mine = [cw for cw in run.coordinated if cw.seam_id == c.id]
    if mine and welds:
        cw, weld = mine[0], welds[0]
    else:  # the gate refused it: the same located curve planned, played and measured as a study
        wm = read_weldmap(s)
        with open_cell(s, wm) as station:
            assert station.arm is not None
            det = detect(s, "ours", station=station, weldmap=wm)
            c = pick(det.curve_estimates)
            done, _ = weld_curves_coordinated(station, det, pos, station.arm.q_scan, refuse_doubtful=False)
        _, weld, study, _ = next(d for d in done if d[1].id == c.id)
        assert study is not None
        cw = study
    assert weld.quality is not None
    if program is not None:
        from cell.export.coordinated_program import write_coordinated_programs
        from cell.motion.robot import RobotModel
        from cell.station.arm import robot_urdf

        robot = RobotModel.from_urdf(robot_urdf(s))
        for controller in ("krl", "rapid"):
            (program / controller).mkdir(parents=True, exist_ok=True)
            write_coordinated_programs(controller, [cw], robot, pos, scenario.replace("-", "_"), program / controller)
    q = weld.quality
    entry = coordinated_entry(cw)
    moves = coordinated_moves(cw)
    return {
        "scenario": scenario,
        "noise": noise or "realistic",
        "curve": c.id,
        "located_sigma_max_mm": round(c.sigma_max_m * 1000.0, 3),
        "located_error_rms_mm": round(err.rms_mm, 3),
        "located_error_max_mm": round(err.max_mm, 3),
        "gate": "refused: " + doubt.detail if doubt is not None else "passed",
        "welded_by_the_cell": doubt is None,
        "tcp_rms_mm": round(q.tcp_rms_mm, 3),
        "tcp_max_mm": round(q.tcp_max_mm, 3),
        "speed_mm_s": round(q.speed_mm_s, 2),
        "loop_unwelded_mm": round(q.short_start_mm, 1),
        "slope_worst_deg": round(float(np.abs(cw.slope_deg).max()), 3),
        "rotation_worst_off_deg": round(float(np.abs(np.asarray(cw.rotation_deg) - 180.0).max()), 3),
        "in_position": cw.in_position,
        "tilt_deg": entry["tilt_deg"],
        "tilt_range_deg": entry["tilt_range_deg"],
        "rotate_deg": entry["rotate_deg"],
        "torch_spread_mm": entry["torch_spread_mm"],
        "arc_s": entry["arc_s"],
        "job_s": entry["job_s"],
        "plan_wall_s": entry["plan_wall_s"],
        "program_moves": {k: sum(mv.kind == k for mv in moves) for k in ("CIRC", "LIN")},
        "program_path_off_mm": round(program_path_off(cw, moves) * 1000.0, 4),
        "program_axes_off_deg": round(math.degrees(max(mv.axes_dev for mv in moves)), 4),
        "wall_s": round(time.perf_counter() - t, 1),
        "seams": _seams(run),
        "in_part": _in_part(run),
        "waypoints": entry["waypoints"],
    }


def seams_row(noise: str | None = None, scenario: str = BRACE) -> dict[str, Any]:
    """``cell weld``'s run of ``scenario`` on its positioner: every seam welded or why not, and the run's wall time
    (a cell whose curves are all refused, so no coordinated weld to measure)."""
    from cell import scenario as sc
    from cell.pipeline.positioned import weld_on_positioner

    s = sc.load(scenario)
    s = s.with_noise(noise) if noise else s
    t = time.perf_counter()
    run = weld_on_positioner(s)
    return {"scenario": scenario, "noise": noise or "realistic", "wall_s": round(time.perf_counter() - t, 1),
            "seams": _seams(run), "in_part": _in_part(run)}  # fmt: skip


WEAVE = {"pattern": "zigzag", "width_mm": 3.0, "frequency_hz": 1.0, "dwell_s": (0.1, 0.1)}  # a PA fillet's weave


def weave_row(noise: str | None = None) -> dict[str, Any]:
    """The same cell with a weaving procedure (:data:`WEAVE`, at 8 mm/s) as its WPS: the coordinated weld's TCP
    against the true curve with the weave meant at each record taken off, the weave's half width, the times and
    the programs' moves (RAPID along the pass's line with the controller's weave, KRL the woven path)."""
    from cell import scenario as sc
    from cell.export.coordinated_program import coordinated_moves
    from cell.pipeline.positioned import weld_on_positioner
    from cell.scenario.procedure_specs import ProcedureSpec, WeaveSpec

    s = sc.load(SCENARIO)
    s = s.with_noise(noise) if noise else s
    row = ProcedureSpec(name="PA-weave", travel_speed_mm_s=8.0, weave=WeaveSpec(**WEAVE))
    s = s.model_copy(update={"procedures": (row,)})
    run = weld_on_positioner(s)
    welds = [w for g in run.groups for w in g.seams if w.welded and w.quality is not None]
    if not run.coordinated or not welds or welds[0].quality is None:
        return {"procedure": WEAVE, "welded": False}
    cw, q = run.coordinated[0], welds[0].quality
    assert cw.weave_F is not None
    return {
        "procedure": {**WEAVE, "travel_speed_mm_s": 8.0},
        "welded": True,
        "tcp_rms_mm": round(q.tcp_rms_mm, 3),
        "tcp_max_mm": round(q.tcp_max_mm, 3),
        "weave_half_width_mm": round(float(np.linalg.norm(cw.weave_F, axis=1).max()) * 1000.0, 3),
        "speed_mm_s": round(q.speed_mm_s, 2),
        "loop_unwelded_mm": round(q.short_start_mm, 1),
        "knots": len(cw.s),
        "arc_s": round(cw.arc_s, 2),
        "job_s": round(cw.duration, 2),
        "plan_wall_s": round(cw.plan_s, 2),
        "rapid_moves": {k: sum(mv.kind == k for mv in coordinated_moves(cw, woven=False)) for k in ("CIRC", "LIN")},
        "krl_moves": {k: sum(mv.kind == k for mv in coordinated_moves(cw)) for k in ("CIRC", "LIN")},
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", type=Path, default=RESULTS / "coordinated.json")
    ap.add_argument("--noise", default=None)
    ap.add_argument("--program", type=Path, default=None, help="write the KRL and RAPID programs here")
    args = ap.parse_args()
    _say(f"{SCENARIO}: locate, plan, weld with the part turning")
    row = coordinated_row(args.noise, args.program)
    _say(f"{SCENARIO}: the same with a weaving procedure")
    row["weave"] = weave_row(args.noise)
    _say(f"{TEE}: the saddle welded with the tilt following it and the rotate axis turning")
    tee_program = args.program / "tube_tee" if args.program is not None else None
    row["tube_tee"] = coordinated_row(args.noise, tee_program, TEE, SADDLE)
    _say(f"{BRACE}: the brace's feet with the tilt following them")
    row["round_brace"] = seams_row(args.noise)
    from cell.provenance import git_commit

    command = "benchmarks/bench_coordinated.py" + (f" --noise {args.noise}" if args.noise else "")
    out = {"command": command, "commit": git_commit(), **row}
    args.json.write_text(json.dumps(out, indent=1) + "\n")
    _say(f"wrote {args.json}")


if __name__ == "__main__":
    main()
