"""The result tables of the cell's own commands, rendered from ``benchmarks/results/`` (used by
``tools/readme_results.py``, which puts them between the markers of docs/results.md).

- ``rescan``: the close-up re-scan, before -> after (``rescan.json``, ``benchmarks/bench_cell.py rescan``);
- ``confidence``: the confidence thresholds (``confidence.json``, ``benchmarks/bench_confidence.py``);
- ``weld``: welding fence1, per seam, and the cycle-time line under it (``weld.json``, ``bench_cell.py weld``);
- ``motion``: the motion primitives (``motion.json``, ``benchmarks/bench_motion.py``);
- ``faults``: every fault scenario (``faults.json``, ``bench_cell.py faults``).

Every figure comes from the JSON. What the JSON cannot hold is written here by hand, kept apart in the mappings
below: how the tables name a scenario (the fault each one injects) and a short note where docs/results.md says
more than the data can (the "what the cell does" column is otherwise one sentence template per kind of outcome).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

Row = Mapping[str, Any]

# ---- written by hand: what the results cannot say ---------------------------------------------------------------

# The re-scan table's scenario column, where the table says what the scenario is.
RESCAN_LABELS: Mapping[str, str] = {
    "faults/extrinsics-off": "faults/extrinsics-off (every camera, the arm's included, off by 1 mm / 0.1 deg)",
}
# The fault table's rows, in their order: the scenario and the fault it injects.
FAULT_LABELS: Mapping[str, str] = {
    "faults/camera-dead": "camera-dead (cam_left)",
    "faults/camera-frozen": "camera-frozen (cam_left)",
    "faults/two-cameras-dead": "two-cameras-dead (both fixed cameras)",
    "faults/camera-random": "camera-random (cam_right)",
    "faults/camera-salt": "camera-salt (eye-in-hand, 40 % salt)",
    "faults/camera-bumped": "camera-bumped (cam_right 15 mm / 1.5 deg)",
    "faults/extrinsics-off": "extrinsics-off (every camera 1 mm / 0.1 deg)",
    "faults/extrinsics-fixed-off": "extrinsics-fixed-off (fixed cameras 1 mm / 0.1 deg)",
    "faults/occluded": "occluded (a clamp and a cable)",
    "faults/missing-part": "missing-part (POST_R not built)",
    "faults/displaced": "displaced (60 mm / 4 deg)",
    "faults/displaced-far": "displaced-far (120 mm)",
    "faults/ladder-shifted": "ladder-shifted (one rung pitch)",
}
# A note after the generated sentence, where the table says what the figures mean.
FAULT_NOTES: Mapping[str, str] = {
    "faults/two-cameras-dead": "the eye-in-hand camera carries the cell",
    "faults/camera-salt": "the eye-in-hand camera, dropped from the scan, still serves up close",
    "faults/displaced": "the alignment re-finds the part",
}
# The motion table's rows: the case's key in motion.json, the table's name for it, whether it shows the goal.
MOTION_ROWS: Sequence[tuple[str, str, bool]] = (
    ("ik_warm", "IK, warm-started along seams, full pose", True),
    ("ik_warm_free_axis", "IK, warm-started, torch axis free", True),
    ("ik_cold", "IK, cold from home with seeded restarts", False),
    ("ptp_duration", "Ruckig jerk-limited PTP: solve (with limit checks)", True),
    ("ptp_sampled", "Ruckig PTP solve + sampling at 4 ms", False),
)

# ---- sentence templates: a short phrase per reason code or kind of outcome ----------------------------------------

# Why a seam was not welded, by its detection's reason code, then by its weld reason code.
WHY_NOT: Mapping[str, str] = {
    "underside": "against the table (flip)",
    "low_confidence": "`low_confidence`",
    "not_planned": "not planned",
}
# What a refusal refuses, by the error's type.
REFUSES: Mapping[str, str] = {"AlignmentError": "refuses the alignment", "SensorError": "refuses the images"}


def _f(v: float | None, nd: int) -> str:
    return "-" if v is None else f"{v:.{nd}f}"


def _plural(n: int, word: str) -> str:
    return f"{n} {word}" if n == 1 else f"{n} {word}s"


def rescan_table(rows: Sequence[Row]) -> str:
    """Per scenario: mean lateral and end point error before -> after [mm], robot time [s]."""
    lines = [
        "| scenario | mean lateral before -> after [mm] | mean endpoint before -> after [mm] | robot time [s] |",
        "|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {RESCAN_LABELS.get(r['scenario'], r['scenario'])} | "
            f"{_f(r['lateral_mean_mm_before'], 3)} -> {_f(r['lateral_mean_mm_after'], 3)} | "
            f"{_f(r['endpoint_mean_mm_before'], 3)} -> {_f(r['endpoint_mean_mm_after'], 3)} | {_f(r['motion_s'], 1)} |"
        )
    return "\n".join(lines) + "\n"


def confidence_table(data: Row) -> str:
    """Per threshold: seams below it, seams over ``big_mm`` among them, the largest lateral error above it."""
    lines = [
        f"| threshold | seams below (re-scanned) | of the {data['big']} over {data['big_mm']} mm caught | "
        "max lateral above it [mm] |",
        "|---|---|---|---|",
    ]
    for t in data["thresholds"]:
        lines.append(f"| {t['threshold']:.2f} | {t['below']} | {t['caught']} | {_f(t['max_lateral_above_mm'], 3)} |")
    return "\n".join(lines) + "\n"


def _why_not(s: Row) -> str:
    for code in (s.get("reason_code"), s.get("weld_reason_code")):
        if isinstance(code, str) and code in WHY_NOT:
            return WHY_NOT[code]
    return str(s.get("weld_reason") or "not welded")


def _cycle_line(r: Row) -> str:
    t, rs = r["timings_s"], r["rescan"]
    if rs and rs["seams"]:
        rescan = f"close-up re-scan of {_plural(rs['seams'], 'seam')} {_f(rs['motion_s'], 1)} s"
    else:
        rescan = "no close-up re-scan"
    return (
        f"Cycle time {_f(r['cycle_time_s'], 1)} s of robot motion (arc {_f(r['arc_time_s'], 1)} s, {rescan}); "
        f"pipeline wall time {_f(t.get('total_s'), 1)} s headless, Python start-up not counted "
        f"(capture {_f(t.get('capture_s'), 1)}, perceive "
        f"{_f(t.get('perceive_s'), 1)}, align {_f(t.get('align_s'), 1)}, locate {_f(t.get('locate_s'), 2)}, re-scan "
        f"{_f(t.get('rescan_s', 0.0), 1)}, plan and safety gate {_f(t.get('plan_s'), 1)}, execute "
        f"{_f(t.get('execute_s'), 2)} s)."
    )


def weldments_table(rows: Sequence[Row]) -> str:
    """One line per ``cell weld`` run of a part that is not all boxes (``weldments.json``): seams found, their mean
    located errors, welded, the worst executed TCP RMS, our time per seam, and why the others were not welded."""
    lines = [
        "| scenario | found / visible | located: lateral / endpoint mean [mm] | welded / visible "
        "| worst TCP RMS [mm] | ours, ms per seam with its close-up (median) | not welded: why (seams) |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        if r.get("error"):
            lines.append(f"| {r['scenario']} | - | - | - | - | - | {r['error']['message']} |")
            continue
        rms = [s["tcp_rms_mm"] for s in r["seams"] if s["welded"] and s["tcp_rms_mm"] is not None]
        why = ", ".join(f"{k.replace('_', ' ')}: {n}" for k, n in sorted(r["weld_reason_counts"].items()))
        lines.append(
            f"| {r['scenario']} | {r['found']}/{r['visible']} | {_f(r['lateral_mean_mm'], 2)} / "
            f"{_f(r['endpoint_mean_mm'], 2)} | {r['welded']}/{r['visible']} | {_f(max(rms) if rms else None, 2)} "
            f"| {_f(r['ms_per_seam_median'], 1)} | {why or '-'} |"
        )
    return "\n".join(lines) + "\n"


def weld_table(r: Row) -> str:
    """One line per seam of a ``cell weld`` run (with its side when the part was turned), then its cycle-time
    line (and the turn's)."""
    two = "sides" in r
    side_h, side_c = ("side | ", "---|") if two else ("", "")
    lines = [
        f"| {side_h}seam | located: paper ME / lateral [mm] | welded | executed TCP vs true seam: RMS / max [mm] | "
        "travel speed [mm/s] | weld time [s] |",
        f"|{side_c}---|---|---|---|---|---|",
    ]
    for s in sorted(r["seams"], key=lambda s: s.get("side", "A")) if two else r["seams"]:
        side = f"{s.get('side', 'A')} | " if two else ""
        located = f"{_f(s['paper_me_mm'], 3)} / {_f(s['lateral_mm'], 3)}" if s["paper_me_mm"] is not None else "-"
        if s["welded"]:
            lines.append(
                f"| {side}{s['id']} | {located} | yes | {_f(s['tcp_rms_mm'], 3)} / {_f(s['tcp_max_mm'], 3)} | "
                f"{_f(s['travel_speed_mm_s'], 4)} | {_f(s['weld_time_s'], 3)} |"
            )
        else:
            lines.append(f"| {side}{s['id']} | {located} | no: {_why_not(s)} | - | - | - |")
    if not two:
        return "\n".join(lines) + "\n\n" + _cycle_line(r) + "\n"
    side_a = {**r, "cycle_time_s": r["sides"]["A"]["cycle_time_s"]}
    text = "\n".join(lines) + "\n\nSide A: " + _cycle_line(side_a) + " " + _turn_line(r)
    return text + "\n"


def _turn_line(r: Row) -> str:
    """The turn and side B of a two-sided ``cell weld`` row: welded per side, the turn, what side B's alignment
    measured, side B's robot and wall time, the job time."""
    sides, flip = r["sides"], r.get("flip")
    a = sides.get("A", {})
    if not flip or "B" not in sides:
        return f"Side A welded {a.get('welded')}; no turn."
    b = sides["B"]
    tb = b.get("timings_s", {})
    return (
        f"Side A welded {a['welded']} seams; the part turned {_f(flip['rotation_deg'], 0)} deg about its "
        f"{flip['axis']} axis (lean {_f(flip['tilt_deg'], 1)} deg); side B's alignment measured the operator's "
        f"placement error at {_f(flip['placement_error_mm'], 1)} mm / {_f(flip['placement_rotation_deg'], 2)} deg "
        f"(fitness {_f(flip['fitness'], 2)}); side B welded {b['welded']} seams in {_f(b['cycle_time_s'], 1)} s of "
        f"robot motion (pipeline {_f(tb.get('total_s'), 1)} s). Job time {_f(r['job_time_s'], 1)} s with the "
        f"operator's {_f(flip['operator_s'], 0)} s turn; the whole command's wall time {_f(r['wall_s'], 1)} s."
    )


def _time(us: float) -> str:
    """A call's time as the tables write it: whole microseconds below 0.5 ms, else milliseconds, 3 digits."""
    return f"{us:.0f} us" if us < 500.0 else f"{us / 1000.0:.3g} ms"


def motion_table(data: Row) -> str:
    """The motion primitives' median and 90th percentile (and goal), the fence1 plan, the cycle times."""
    by_key = {p["key"]: p for p in data["primitives"]}
    lines = ["| case | median | p90 | goal |", "|---|---|---|---|"]
    for key, label, show_goal in MOTION_ROWS:
        p = by_key[key]
        goal = f" {_time(p['goal_us'])} " if show_goal and "goal_us" in p else " "
        lines.append(f"| {label} | {_time(p['median_us'])} | {_time(p['p90_us'])} |{goal}|")
    plans = data["plans"]
    first = plans[0]
    lines.append(
        f"| welding plan of {first['scenario']} (designed seams): {first['planned']}/{first['seams']} planned | "
        f"{first['planning_s']:.1f} s | | |"
    )
    names = " / ".join(p["scenario"] for p in plans)
    cycles = " / ".join(f"{p['cycle_s']:.1f} s ({p['arc_s']:.1f} s)" for p in plans)
    lines.append(f"| cycle time {names} (arc time) | {cycles} | | |")
    return "\n".join(lines) + "\n"


def fault_sentence(r: Row) -> str:
    """What the cell does in a fault scenario, from the facts of its row (one template per kind of outcome)."""
    parts: list[str] = []
    counts = r.get("status_counts", {})
    err = r.get("error")
    if err is not None:
        refusal = f'{REFUSES.get(err["type"], "stops")} ("{err["message"]}")'
        if r.get("found", 0) == 0 and counts.get("not_found", 0) == r.get("visible"):
            refusal += ", every seam `not_found` with that reason"
        parts.append(refusal)
    if r.get("lost_cameras"):
        parts.append("drops " + _lost(r["lost_cameras"]))
    for status, key in (("occluded", "occluded_reasons"), ("not_found", "not_found_reasons")):
        n, reasons = counts.get(status, 0), r.get(key, [])
        if n and err is None:
            why = f' ("{reasons[0]}")' if len(reasons) == 1 else " with the reason"
            parts.append(f"{_plural(n, 'seam')} `{status}`{why}, never welded")
    rs = r.get("rescan")
    if rs and rs["seams"]:
        used = f"{rs['used']} used" if rs["used"] else "none used"
        if rs["escalated_mm"]:
            parts.append(f"a close-up disagrees by {rs['escalated_mm']:.2f} mm: re-scans every seam up close ({used})")
        else:
            parts.append(f"re-scans {_plural(rs['seams'], 'seam')} up close ({used})")
    low = r.get("weld_reason_counts", {}).get("low_confidence", 0)
    if low:
        parts.append(f"{_plural(low, 'seam')} `low_confidence`, not welded")
    if not parts:
        parts.append("welds every visible seam")
    note = FAULT_NOTES.get(r["scenario"])
    return "; ".join([*parts, note] if note else parts)


def _lost(described: Sequence[str]) -> str:
    """``"name: reason"`` of each lost camera as ``name ("reason")``, cameras with the same reason together."""
    by_reason: dict[str, list[str]] = {}
    for d in described:
        name, _, why = d.partition(": ")
        by_reason.setdefault(why, []).append(name)
    return ", ".join(" and ".join(names) + (f' ("{why}")' if why else "") for why, names in by_reason.items())


def faults_table(rows: Sequence[Row]) -> str:
    """One line per fault scenario (in :data:`FAULT_LABELS`'s order first): what the cell does, welded, worst TCP
    error, exit."""
    order = {name: k for k, name in enumerate(FAULT_LABELS)}
    lines = [
        "| scenario (`scenarios/faults/`) | what the cell does | welded | worst executed TCP error [mm] | exit |",
        "|---|---|---|---|---|",
    ]
    for r in sorted(rows, key=lambda r: (order.get(r["scenario"], len(order)), r["scenario"])):
        label = FAULT_LABELS.get(r["scenario"], r["scenario"].removeprefix("faults/"))
        welded = f"{r['welded']}/{r['visible']}" if "welded" in r else "-"
        lines.append(f"| {label} | {fault_sentence(r)} | {welded} | {_f(r.get('tcp_max_mm'), 2)} | {r['exit_code']} |")
    return "\n".join(lines) + "\n"


def real_scans_table(data: Row) -> str:
    """The tee's fillets in the three real lidar scans (``real_scans.json``): the seen fillet against an independent
    two-plane fit and against the aligned CAD, its sigma, the hidden fillet's status, the placements tried."""
    lines = [
        "| scan | points | seen fillet | vs independent line [mm] | vs aligned CAD [mm] | sigma [mm] | hidden fillet "
        "| other placements found |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for s in data["scans"]:
        seen = s["seen"]
        hidden = next(k for k in s if k.startswith(seen.split(":")[0] + ":") and k != seen)
        f = s["found"]
        p = s["placements"]
        found = f"{p['found'] + (p['without_placement']['status'] == 'found')}/{p['tried'] + 1}"
        lines.append(
            f"| {s['scan']} | {s['points']:,} | {seen.split(':')[1]} {s[seen]['status'].replace('_', ' ')} "
            f"| {f['lateral_vs_independent_mm']:.2f} | {f['lateral_vs_cad_mm']:.2f} | {f['sigma_mm']:.2f} "
            f"| {hidden.split(':')[1]} {s[hidden]['status'].replace('_', ' ')} | {found} |"
        )
    return "\n".join(lines) + "\n"


def planning_table(data: Row) -> str:
    """Planning per scenario (``planning.json``): seams asked and planned, the refusals by code, the planner's CPU
    time in all and per planned seam, the reach pre-check per seam, and the wall time of the whole ``cell weld``."""
    walls = {r["scenario"]: r for r in data.get("weld_runs", [])}
    lines = [
        "| scenario | seams asked | planned | refused (code: seams) | planning CPU [s] | per planned seam [s] "
        "| reach pre-check [us/seam] | cell weld wall [s], welded |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in data["rows"]:
        refused = ", ".join(f"{k}: {v}" for k, v in sorted(r["refused_by_code"].items())) or "-"
        w = walls.get(r["scenario"])
        weld = f"{w['wall_s']:.0f}, {w['welded']}/{w['visible']}" if w else "-"
        lines.append(
            f"| {r['scenario']} | {r['seams_asked']} | {r['seams_planned']} | {refused} | {r['planning_cpu_s']:.1f} "
            f"| {r['cpu_s_per_planned_seam']:.2f} | {r['reach_precheck_us_per_seam']:.0f} | {weld} |"
        )
    return "\n".join(lines) + "\n"


def cycle_table(after: Row, before: Row | None) -> str:
    """Cycle time against its bound per scenario (``cycle.json``, and ``cycle_before.json`` for the planner before
    the cuts): both sides' plans, robot time with the arc on and off, where the air time goes, its bound and the
    ratio, the worst executed TCP max."""
    old = {r["scenario"]: r for r in before["rows"]} if before else {}
    lines = [
        "| scenario | seams | cycle [s] | arc [s] | air [s] | approach + depart [s] | transfers [s] | home legs [s] "
        "| air bound [s] | air / bound | TCP max [mm] |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]

    def was(r: Row, key: str, fmt: str = ".1f") -> str:
        o = old.get(r["scenario"])
        now = format(r[key], fmt) if r.get(key) is not None else "-"
        return f"{format(o[key], fmt)} -> {now}" if o and o.get(key) is not None else now

    for r in after["rows"]:
        bound = f"{r['air_bound_s']:.1f}" + ("" if r["bound_exact"] else f" (>= {r['air_lower_s']:.1f})")
        lines.append(
            f"| {r['scenario']} | {r['seams']} | {was(r, 'cycle_time_s')} | {r['arc_time_s']:.1f} "
            f"| {was(r, 'air_time_s')} | {r['approach_s'] + r['depart_s']:.1f} | {r['transfer_s']:.1f} "
            f"| {r['home_s']:.1f} | {bound} | {was(r, 'air_over_bound', '.2f')} | {was(r, 'tcp_max_mm', '.3f')} |"
        )
    return "\n".join(lines) + "\n"
