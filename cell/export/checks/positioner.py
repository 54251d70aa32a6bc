"""``cell krl check`` on a positioner's programs (docs/positioner.md, "Programs"): the axes and limits and the base
the header states (:mod:`cell.export.krl_external` writes them), and every point's E2 / E3 against those limits."""

from __future__ import annotations

import re
from typing import Any

from cell.export.checks.program import _EXT_TYPES, Finding, Program, _motions
from cell.export.checks.read import parse_value

_STATED = re.compile(r"\bE(\d)\s+(\w+)\s+limits\s+([+-]?\d+(?:\.\d*)?)\s*\.\.\s*([+-]?\d+(?:\.\d*)?)\s*deg\b", re.I)
_POSITIONER = re.compile(r"\bpositioner\b", re.I)
_BASE_R = re.compile(r"base at this program's axes in \$ROBROOT = (\{[^}]*\})", re.I)
TOL_DEG = 0.001  # the axes are written to 0.001 deg


def stated_base(p: Program) -> dict[str, Any] | None:
    """The base in $ROBROOT at the program's axes, as its header states it (None: not stated)."""
    for _, text in p.src.comments:
        if (m := _BASE_R.search(text)) is not None:
            v = parse_value(m.group(1))
            return v if isinstance(v, dict) else None
    return None


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
