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
_CHAIN = re.compile(
    r"chain in \$ROBROOT: P = (\{[^}]*\}), tilt axis ([+-]?\d+(?:\.\d*)?) mm above P along its x, faceplate"
    r" ([+-]?\d+(?:\.\d*)?) mm from it, BASE_DATA on the faceplate = (\{[^}]*\})",
    re.I,
)
TOL_DEG = 0.001  # the axes are written to 0.001 deg


def chain_line(X_RP: Any, tilt_height_m: float, faceplate_offset_m: float, X_FB: Any) -> str:
    """The header comment stating the positioner's chain, read back by :func:`turning_base`."""
    from cell.export.krl_data import frame_text

    return (
        f";- Positioner chain in $ROBROOT: P = {frame_text(X_RP)}, tilt axis {tilt_height_m * 1000:.3f} mm above P"
        f" along its x, faceplate {faceplate_offset_m * 1000:.3f} mm from it, BASE_DATA on the faceplate ="
        f" {frame_text(X_FB)}"
    )


def turning_base(p: Program) -> Program:
    """A program whose header states the positioner's chain (coordinated motion: E2 / E3 change from point to
    point) with every E6POS moved into the base the header states at its first axes: the base at the point's own
    E2 (tilt) and E3 (rotate) by the chain, so the arm's check reads every point where the turning part holds it.
    Unchanged without such a line."""
    from dataclasses import replace

    import numpy as np

    from cell.export.checks.kinematics import frame_of
    from cell.geometry import invert, make_pose, rot_x, rot_z

    m = next((m for _, text in p.src.comments if (m := _CHAIN.search(text)) is not None), None)
    base = stated_base(p)
    if m is None or base is None:
        return p
    X_RP, X_FB = frame_of(parse_value(m.group(1))), frame_of(parse_value(m.group(4)))
    h, d = float(m.group(2)) / 1000.0, float(m.group(3)) / 1000.0
    X_BR = invert(frame_of(base))
    decls = dict(p.dat.decls)
    for key, dcl in p.dat.decls.items():
        v = dcl.value
        if dcl.type != "E6POS" or not isinstance(v, dict) or not isinstance(v.get("E2"), float):
            continue
        t, r = np.radians(v["E2"]), np.radians(v["E3"])
        X_RB = X_RP @ make_pose(p=(0, 0, h)) @ make_pose(rot_x(t)) @ make_pose(p=(0, 0, d)) @ make_pose(rot_z(r)) @ X_FB
        X = X_BR @ X_RB @ frame_of(v)
        decls[key] = replace(dcl, value={**v, **_xyzabc(X)})
    return replace(p, dat=replace(p.dat, decls=decls))


def _xyzabc(X: Any) -> dict[str, float]:
    from cell.export.checks.read import parse_value as parse
    from cell.export.krl_data import frame_text

    v = parse(frame_text(X))
    assert isinstance(v, dict)
    return {k: float(v[k]) for k in "XYZABC"}


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
