"""``cell krl check``: re-read a KRL program (:mod:`cell.export.checks.read`) and list what would stop it or weld wrong,
one :class:`Finding` per problem (its checks: docs/programs.md)."""

from __future__ import annotations

import re
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from cell.export.checks.read import Decl, KrlFile, Statement, read_krl
from cell.export.circles import circle_through

GLOBAL_POINTS = frozenset({"XHOME"})
_ARC_FOLD = re.compile(r"^(ARCON|ARCSWI|ARCOFF)\s+(\w+)", re.I)
_PARTS = {"ARCON": ("STRIKE", "WELD"), "ARCSWI": ("WELD",), "ARCOFF": ("CRATER",)}
_TRACK = re.compile(r"\blinear track E1\b", re.I)
_TRACK_LIMITS = re.compile(r"\blimits\s+([+-]?\d+(?:\.\d*)?)\s*\.\.\s*([+-]?\d+(?:\.\d*)?)\s*mm\b", re.I)
_TRACK_AXIS = re.compile(r"\baxis\s*\[([^\]]*)\]", re.I)
_EXT_TYPES = ("E6POS", "E6AXIS")
E1_TOL_MM = 0.001  # E1 is written to 0.001 mm
CIRCLE_TOL_MM = 0.05  # a circular move's points lie this close to its stated circle
ANGLE_TOL_DEG = 0.05  # its CA this close to the angle its points turn through
_CIRCLE = re.compile(
    r"circle r = ([\d.]+) mm, centre \[([-\d.]+), ([-\d.]+), ([-\d.]+)\] mm \(base\), angle ([\d.]+) deg"
)
_CHORD = re.compile(r"chord within ([\d.]+) mm of the planned path \(<= ([\d.]+) mm\)")


@dataclass(frozen=True)
class Finding:
    """One thing wrong: the file, its line (0: the file as a whole), a code (module docstring) and the detail."""

    file: str
    line: int
    code: str
    message: str

    def __str__(self) -> str:
        return f"{self.file}:{self.line}: {self.code}: {self.message}"


@dataclass(frozen=True)
class Program:
    """A program read from disk: its name, the two files read and their file names."""

    name: str
    src: KrlFile
    dat: KrlFile
    src_name: str
    dat_name: str


def read_programs(directory: Path) -> tuple[list[Program], list[Finding]]:
    """Every ``NAME.src`` of the folder with its ``NAME.dat``; findings for a .src without .dat."""
    programs, findings = [], []
    for src in sorted(directory.glob("*.src")) + sorted(directory.glob("*.SRC")):
        dat = next((p for p in (src.with_suffix(".dat"), src.with_suffix(".DAT")) if p.is_file()), None)
        if dat is None:
            findings.append(Finding(src.name, 0, "files", f"no {src.stem}.dat beside {src.name}"))
            continue
        s = read_krl(src.read_text(encoding="ascii", errors="replace"), "src")
        d = read_krl(dat.read_text(encoding="ascii", errors="replace"), "dat")
        programs.append(Program(src.stem, s, d, src.name, dat.name))
    return programs, findings


def check_program(p: Program, e1_limits_mm: tuple[float, float] | None = None) -> list[Finding]:
    """Every check but the kinematics (module docstring); ``e1_limits_mm`` the linear track's E1 limits [mm] when
    the check is given them."""
    out = [Finding(p.src_name, pr.line, "syntax", pr.message) for pr in p.src.problems]
    out += [Finding(p.dat_name, pr.line, "syntax", pr.message) for pr in p.dat.problems]
    for f, fname, word in ((p.src, p.src_name, "DEF"), (p.dat, p.dat_name, "DEFDAT")):
        if f.module is None:
            out.append(Finding(fname, 0, "files", f"no {word} line"))
        elif f.module.upper() != p.name.upper():
            out.append(Finding(fname, 0, "files", f"{word} {f.module} differs from the file name {p.name}"))
        if not f.closed:
            end = "END" if f.kind == "src" else "ENDDAT"
            out.append(Finding(fname, 0, "structure", f"no {end}: the file is truncated or not closed"))
        if f.open_folds:
            out.append(Finding(fname, 0, "structure", f"{f.open_folds} FOLD(s) never closed by ENDFOLD"))
    out += _check_init(p)
    out += _check_points(p)
    out += _check_arc(p)
    out += check_circles(p)
    out += check_track(p, e1_limits_mm)
    return out


def stated_track(p: Program) -> tuple[bool, tuple[float, float] | None]:
    """Whether the program's comments state a linear track E1, and its limits [mm] when they give them."""
    limits, stated = None, False
    for _, text in p.src.comments:
        if _TRACK.search(text):
            stated = True
            if (m := _TRACK_LIMITS.search(text)) is not None:
                limits = (float(m.group(1)), float(m.group(2)))
    return stated, limits


def stated_axis(p: Program) -> tuple[float, float, float] | None:
    """The linear track's direction the program's header states (``axis [x, y, z] in $ROBROOT``), a unit vector in
    the robot base at E1 = 0; None when it states none."""
    for _, text in p.src.comments:
        if _TRACK.search(text) and (m := _TRACK_AXIS.search(text)) is not None:
            try:
                x, y, z = (float(v) for v in m.group(1).split(","))
            except ValueError:
                return None
            n = (x * x + y * y + z * z) ** 0.5
            return (x / n, y / n, z / n) if n > 1e-9 else None
    return None


def check_track(p: Program, e1_limits_mm: tuple[float, float] | None = None) -> list[Finding]:
    """E1 of every E6POS / E6AXIS against the track the program states or the check is given (module docstring)."""
    stated, limits = stated_track(p)
    limits = e1_limits_mm if e1_limits_mm is not None else limits
    track = stated or limits is not None
    points = [(d.name, d.line, p.dat_name, d.value) for d in p.dat.decls.values() if d.type in _EXT_TYPES]
    points += [(f"the point of line {s.line}", s.line, p.src_name, s.point) for s in _motions(p.src)
               if isinstance(s.point, dict)]  # fmt: skip
    out = []
    for name, line, fname, v in points:
        if not isinstance(v, dict):
            continue
        e1 = v.get("E1")
        if not track:
            if isinstance(e1, float) and abs(e1) > E1_TOL_MM:
                out.append(Finding(fname, line, "track", f"{name}: E1 {e1:g} mm but the program states no linear"
                                   " track (and none was given)"))  # fmt: skip
        elif not isinstance(e1, float):
            out.append(Finding(fname, line, "track", f"{name} has no E1: the program runs on a linear track"))
        elif limits is not None and not limits[0] - E1_TOL_MM <= e1 <= limits[1] + E1_TOL_MM:
            out.append(Finding(fname, line, "track", f"{name}: E1 {e1:g} mm is outside the track's limits"
                               f" {limits[0]:g} .. {limits[1]:g} mm"))  # fmt: skip
    return out


def _motions(f: KrlFile) -> Iterator[Statement]:
    return (s for s in f.statements if s.kind in ("PTP", "LIN", "CIRC", "SPTP", "SLIN", "SCIRC"))


def _check_init(p: Program) -> list[Finding]:
    first = next(_motions(p.src), None)
    before = [s for s in p.src.statements if first is None or s.line < first.line]
    texts = [re.sub(r"\s+", " ", s.text.upper()) for s in before]
    out = []
    for want, what in (
        ("GLOBAL INTERRUPT DECL 3 WHEN $STOPMESS==TRUE DO IR_STOPM ( )", "the stop-message interrupt declaration"),
        ("INTERRUPT ON 3", "INTERRUPT ON 3"),
    ):
        if want not in texts:
            out.append(Finding(p.src_name, 0, "init", f"{what} is missing before the first motion"))
    if not any(t.replace(" ", "").startswith("BAS(#INITMOV,0") for t in texts):
        out.append(Finding(p.src_name, 0, "init", "BAS(#INITMOV, 0) is missing before the first motion"))
    if first is not None:
        d = _decl(p, first.point)
        axis = isinstance(first.point, dict) or (d is not None and d.type in ("E6AXIS", "AXIS"))
        if first.kind not in ("PTP", "SPTP") or not (axis or _name(first.point) in GLOBAL_POINTS):
            out.append(Finding(p.src_name, first.line, "init", "the first motion must be a PTP to an axis point"))
    return out


def _name(point: object) -> str:
    return point.upper() if isinstance(point, str) else ""


def _decl(p: Program, point: object) -> Decl | None:
    return p.dat.decls.get(_name(point)) or p.src.decls.get(_name(point))


def _check_points(p: Program) -> list[Finding]:
    out = []
    for s in _motions(p.src):
        if isinstance(s.point, str) and s.point.upper() not in GLOBAL_POINTS and _decl(p, s.point) is None:
            out.append(Finding(p.src_name, s.line, "undeclared", f"{s.kind} {s.point}: {s.point} is not declared"))
    for s in p.src.statements:  # the inline forms' motion data, point data and ArcTech data sets
        names: list[str] = []
        if s.kind == "ASSIGN" and (m := re.match(r"^\s*([LFP]DAT_ACT)\s*=\s*(\w+)\s*$", s.text, re.I)):
            names = [m.group(2)]
        elif s.kind in ("ARCMAIN", "TRIGGER") and (m := re.search(r"ArcMainNG\s*\(\s*#\w+\s*,([^)]*)\)", s.text)):
            names = [a.strip() for a in m.group(1).split(",")]
        for name in names:
            if _decl(p, name) is None:
                out.append(Finding(p.src_name, s.line, "undeclared", f"{name} is not declared"))
    for d in p.dat.decls.values():
        if d.type in ("E6POS", "POS") and isinstance(d.value, dict) and not {"S", "T"} <= set(d.value):
            out.append(Finding(p.dat_name, d.line, "status_turn", f"{d.name} has no S and T"))
    return out


def _check_arc(p: Program) -> list[Finding]:
    out: list[Finding] = []
    burning_since = 0  # line of the arc's start, 0 when off
    waited, depth = True, 0  # the arc-established input waited for; IF depth (an error branch is no arc off)
    for s in p.src.statements:
        depth += (s.kind == "IF") - (s.kind == "ENDIF")
        if s.kind == "FOLD" and (m := _ARC_FOLD.match(s.folds[-1] if s.folds else "")):
            kind, wdat = m.group(1).upper(), m.group(2)
            if kind == "ARCON" and burning_since:
                out.append(Finding(p.src_name, s.line, "arc", f"ARC_ON while the arc of line {burning_since} burns"))
            if kind != "ARCON" and not burning_since:
                out.append(Finding(p.src_name, s.line, "arc", f"{kind[:3]}_{kind[3:]} with no arc burning"))
            d = p.dat.decls.get(wdat.upper())
            if d is None or d.type != "STARCDAT_T" or not isinstance(d.value, dict):
                out.append(Finding(p.src_name, s.line, "arc", f"weld data set {wdat} is not declared (stArcDat_T)"))
            elif missing := [part for part in _PARTS[kind] if part not in d.value]:
                out.append(Finding(p.dat_name, d.line, "arc", f"{wdat} has no {', '.join(missing)} data"))
            motions = [m for m in _motions(p.src) if s.folds[-1] in m.folds]
            if len(motions) != 1:
                out.append(Finding(p.src_name, s.line, "arc", f"{kind[:3]}_{kind[3:]} holds {len(motions)} motions,"
                                   " not one"))  # fmt: skip
            burning_since = s.line if kind != "ARCOFF" else 0
            continue
        up = re.sub(r"\s+", "", s.text.upper())
        if depth and s.kind == "ASSIGN":
            continue
        if s.kind == "ASSIGN" and re.match(r"^\$OUT\[\d+\]=TRUE", up):
            burning_since, waited = s.line, False
        elif s.kind == "WAIT" and "$IN[" in up:
            waited = True
        elif s.kind == "ASSIGN" and re.match(r"^\$OUT\[\d+\]=FALSE", up):
            burning_since = 0 if waited else burning_since
        elif s.kind in ("PTP", "SPTP") and burning_since and not any(_ARC_FOLD.match(f) for f in s.folds):
            out.append(Finding(p.src_name, s.line, "arc", f"PTP while the arc of line {burning_since} burns"))
        elif s.kind in ("LIN", "CIRC") and burning_since and not waited:
            out.append(Finding(p.src_name, s.line, "arc", "welding motion before WAIT FOR the arc-established input"))
            waited = True
    if burning_since:
        out.append(Finding(p.src_name, burning_since, "arc", "the arc switched on here is never switched off"))
    return out


def _xyz(p: Program, point: object) -> np.ndarray | None:
    """A motion's point as (3,) [mm] in the base (a declared or inline E6POS/POS), or None (an axis point)."""
    v = point if isinstance(point, dict) else (d.value if (d := _decl(p, point)) is not None else None)
    if not isinstance(v, dict) or not {"X", "Y", "Z"} <= set(v):
        return None
    return np.array([float(v["X"]), float(v["Y"]), float(v["Z"])])


def check_circles(p: Program) -> list[Finding]:
    """Each circular move (``circ``): its start (the previous motion's end), auxiliary and end points not on one
    line; its CA the angle they turn through; the three on the circle stated before it (``;- circle r = ...``,
    the planned path's), within :data:`CIRCLE_TOL_MM`, and the stated angle its CA. Each chord of a curved weld
    within the tolerance it states."""
    out: list[Finding] = []
    comments = list(p.src.comments)
    start: np.ndarray | None = None
    last_line = 0
    for s in _motions(p.src):
        stated = [t for n, t in comments if last_line < n < s.line]
        if s.kind in ("CIRC", "SCIRC"):
            out += _check_circle(p, s, start, stated)
        for t in stated:
            if (c := _CHORD.search(t)) is not None and float(c.group(1)) > float(c.group(2)) + 1e-9:
                out.append(
                    Finding(p.src_name, s.line, "circ", f"chord {c.group(1)} mm from the path > {c.group(2)} mm")
                )
        start, last_line = _xyz(p, s.point), s.line
    return out


def _check_circle(p: Program, s: Statement, start: np.ndarray | None, stated: list[str]) -> list[Finding]:
    aux, end = _xyz(p, s.aux), _xyz(p, s.point)
    if start is None or aux is None or end is None:
        return [
            Finding(p.src_name, s.line, "circ", "CIRC whose start, auxiliary or end point is not a Cartesian point")
        ]
    circle = circle_through(start, aux, end)
    if circle is None:
        return [Finding(p.src_name, s.line, "circ", "CIRC: start, auxiliary and end points on one line")]
    out = []
    sweep = float(np.degrees(circle[2]))
    if s.ca is not None and abs(abs(s.ca) - sweep) > ANGLE_TOL_DEG:
        out.append(Finding(p.src_name, s.line, "circ", f"CA {s.ca:g} deg, but the points turn through {sweep:.3f} deg"))
    plan = next((c for t in stated if (c := _CIRCLE.search(t)) is not None), None)
    if plan is not None:
        r = float(plan.group(1))
        centre = np.array([float(plan.group(k)) for k in (2, 3, 4)])
        for what, q in (("start", start), ("auxiliary point", aux), ("end", end)):
            off = abs(float(np.linalg.norm(q - centre)) - r)
            if off > CIRCLE_TOL_MM:
                out.append(Finding(p.src_name, s.line, "circ", f"the {what} lies {off:.3f} mm off the planned circle"
                                   f" (r = {r:.3f} mm; tolerance {CIRCLE_TOL_MM} mm)"))  # fmt: skip
        if abs(float(plan.group(5)) - sweep) > ANGLE_TOL_DEG:
            out.append(Finding(p.src_name, s.line, "circ", f"turns {sweep:.3f} deg, the plan {plan.group(5)} deg"))
    return out
