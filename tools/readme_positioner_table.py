"""docs/results.md's positioner block (``tools/readme_results.py``): ``cell weld fence1-positioner``
against ``cell weld fence1`` and each seam's pose and ISO 6947 position, from ``benchmarks/results/positioner.json``
(``benchmarks/bench_positioner.py``)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any


def _f(v: Any, fmt: str = ".3f") -> str:
    return "-" if v is None else format(v, fmt)


def positioner_table(data: Mapping[str, Any]) -> str:
    a, b = data["fence1"], data["fence1_positioner"]
    cpu_ratio = data.get("plan_cpu_per_seam_ratio")
    lines = [
        "| job | seams welded | operator turns | job time [s] | of it: operator / positioner [s] | TCP max [mm] |"
        " planning per seam planned: wall / CPU [s] |",
        "|---|---|---|---|---|---|---|",
        f"| `{a['job']}` | {a['welded']}/{a['seams']} | {a['operator_turns']} | {_f(a['job_time_s'], '.1f')} |"
        f" {_f(a['operator_s'], '.0f')} / - | {_f(a['tcp_max_mm'])} | {_f(a['plan_per_seam_s'], '.2f')} /"
        f" {_f(a.get('plan_cpu_per_seam_s'), '.2f')} |",
        f"| `{b['job']}` | {b['welded']}/{b['seams']} | 0 | {_f(b['job_time_s'], '.1f')} |"
        f" - / {_f(b['positioner_s'], '.1f')} ({b['poses']} poses) | {_f(b['tcp_max_mm'])} |"
        f" {_f(b['plan_per_seam_s'], '.2f')} / {_f(b.get('plan_cpu_per_seam_s'), '.2f')}"
        f" ({data['plan_per_seam_ratio']:.2f}x / {_f(cpu_ratio, '.2f')}x) |",
        "",
        "The positioner's moves between poses, each checked against the arm where it stands (a route chosen that"
        f" sweeps nothing into it), take {_f(b.get('move_check_s'), '.2f')} s more: with them"
        f" {_f(b.get('plan_and_move_check_per_seam_s'), '.2f')} s per seam,"
        f" {_f(data.get('plan_and_move_check_ratio'), '.2f')}x fence1's planning (wall).",
        "",
        "| seam | pose: tilt / rotate [deg] | ISO 6947: code, S / R [deg] | in tolerance | welded | TCP max [mm] |"
        " why not |",
        "|---|---|---|---|---|---|---|",
    ]
    poses = b.get("pose_rows", [])
    for s in b["seam_rows"]:
        wp = s["weld_position"]
        k = s["pose"]
        at = f"{poses[k]['tilt_deg']:+.1f} / {poses[k]['rotate_deg']:+.1f}" if k is not None and k < len(poses) else "-"
        pos = f"{wp['code']}, {wp['slope_deg']:+.2f} / {wp['rotation_deg']:.2f}" if wp else "-"
        ok = ("yes" if wp["within_tolerance"] else "no") if wp else "-"
        head, code = s["reason"].split(":")[0], s.get("reason_code") or ""
        why = "" if s["welded"] else f"{code} ({head})" if code and head != code else head or code
        lines.append(
            f"| {s['id']} | {at} | {pos} | {ok} | {'yes' if s['welded'] else 'no'} | {_f(s['tcp_max_mm'])} | {why} |"
        )
    return "\n".join(lines) + "\n"


def coordinated_table(d: Mapping[str, Any]) -> str:
    """docs/results.md's coordinated block: the pipe stub's fillet welded with the part turning (and tube-tee's
    saddle, the tilt following it), from
    ``benchmarks/results/coordinated.json`` (``benchmarks/bench_coordinated.py``)."""
    tee = d.get("tube_tee")
    lines = [
        "| scenario: seam | located: sigma max / error RMS / max [mm] | weld gate | TCP RMS / max [mm] | speed along"
        " the part [mm/s] | ISO 6947 over its waypoints: worst slope / rotation off 180 [deg] | tilt; rotate from .."
        " to [deg] | torch spread [mm] | arc / job [s] | planning [s] |",
        "|---|---|---|---|---|---|---|---|---|---|",
        *(_coordinated_row(r) for r in (d, tee) if r),
    ]
    if "program_moves" in d:
        moves = ", ".join(f"{n} {k}" for k, n in d["program_moves"].items() if n)
        off, dev = _f(d["program_path_off_mm"], ".4f"), _f(d["program_axes_off_deg"], ".3f")
        lines += ["", f"Programs: {moves} in the turning base; the weld's knots within {off} mm of the moves as"
                  f" the controller runs them, the planned E2/E3 within {dev} deg of its synchronous"
                  " interpolation."]  # fmt: skip
    if tee and "program_moves" in tee:
        moves = ", ".join(f"{n} {k}" for k, n in tee["program_moves"].items() if n)
        off, dev = _f(tee["program_path_off_mm"], ".4f"), _f(tee["program_axes_off_deg"], ".3f")
        seams = tee.get("seams", [])
        done = ", ".join(f"`{x['id']}`" for x in seams if x["welded"])
        left = "; ".join(f"`{x['id']}`: {x['code']} ({x['reason'].split(': ', 2)[-1][:90]})" for x in seams
                         if not x["welded"] and x["code"] != "partial")  # fmt: skip
        part = ", ".join(f"`{x['id']}`" for x in seams if x["code"] == "partial")
        lines += ["", f"{tee['scenario']}: programs {moves} in the turning base (knots within {off} mm, E2/E3"
                  f" within {dev} deg of the controller's interpolation); welded {done}; not welded:"
                  f" {left or 'none'}{f'; welded in part (below): {part}' if part else ''}."]  # fmt: skip
    lines += _in_part_lines([r for r in (tee, d.get("round_brace")) if r])
    wv = d.get("weave")
    if wv and wv.get("welded"):
        p = wv["procedure"]
        rm = ", ".join(f"{n} {k}" for k, n in wv["rapid_moves"].items() if n)
        km = ", ".join(f"{n} {k}" for k, n in wv["krl_moves"].items() if n)
        lines += ["", "| with a weave | TCP RMS / max without the weave [mm] | weave half width [mm] | speed [mm/s] |"
                  " knots | arc / job [s] | planning [s] | RAPID (controller's weave) | KRL (woven path) |",
                  "|---|---|---|---|---|---|---|---|---|",
                  f"| {p['pattern']} {_f(p['width_mm'], 'g')} mm at {_f(p['frequency_hz'], 'g')} Hz, dwell"
                  f" {_f(p['dwell_s'][0], 'g')} s | {_f(wv['tcp_rms_mm'])} / {_f(wv['tcp_max_mm'])} |"
                  f" {_f(wv['weave_half_width_mm'], '.2f')} | {_f(wv['speed_mm_s'], '.2f')} | {wv['knots']} |"
                  f" {_f(wv['arc_s'], '.1f')} / {_f(wv['job_s'], '.1f')} | {_f(wv['plan_wall_s'], '.1f')} | {rm} |"
                  f" {km} |"]  # fmt: skip
    return "\n".join(lines) + "\n"


def _in_part_lines(rows: list[Mapping[str, Any]]) -> list[str]:
    """The curves welded in part with the part turning (each row's ``in_part``): the stretch welded (each arc's,
    in more than one) and its share, the TCP (over all its arcs), the position, the axes, the times, the programs
    (the first arc's) and what is left for a manual weld."""
    parts = [(r["scenario"], p) for r in rows for p in r.get("in_part") or ()]
    if not parts:
        return []
    out = ["", "| welded in part: scenario: seam | stretch welded [mm along the located curve, past its length: round"
           " its start] (share) | TCP RMS / max [mm] | worst"
           " slope / rotation off 180 [deg] | tilt; rotate from .. to [deg] | arc / job [s] | planning [s] | program"
           " (knots off / E2-E3 off) | left for a manual weld |", "|---|---|---|---|---|---|---|---|---|"]  # fmt: skip
    for sc, p in parts:
        t, r = p["tilt_range_deg"], p["rotate_deg"]
        moves = ", ".join(f"{n} {k}" for k, n in p["program_moves"].items() if n)
        rest = "; ".join(f"{x['from_mm']:.0f}-{x['to_mm']:.0f} mm ({x['code']})" for x in p["remainder"])
        spans = [a["span_mm"] for a in p.get("arcs") or ()] or [p["span_mm"]]  # more than one arc: each one's
        span = " + ".join(f"{a:.0f}-{b:.0f}" for a, b in spans)
        out.append(f"| {sc}: `{p['curve']}` | {span} ({p['share']:.0%}{f', {len(spans)} arcs' * (len(spans) > 1)}) |"
                   f" {_f(p['tcp_rms_mm'])} / {_f(p['tcp_max_mm'])} | {_f(p['slope_worst_deg'], '.2f')} /"
                   f" {_f(p['rotation_worst_off_deg'], '.2f')} | {_f(t[0], '.1f')} .. {_f(t[1], '.1f')};"
                   f" {_f(r[0], '.1f')} .. {_f(r[1], '.1f')} | {_f(p['arc_s'], '.1f')} / {_f(p['job_s'], '.1f')} |"
                   f" {_f(p['plan_wall_s'], '.1f')} | {moves} ({_f(p['program_path_off_mm'], '.3f')} mm /"
                   f" {_f(p['program_axes_off_deg'], '.2f')} deg) | {rest} |")  # fmt: skip
    return out


def _coordinated_row(d: Mapping[str, Any]) -> str:
    """One coordinated weld's row: the located curve, the gate, the weld measured, its axes and times."""
    w, t = d["waypoints"], d.get("tilt_range_deg")
    tilt = _f(d["tilt_deg"], ".1f") if not t or t[1] - t[0] < 0.05 else f"{_f(t[0], '.1f')} .. {_f(t[1], '.1f')}"
    return (
        f"| {d.get('scenario', '')}: `{d['curve']}` | {_f(d['located_sigma_max_mm'])} / {_f(d['located_error_rms_mm'])}"
        f" / {_f(d['located_error_max_mm'])} | {d['gate']} | {_f(d['tcp_rms_mm'])} / {_f(d['tcp_max_mm'])} |"
        f" {_f(d['speed_mm_s'], '.2f')} | {_f(d['slope_worst_deg'], '.2f')} / {_f(d['rotation_worst_off_deg'], '.2f')}"
        f" ({len(w['s_mm'])} waypoints, {'PA' if d['in_position'] else 'not PA'}) | {tilt};"
        f" {_f(d['rotate_deg'][0], '.1f')} .. {_f(d['rotate_deg'][1], '.1f')} | {_f(d['torch_spread_mm'], '.2f')} |"
        f" {_f(d['arc_s'], '.1f')} / {_f(d['job_s'], '.1f')} | {_f(d['plan_wall_s'], '.1f')} |"
    )
