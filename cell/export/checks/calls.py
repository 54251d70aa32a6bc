"""``cell krl check`` across programs: a main program calling others, and what programs that run on one controller
must agree on (the checks ``call``, ``operator_stop``, ``home``, ``setup``: docs/programs.md)."""

from __future__ import annotations

import itertools
import re
from collections.abc import Collection, Sequence
from dataclasses import replace as dc_replace
from pathlib import Path
from typing import Any

import numpy as np

from cell.export.checks.kinematics import check_kinematics, frame_of
from cell.export.checks.positioner import check_positioner, stated_base, stated_positioner, turning_base
from cell.export.checks.program import Finding, Program, check_program, read_programs, stated_axis
from cell.export.checks.read import Statement, read_krl
from cell.types.robot import Kinematics

KSS_ROUTINES = frozenset(
    {"BAS", "SET_CD_PARAMS", "IR_STOPM", "ERR_CLEAR", "ARCMAINNG", "SET_KRLMSG", "SET_KRLDLG", "CLEAR_KRLMSG",
     "EXISTS_KRLMSG", "EXISTS_KRLDLG", "CLEAR_MSGBUFFER", "MSGNOTIFY", "MSGSTATE", "MSGQUIT", "MSGDIALOG",
     "MSGLOOP", "MSGWAIT"}
)  # fmt: skip
_OPEN = {"IF", "WHILE", "REPEAT", "LOOP", "FOR"}
_CLOSE = {"ENDIF", "ENDWHILE", "UNTIL", "ENDLOOP", "ENDFOR"}
_WAITING = ("EXISTS_KRLMSG(", "EXISTS_KRLDLG(")
_SET_MSG = re.compile(r"Set_KrlMsg\s*\(\s*#\w+\s*,\s*(\w+)|Set_KrlDlg\s*\(\s*(\w+)", re.I)
MSG_TXT_MAX = 80  # KrlMsg_T.Msg_Txt[] is a CHAR[80]
_BASE = re.compile(r"^BAS\s*\(\s*#BASE\s*,\s*(\d+)\s*\)", re.I)


def _find_src(folder: Path, name: str) -> Path | None:
    return next((p for p in sorted(folder.glob("*")) if p.suffix.lower() == ".src" and p.stem.upper() == name), None)


def read_program(src: Path) -> tuple[Program | None, list[Finding]]:
    """The program of one ``NAME.src`` (or its ``NAME.dat``) with its .dat; a finding when the .dat is missing."""
    src = _find_src(src.parent, src.stem.upper()) or src
    dat = next((p for p in (src.with_suffix(".dat"), src.with_suffix(".DAT")) if p.is_file()), None)
    if not src.is_file() or src.suffix.lower() != ".src":
        return None, [Finding(src.name, 0, "files", f"no {src.stem}.src: give a program's .src (or its folder)")]
    if dat is None:
        return None, [Finding(src.name, 0, "files", f"no {src.stem}.dat beside {src.name}")]
    s = read_krl(src.read_text(encoding="ascii", errors="replace"), "src")
    d = read_krl(dat.read_text(encoding="ascii", errors="replace"), "dat")
    return Program(src.stem, s, d, src.name, dat.name), []


def program_calls(p: Program) -> list[tuple[str, Statement]]:
    """The calls of routines other than KSS's (:data:`KSS_ROUTINES`) in order: (upper-case name, statement)."""
    return [(s.callee, s) for s in p.src.statements if s.callee is not None and s.callee not in KSS_ROUTINES]


def read_target(path: Path) -> tuple[list[Program], list[Finding]]:
    """A folder's programs, or one program file and every program it calls (from its folder, in turn)."""
    if path.is_dir():
        return read_programs(path)
    first, findings = read_program(path)
    programs: list[Program] = []
    todo = [first] if first is not None else []
    while todo:
        p = todo.pop(0)
        programs.append(p)
        for name, _ in program_calls(p):
            if any(q.name.upper() == name for q in programs + todo):
                continue
            src = _find_src(path.parent, name)
            if src is not None:
                q, more = read_program(src)
                findings += more
                todo += [q] if q is not None else []
    return programs, findings


def _welds(p: Program) -> bool:
    """Whether the program switches an arc on (an ArcTech ARC_ON fold or a plain ``$OUT[n] = TRUE``)."""
    return any(
        (s.kind == "FOLD" and re.match(r"^ARCON\b", s.folds[-1] if s.folds else "", re.I))
        or (s.kind == "ASSIGN" and re.match(r"^\$OUT\[\d+\]\s*=\s*TRUE", s.text, re.I))
        for s in p.src.statements
    )


def _stops(between: Sequence[Statement]) -> bool:
    """Whether these statements stop for the operator (module docstring)."""
    depth, asked = 0, False
    for s in between:
        t = re.sub(r"\s+", "", s.text.upper())
        if depth == 0 and (
            s.kind == "HALT"
            or (s.kind == "WAIT" and t.startswith("WAITFOR") and "$IN[" in t)
            or t.startswith(("MSGQUIT(", "MSGDIALOG("))
            or re.match(r"^\w+=MSG(QUIT|DIALOG)\(", t)
        ):
            return True
        if "SET_KRLMSG(#QUIT" in t or "SET_KRLDLG(" in t:
            asked = True
        if asked and s.kind in ("WHILE", "UNTIL") and any(w in t for w in _WAITING):
            return True
        depth += (s.kind in _OPEN) - (s.kind in _CLOSE)
    return False


_MOVES = ("PTP", "SPTP", "LIN", "SLIN", "CIRC", "SCIRC")


def _at_home(motions: Sequence[Statement], last: bool) -> bool | None:
    """Whether the first (``last``: the last) of these motions is ``PTP XHOME``; None when there is none."""
    if not motions:
        return None
    s = motions[-1] if last else motions[0]
    return s.kind in ("PTP", "SPTP") and isinstance(s.point, str) and s.point.upper() == "XHOME"


def _motions(p: Program) -> list[Statement]:
    return [s for s in p.src.statements if s.kind in _MOVES]


def _check_messages(p: Program) -> list[Finding]:
    """Each message a ``Set_KrlMsg`` / ``Set_KrlDlg`` shows is a declared KrlMsg_T with a text of at most 80
    characters (``Msg_Txt[]`` is a CHAR[80])."""
    out = []
    for s in p.src.statements:
        m = _SET_MSG.search(s.text)
        if m is None:
            continue
        name = m.group(1) or m.group(2)
        d = p.dat.decls.get(name.upper()) or p.src.decls.get(name.upper())
        if d is None or d.type != "KRLMSG_T":
            out.append(Finding(p.src_name, s.line, "operator_stop", f"the message {name} is not declared (KrlMsg_T)"))
        elif isinstance(d.value, dict) and len(str(d.value.get("MSG_TXT", ""))) > MSG_TXT_MAX:
            n = len(str(d.value["MSG_TXT"]))
            out.append(Finding(p.dat_name, d.line, "operator_stop", f"{name}'s text has {n} characters, over the"
                               f" {MSG_TXT_MAX} of Msg_Txt[]"))  # fmt: skip
    return out


def check_calls(p: Program, programs: Collection[Program]) -> list[Finding]:
    """The checks of a program calling others (module docstring): ``call``, ``operator_stop``, ``home``."""
    by_name = {q.name.upper(): q for q in programs}
    calls = program_calls(p)
    out: list[Finding] = []
    for name, s in calls:
        if name == p.name.upper():
            out.append(Finding(p.src_name, s.line, "call", f"{p.name} calls itself"))
        elif name not in by_name:
            out.append(Finding(p.src_name, s.line, "call", f"{name}( ) is neither a program in the folder nor a KSS"
                               " routine this checker knows"))  # fmt: skip
    out += _check_messages(p)
    called = [(n, s) for n, s in calls if n in by_name and n != p.name.upper()]
    welding = [(n, s) for n, s in called if _welds(by_name[n])]
    for (a, sa), (b, sb) in itertools.pairwise(welding):
        if stated_positioner(by_name[b]):  # a positioner turns the part for it: nobody need stop the program
            continue
        if not _stops([s for s in p.src.statements if sa.line < s.line < sb.line]):
            msg = f"{b} runs after {a} with no operator stop between them (HALT, a message or dialog waited for,"
            out.append(Finding(p.src_name, sb.line, "operator_stop", msg + " or WAIT FOR an input)"))
    if called:
        for last, (n, s) in ((False, called[0]), (True, called[-1])):
            mine = [m for m in _motions(p) if (m.line > s.line if last else m.line < s.line)]
            ok = _at_home(mine, last) if mine else _at_home(_motions(by_name[n]), last)
            if not ok:
                where, side = ("end", "after") if last else ("start", "before")
                out.append(Finding(p.src_name, s.line, "home", f"{p.name} does not {where} at home: no PTP XHOME"
                                   f" {side} {n}( ), nor in {n} itself"))  # fmt: skip
    return out


def _values_differ(a: Any, b: Any) -> bool:
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() != b.keys() or any(_values_differ(a[k], b[k]) for k in a)
    if isinstance(a, float) and isinstance(b, float):
        return abs(a - b) > 1e-6
    return bool(a != b)


def check_setup(programs: Sequence[Program]) -> list[Finding]:
    """TOOL_DATA[n] / BASE_DATA[n] given different values by two programs (module docstring)."""
    first: dict[str, tuple[Program, Any]] = {}
    out = []
    for p in programs:
        for key, v in p.src.setup.items():
            if not key.startswith(("TOOL_DATA[", "BASE_DATA[")):
                continue
            if key not in first:
                first[key] = (p, v)
            elif _values_differ(first[key][1], v):
                msg = f"{key} differs from {first[key][0].name}'s: the controller holds one value per index"
                out.append(Finding(p.src_name, 0, "setup", msg + " (give each base of the part its own index)"))
    return out


def fixed_base(p: Program) -> Program:
    """The program as an arm on a fixed base sees it: on a linear track whose axis the header states
    (:func:`~cell.export.checks.program.stated_axis`), each E6POS moved back by its E1 along the axis, so that the
    kinematic check (:mod:`cell.export.checks.kinematics`) finds the configuration the arm reaches it in from where the
    carriage put the base. The program itself when it states no track axis or no base to turn the axis into."""
    axis = stated_axis(p)
    bi = next((m.group(1) for s in p.src.statements if (m := _BASE.match(s.text))), None)
    base = p.src.setup.get(f"BASE_DATA[{bi}]") if bi is not None else None
    if axis is None or not isinstance(base, dict):
        return p
    R_BR = frame_of(base)[:3, :3].T
    decls = dict(p.dat.decls)
    for key, d in p.dat.decls.items():
        e1 = d.value.get("E1") if d.type in ("E6POS", "POS") and isinstance(d.value, dict) else None
        if isinstance(e1, float) and e1 != 0.0:
            shift_B = R_BR @ (-e1 * np.asarray(axis))  # [mm]
            moved = {**d.value, **{k: float(d.value.get(k, 0.0)) + v for k, v in zip("XYZ", shift_B, strict=True)}}
            decls[key] = dc_replace(d, value=moved)
    return dc_replace(p, dat=dc_replace(p.dat, decls=decls))


def check_all(
    programs: Sequence[Program], robot: Kinematics, e1_limits_mm: tuple[float, float] | None = None
) -> list[Finding]:
    """Every check on every program: :func:`~cell.export.checks.program.check_program` (E1 within ``e1_limits_mm``
    [mm] when given), the kinematics (but for a main program without Cartesian points of its own: it has nothing
    to check there), the calls and the shared setup."""
    out: list[Finding] = []
    for p in programs:
        out += check_program(p, e1_limits_mm)
        cartesian = any(d.type in ("E6POS", "POS") for d in p.dat.decls.values())
        if cartesian or not program_calls(p):
            on_positioner = bool(stated_positioner(p))  # a coordinated weld's circles: the torch nearly still
            out += check_kinematics(turning_base(fixed_base(p)), robot, stated_base(p), circles=on_positioner)
        out += check_positioner(p)
        out += check_calls(p, programs)
    return out + check_setup(programs)
