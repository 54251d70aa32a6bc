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
    lines = [
        "| job | seams welded | operator turns | job time [s] | of it: operator / positioner [s] | TCP max [mm] |"
        " planning per seam planned [s] |",
        "|---|---|---|---|---|---|---|",
        f"| `{a['job']}` | {a['welded']}/{a['seams']} | {a['operator_turns']} | {_f(a['job_time_s'], '.1f')} |"
        f" {_f(a['operator_s'], '.0f')} / - | {_f(a['tcp_max_mm'])} | {_f(a['plan_per_seam_s'], '.2f')} |",
        f"| `{b['job']}` | {b['welded']}/{b['seams']} | 0 | {_f(b['job_time_s'], '.1f')} |"
        f" - / {_f(b['positioner_s'], '.1f')} ({b['poses']} poses) | {_f(b['tcp_max_mm'])} |"
        f" {_f(b['plan_per_seam_s'], '.2f')} ({data['plan_per_seam_ratio']:.1f}x) |",
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
