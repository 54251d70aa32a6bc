"""The project's own KRL reader: the subset the exporter writes plus what a KRL programmer adds around it (header
lines, DEF/DEFDAT, declarations, folds, the setup block, motions, ArcTech calls, control flow, calls). Lines it
cannot read become :class:`Problem` values, never exceptions."""

from __future__ import annotations

import contextlib
import re
from dataclasses import dataclass, field
from typing import Any

_NUM = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")
_IDENT = re.compile(r"[A-Za-z_$][A-Za-z0-9_$]*")
_MOTION = re.compile(r"^(PTP|LIN|CIRC|SPTP|SLIN|SCIRC|PTP_REL|LIN_REL)\s+(.*)$", re.I)
_DECL = re.compile(r"^DECL\s+(?:GLOBAL\s+)?(\w+)\s+(\w+)(\[[^\]]*\])?\s*(?:=\s*(.*))?$", re.I)
_SETUP = re.compile(r"^;-\s*(\w+)(?:\[(\d+)\])?\s*=\s*(\{.*\})")
_CONTROL = ("WHILE", "ENDWHILE", "REPEAT", "UNTIL", "LOOP", "ENDLOOP", "FOR", "ENDFOR", "EXIT")
_CALL = re.compile(r"^(\w+)\s*\(")


@dataclass(frozen=True)
class Problem:
    """A line the reader could not make sense of: ``line`` (1-based) and what was wrong."""

    line: int
    message: str


@dataclass(frozen=True)
class Decl:
    """``DECL type name = value``: value a structure (dict), a scalar, or None when not initialised."""

    type: str
    name: str
    value: Any
    line: int


@dataclass(frozen=True)
class Statement:
    """One statement: ``kind`` (``PTP``, ``LIN``, ... for motions; ``ARCMAIN``, ``TRIGGER``, ``WAIT``, ``IF``,
    ``ENDIF``, ``HALT``, ``ASSIGN``, ``CALL``, ``FOLD``, ``ENDFOLD``, ``INTERRUPT``; the loops' ``WHILE`` /
    ``ENDWHILE``, ``REPEAT`` / ``UNTIL``, ``LOOP`` / ``ENDLOOP``, ``FOR`` / ``ENDFOR``, ``EXIT``), the text, its
    line, the motion's point (a name, or an inline structure) and the fold headers it sits in (outermost first)."""

    @property
    def callee(self) -> str | None:
        """The routine a ``CALL`` statement calls (``NAME( )``, ``BAS(...)``), upper-case; None for other kinds."""
        m = _CALL.match(self.text) if self.kind == "CALL" else None
        return m.group(1).upper() if m is not None else None

    kind: str
    text: str
    line: int
    point: Any = None
    folds: tuple[str, ...] = ()
    aux: Any = None  # a CIRC's auxiliary point (a name or an inline structure)
    ca: float | None = None  # a CIRC's circular angle CA [deg], None when not given


@dataclass
class KrlFile:
    """One file read: its module name (DEF/DEFDAT), whether it reached END/ENDDAT, declarations by upper-case
    name, statements in order, the setup block's values by ``NAME[n]``, the problems found and the whole-line
    comments (the header states a linear track's limits there)."""

    kind: str  # "src" | "dat"
    module: str | None = None
    closed: bool = False
    decls: dict[str, Decl] = field(default_factory=dict)
    statements: list[Statement] = field(default_factory=list)
    setup: dict[str, Any] = field(default_factory=dict)
    problems: list[Problem] = field(default_factory=list)
    open_folds: int = 0
    comments: list[tuple[int, str]] = field(default_factory=list)  # (line, text) of each whole-line comment


class _Values:
    """A recursive-descent reader of one KRL value."""

    def __init__(self, text: str) -> None:
        self.s, self.i = text, 0

    def _ws(self) -> None:
        while self.i < len(self.s) and self.s[self.i] in " \t":
            self.i += 1

    def value(self) -> Any:
        self._ws()
        if self.i >= len(self.s):
            raise ValueError("a value is missing")
        c = self.s[self.i]
        if c == "{":
            return self.struct()
        if c == '"':
            end = self.s.find('"', self.i + 1)
            if end < 0:
                raise ValueError("a string is not closed")
            out = self.s[self.i + 1 : end]
            self.i = end + 1
            return out
        if c == "#":
            m = _IDENT.match(self.s, self.i + 1)
            if m is None:
                raise ValueError(f"an enum value is malformed at column {self.i + 1}")
            self.i = m.end()
            return "#" + m.group()
        m = _NUM.match(self.s, self.i)
        if m is not None:
            self.i = m.end()
            return float(m.group())
        m = _IDENT.match(self.s, self.i)
        if m is not None:
            self.i = m.end()
            word = m.group().upper()
            return {"TRUE": True, "FALSE": False}.get(word, m.group())
        raise ValueError(f"unexpected {c!r} at column {self.i + 1}")

    def struct(self) -> dict[str, Any]:
        self.i += 1  # '{'
        out: dict[str, Any] = {}
        while True:
            self._ws()
            if self.i < len(self.s) and self.s[self.i] == "}":
                self.i += 1
                return out
            m = _IDENT.match(self.s, self.i)
            if m is None:
                raise ValueError(f"a field name is expected at column {self.i + 1}")
            self.i = m.end()
            if self.s.startswith("[]", self.i):
                self.i += 2
            out[m.group().upper()] = self.value()
            self._ws()
            if self.i < len(self.s) and self.s[self.i] == ",":
                self.i += 1
            elif self.i >= len(self.s) or self.s[self.i] != "}":
                raise ValueError(f"',' or '}}' expected at column {self.i + 1}")


def parse_value(text: str) -> Any:
    """One KRL value (a structure, number, string, enum, boolean or name); ValueError when malformed."""
    r = _Values(text.strip())
    v = r.value()
    r._ws()
    if r.i != len(r.s):
        raise ValueError(f"unexpected text after the value: {r.s[r.i :]!r}")
    return v


def _code(line: str) -> tuple[str, str]:
    """(code, comment) of a line: the comment starts at the first ';' outside a string."""
    in_str = False
    for i, c in enumerate(line):
        if c == '"':
            in_str = not in_str
        elif c == ";" and not in_str:
            return line[:i].strip(), line[i:]
    return line.strip(), ""


def read_krl(text: str, kind: str) -> KrlFile:
    """Read the text of a ``.src`` (kind ``src``) or ``.dat`` (kind ``dat``) file."""
    f = KrlFile(kind)
    folds: list[str] = []
    for n, raw in enumerate(text.splitlines(), start=1):
        code, comment = _code(raw)
        up_comment = comment.upper()
        if not code:
            if up_comment.startswith(";FOLD"):
                folds.append(comment[5:].strip())
                f.statements.append(Statement("FOLD", comment, n, folds=tuple(folds)))
            elif up_comment.startswith(";ENDFOLD"):
                if not folds:
                    f.problems.append(Problem(n, "ENDFOLD without a FOLD"))
                else:
                    folds.pop()
                f.statements.append(Statement("ENDFOLD", comment, n, folds=tuple(folds)))
            elif (m := _SETUP.match(comment)) is not None:
                key = m.group(1).upper() + (f"[{m.group(2)}]" if m.group(2) else "")
                with contextlib.suppress(ValueError):  # a free comment that only looks like a setup line
                    f.setup[key] = parse_value(m.group(3))
            if comment and not up_comment.startswith((";FOLD", ";ENDFOLD")):
                f.comments.append((n, comment))
            continue
        if f.closed:
            f.problems.append(Problem(n, f"text after {'END' if kind == 'src' else 'ENDDAT'}: {code!r}"))
            continue
        try:
            _statement(f, code, n, tuple(folds))
        except ValueError as e:
            f.problems.append(Problem(n, f"cannot read {code[:60]!r}: {e}"))
    f.open_folds = len(folds)
    return f


def _split_first(text: str) -> tuple[str, str, str]:
    """(first, ",", rest) of a comma-separated list whose items may be structures in braces."""
    depth = 0
    for i, c in enumerate(text):
        depth += (c == "{") - (c == "}")
        if c == "," and depth == 0:
            return text[:i].strip(), ",", text[i + 1 :].strip()
    raise ValueError("a CIRC needs an auxiliary point and an end point: CIRC AUX, END")


def _statement(f: KrlFile, code: str, n: int, folds: tuple[str, ...]) -> None:
    up = code.upper()
    if code.startswith("&"):
        return
    if up.startswith("DEFDAT "):
        f.module = code.split()[1]
        return
    if up.startswith("DEF ") or up.startswith("GLOBAL DEF "):
        m = re.match(r"^(?:GLOBAL\s+)?DEF\s+(\w+)\s*\(", code, re.I)
        if m is None:
            raise ValueError("DEF needs a name and a parameter list: DEF NAME( )")
        f.module = m.group(1)
        return
    if up in ("END", "ENDDAT"):
        if (up == "END") != (f.kind == "src"):
            raise ValueError(f"{up} in a .{f.kind} file")
        f.closed = True
        return
    if up.startswith("DECL "):
        m = _DECL.match(code)
        if m is None:
            raise ValueError("a declaration is DECL TYPE NAME[=value]")
        value = parse_value(m.group(4)) if m.group(4) is not None else None
        f.decls[m.group(2).upper()] = Decl(m.group(1).upper(), m.group(2), value, n)
        return
    if (m := _MOTION.match(code)) is not None:
        target = m.group(2).strip()
        for approx in ("C_DIS", "C_PTP", "C_VEL", "C_ORI", "C_SPL"):
            target = re.sub(rf"\s+{approx}\b.*$", "", target, flags=re.I)
        ca: float | None = None
        if (c := re.search(r"\s*,?\s*\bCA\s+([+-]?[\d.]+(?:[eE][+-]?\d+)?)\s*$", target, re.I)) is not None:
            ca, target = float(c.group(1)), target[: c.start()].strip()
        aux: Any = None
        if m.group(1).upper() in ("CIRC", "SCIRC"):
            first, _, target = _split_first(target)
            aux = parse_value(first) if first.startswith("{") else first
        point: Any = parse_value(target) if target.startswith("{") else target.split(",")[-1].strip()
        f.statements.append(Statement(m.group(1).upper(), code, n, point, folds, aux, ca))
        return
    head = up.split("(")[0].split()[0] if up.split() else up
    kinds = {"ARCMAINNG": "ARCMAIN", "GLOBAL": "INTERRUPT", "BAS": "CALL"}
    kinds.update((k, k) for k in ("TRIGGER", "WAIT", "IF", "ENDIF", "ELSE", "HALT", "INTERRUPT", *_CONTROL))
    if head in kinds:
        f.statements.append(Statement(kinds[head], code, n, folds=folds))
        return
    if "=" in code and _IDENT.match(code):
        f.statements.append(Statement("ASSIGN", code, n, folds=folds))
        return
    if re.match(r"^\w+\s*\(.*\)$", code):
        f.statements.append(Statement("CALL", code, n, folds=folds))
        return
    raise ValueError("not a statement this reader knows")
