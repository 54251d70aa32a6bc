"""A positioner in KRL (docs/positioner.md, "Programs"): the header that states its axes and limits, the base on its
kinematic chain (``$BASE = EK(MACHINE_DEF[m].ROOT, MACHINE_DEF[m].MECH_TYPE, BASE_DATA[n])``), the move of its axes
before the welds, and ``cell krl check``'s test of every point's E2 / E3 against the limits the header states."""

from __future__ import annotations

import re
from typing import Any

from cell.export.krl_check import _EXT_TYPES, Finding, Program, _motions
from cell.export.krl_data import e6axis, frame_text, num
from cell.export.krl_read import parse_value
from cell.export.program import ProgramJob
from cell.geometry import FloatArray
from cell.types.positioner import ExternalAxes

_STATED = re.compile(r"\bE(\d)\s+(\w+)\s+limits\s+([+-]?\d+(?:\.\d*)?)\s*\.\.\s*([+-]?\d+(?:\.\d*)?)\s*deg\b", re.I)
_POSITIONER = re.compile(r"\bpositioner\b", re.I)
_BASE_R = re.compile(r"base at this program's axes in \$ROBROOT = (\{[^}]*\})", re.I)
TOL_DEG = 0.001  # the axes are written to 0.001 deg


def positioner_header(ext: ExternalAxes, X_RB: FloatArray) -> list[str]:
    """The header comment: the positioner's axes, their numbers and limits, how the base chains."""
    axes = "; ".join(
        f"E{n} {name} limits {lo:.1f} .. {hi:.1f} deg"
        for n, name, (lo, hi) in zip(ext.numbers, ext.names, ext.limits_deg, strict=True)
    )
    return [
        f";- Positioner (tilt-rotate, coordinated, MACHINE_DEF[{ext.machine}]): {axes}.",
        ";- The points are in BASE_DATA on the positioner's faceplate ($BASE = EK(...)); every point carries the"
        " axes' values: they stand still while the arm welds.",
        f";- The base at this program's axes in $ROBROOT = {frame_text(X_RB)} (what EK gives; for checking)",
    ]


def stated_base(p: Program) -> dict[str, Any] | None:
    """The base in $ROBROOT at the program's axes, as its header states it (None: not stated)."""
    for _, text in p.src.comments:
        if (m := _BASE_R.search(text)) is not None:
            v = parse_value(m.group(1))
            return v if isinstance(v, dict) else None
    return None


def base_lines(job: ProgramJob) -> list[str]:
    """``BAS(#BASE, n)`` without a positioner; with one, the base on its kinematic chain."""
    n = job.options.base_index
    if job.external is None:
        return [f"BAS(#BASE, {n})"]
    m = job.external.machine
    return [
        f"$BASE = EK(MACHINE_DEF[{m}].ROOT, MACHINE_DEF[{m}].MECH_TYPE, BASE_DATA[{n}]) ; the part on the faceplate"
    ]


def positioner_move(b: Any, job: ProgramJob) -> list[str]:
    """The positioner's axes to the program's values, the arm at home (declared in the .dat ``b.dat``)."""
    ext = job.external
    if ext is None:
        return []
    b.dat.append(f"DECL E6AXIS XPOSITIONER={e6axis(job.plan.q_home, 0.0, ext.by_number())}")
    values = ", ".join(f"{name} {num(v, 1)} deg" for name, v in zip(ext.names, ext.values_deg, strict=True))
    return [f"PTP XPOSITIONER ; the positioner to {values}, the arm at home"]


def stated_positioner(p: Program) -> dict[int, tuple[str, float, float]]:
    """E number -> (axis name, min, max) [deg] as the program's header states them (empty: no positioner)."""
    out: dict[int, tuple[str, float, float]] = {}
    for _, text in p.src.comments:
        if _POSITIONER.search(text):
            for m in _STATED.finditer(text):
                out[int(m.group(1))] = (m.group(2), float(m.group(3)), float(m.group(4)))
    return out


def check_positioner(p: Program, limits_deg: dict[int, tuple[float, float]] | None = None) -> list[Finding]:
    """Every E6POS / E6AXIS's positioner axes against their limits (``limits_deg``: E number -> (min, max), else
    the header's): an axis missing or outside is a finding (code ``positioner``)."""
    stated = stated_positioner(p)
    limits = limits_deg if limits_deg is not None else {n: (lo, hi) for n, (_, lo, hi) in stated.items()}
    if not limits:
        return []
    points = [(d.name, d.line, p.dat_name, d.value) for d in p.dat.decls.values() if d.type in _EXT_TYPES]
    points += [(f"the point of line {s.line}", s.line, p.src_name, s.point) for s in _motions(p.src)
               if isinstance(s.point, dict)]  # fmt: skip
    out = []
    for name, line, fname, v in points:
        if not isinstance(v, dict) or name in ("XHOME",):
            continue
        for n, (lo, hi) in sorted(limits.items()):
            e = v.get(f"E{n}")
            if not isinstance(e, float):
                out.append(Finding(fname, line, "positioner", f"{name} has no E{n}: the program runs on a positioner"))
            elif not lo - TOL_DEG <= e <= hi + TOL_DEG:
                out.append(
                    Finding(fname, line, "positioner", f"{name}: E{n} {e:g} deg is outside its limits {lo:g} .. {hi:g}")
                )
    return out
