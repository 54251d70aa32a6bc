"""PLY and PCD parsed with numpy for :mod:`cell.perception.cloud_files`: the header checked against the body, only x,
y, z read; a body shorter than its header, a value that is not a number or a variant not read here is a
:class:`~cell.errors.CloudFileError` (the formats read: docs/locate.md, "What it reads")."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import numpy.typing as npt

from cell.errors import CloudFault, CloudFileError

_PLY_TYPES = {
    "char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2", "int16": "i2",
    "ushort": "u2", "uint16": "u2", "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
    "float": "f4", "float32": "f4", "double": "f8", "float64": "f8",
}  # fmt: skip
_PLY_FORMATS = {"ascii": "", "binary_little_endian": "<", "binary_big_endian": ">"}
_PCD_DATA = ("ascii", "binary", "binary_compressed")
_MAX_HEADER = 1 << 16  # [bytes] a header is a few hundred bytes; past this the file is not one


@dataclass(frozen=True)
class Body:
    """What a file holds: ``count`` points, their coordinates (count, 3) as written (None when ``compressed``)."""

    count: int
    xyz: npt.NDArray[np.float64] | None
    compressed: bool = False


def _fail(path: Path, what: str, valid: str, code: CloudFault = CloudFault.MALFORMED) -> CloudFileError:
    return CloudFileError(f"point cloud {str(path)!r}: {what}; valid: {valid}", code=code, path=str(path))


def _header_lines(path: Path, data: bytes, last: bytes, kind: str) -> tuple[list[str], int]:
    """The header's lines (CR stripped, decoded) up to the one starting with ``last``, and the body's offset."""
    lines, at = [], 0
    while at < min(len(data), _MAX_HEADER):
        end = data.find(b"\n", at)
        if end < 0:
            break
        raw = data[at:end].rstrip(b"\r")
        at = end + 1
        lines.append(raw.decode("ascii", errors="replace"))
        if raw.split()[:1] == [last]:
            return lines, at
    raise _fail(path, f"its {kind} header has no {last.decode()!r} line", f"a complete {kind} header")


def _floats(path: Path, tokens: list[bytes]) -> npt.NDArray[np.float64]:
    try:
        return np.array(tokens, dtype=np.float64)
    except ValueError:
        bad = next(t for t in tokens if not _is_number(t))
        raise _fail(path, f"the value {bad[:20].decode(errors='replace')!r} is not a number", "numbers") from None


def _is_number(token: bytes) -> bool:
    try:
        float(token)
    except ValueError:
        return False
    return True


def _too_short(path: Path, got: int, n: int, unit: str) -> CloudFileError:
    return _fail(path, f"its body holds {got} {unit} where its header says {n} points (truncated?)", "a whole file")


def parse_ply(path: Path, data: bytes) -> Body:
    """The vertex element's x, y, z of a PLY file's bytes ``data``."""
    lines, offset = _header_lines(path, data, b"end_header", "PLY")
    fmt: str | None = None
    elements: list[tuple[str, int, list[tuple[str, str]]]] = []  # name, count, (property, dtype or "list")
    for line in lines[1:-1]:
        words = line.split()
        if not words or words[0] in ("comment", "obj_info"):
            continue
        if words[0] == "format" and len(words) >= 2:
            fmt = words[1]
        elif words[0] == "element" and len(words) == 3 and words[2].isdigit():
            elements.append((words[1], int(words[2]), []))
        elif words[0] == "property" and elements and len(words) >= 3:
            kind = "list" if words[1] == "list" else _PLY_TYPES.get(words[1], "?")
            if kind == "?":
                raise _fail(path, f"property type {words[1]!r}", f"one of {', '.join(_PLY_TYPES)}")
            elements[-1][2].append((words[-1], kind))
        else:
            raise _fail(path, f"the PLY header line {line[:60]!r} is not PLY", "format, element, property, comment")
    if fmt not in _PLY_FORMATS:
        raise _fail(path, f"PLY format {fmt!r}", f"format {', '.join(_PLY_FORMATS)}")
    names = [e[0] for e in elements]
    if "vertex" not in names:
        raise _fail(
            path, f"its PLY header has no vertex element (elements: {', '.join(names) or 'none'})", "an element vertex"
        )
    v = names.index("vertex")
    count, props = elements[v][1], elements[v][2]
    columns = [p[0] for p in props]
    if not {"x", "y", "z"} <= set(columns):
        raise _fail(
            path,
            f"its vertex element has no x, y, z (properties: {', '.join(columns) or 'none'})",
            "properties x, y, z",
        )
    if any(kind == "list" for e in elements[: v + 1] for _, kind in e[2]):
        raise _fail(
            path,
            "a list property in or before the vertex element is not read here",
            "scalar vertex properties (save the cloud as points)",
            CloudFault.UNSUPPORTED,
        )
    if count == 0:
        return Body(0, np.zeros((0, 3)))
    cols = [columns.index(c) for c in ("x", "y", "z")]
    if fmt == "ascii":
        rows = [r for r in data[offset:].splitlines() if r.strip()]
        skip = sum(e[1] for e in elements[:v])
        mine = rows[skip : skip + count]
        if len(mine) < count:
            raise _too_short(path, len(mine), count, "vertex rows")
        tokens = b" ".join(mine).split()
        if len(tokens) != count * len(props):
            raise _fail(path, f"its vertex rows hold {len(tokens)} values, not {count} x {len(props)}", "whole rows")
        return Body(count, _floats(path, tokens).reshape(count, len(props))[:, cols])
    order = _PLY_FORMATS[fmt]
    for _, n, eprops in elements[:v]:
        offset += n * np.dtype([(f"p{i}", order + k) for i, (_, k) in enumerate(eprops)]).itemsize
    dtype = np.dtype([(f"p{i}", order + k) for i, (_, k) in enumerate(props)])
    got = max(0, len(data) - offset) // dtype.itemsize
    if got < count:
        raise _too_short(path, got, count, "vertices")
    table = np.frombuffer(data, dtype=dtype, count=count, offset=offset)
    return Body(count, np.stack([table[f"p{c}"].astype(np.float64) for c in cols], axis=1))


def parse_pcd(path: Path, data: bytes) -> Body:
    """The x, y, z fields of a PCD file's bytes ``data`` (ascii or binary; binary_compressed only checked)."""
    lines, offset = _header_lines(path, data, b"DATA", "PCD")
    head: dict[str, list[str]] = {}
    for line in lines:
        words = line.split()
        if words and not words[0].startswith("#"):
            head[words[0].upper()] = words[1:]
    fields = head.get("FIELDS", [])
    if not {"x", "y", "z"} <= set(fields):
        raise _fail(
            path, f"its PCD FIELDS are {' '.join(fields) or 'missing'}, without x y z", "FIELDS including x y z"
        )
    counts = head.get("COUNT", ["1"] * len(fields))
    sizes, types = head.get("SIZE", []), head.get("TYPE", [])
    if not len(sizes) == len(types) == len(counts) == len(fields):
        raise _fail(path, "its PCD SIZE, TYPE and COUNT do not match FIELDS", "one SIZE, TYPE and COUNT per field")
    try:
        n_count = [int(c) for c in counts]
        points = int(head["POINTS"][0]) if "POINTS" in head else int(head["WIDTH"][0]) * int(head["HEIGHT"][0])
    except (KeyError, IndexError, ValueError):
        raise _fail(path, "its PCD POINTS (or WIDTH and HEIGHT) are not whole numbers", "POINTS N") from None
    kinds = []
    for f, s, t, c in zip(fields, sizes, types, n_count, strict=True):
        kind = {"F": "f", "I": "i", "U": "u"}.get(t.upper(), "?") + s
        if kind not in ("f4", "f8", "i1", "i2", "i4", "i8", "u1", "u2", "u4", "u8"):
            raise _fail(path, f"field {f!r} has TYPE {t} SIZE {s}", "TYPE F (SIZE 4, 8), I or U (SIZE 1, 2, 4, 8)")
        if f in ("x", "y", "z") and c != 1:
            raise _fail(path, f"field {f!r} has COUNT {c}", "COUNT 1 for x, y, z")
        kinds.append((kind, c))
    mode = (head["DATA"] or ["?"])[0].lower()
    if mode not in _PCD_DATA:
        raise _fail(path, f"PCD DATA {mode!r}", f"DATA {', '.join(_PCD_DATA)}", CloudFault.UNSUPPORTED)
    if points == 0:
        return Body(0, np.zeros((0, 3)))
    starts = np.cumsum([0, *n_count])  # the first column of each field
    cols = [int(starts[fields.index(c)]) for c in ("x", "y", "z")]
    if mode == "ascii":
        tokens = data[offset:].split()
        width = int(starts[-1])
        if len(tokens) < points * width:
            raise _too_short(path, len(tokens) // width, points, "rows")
        if len(tokens) > points * width:
            raise _fail(path, f"its body holds {len(tokens)} values, more than {points} x {width}", "POINTS rows")
        return Body(points, _floats(path, tokens).reshape(points, width)[:, cols])
    dtype = np.dtype([(f"f{i}", "<" + k, (c,)) if c > 1 else (f"f{i}", "<" + k) for i, (k, c) in enumerate(kinds)])
    if mode == "binary":
        got = max(0, len(data) - offset) // dtype.itemsize
        if got < points:
            raise _too_short(path, got, points, "rows")
        table = np.frombuffer(data, dtype=dtype, count=points, offset=offset)
        return Body(points, np.stack([table[f"f{fields.index(c)}"].astype(np.float64) for c in "xyz"], axis=1))
    if len(data) < offset + 8:
        raise _too_short(path, 0, points, "rows")
    packed, unpacked = (int(v) for v in np.frombuffer(data, dtype="<u4", count=2, offset=offset))
    if unpacked != points * dtype.itemsize or len(data) < offset + 8 + packed:
        raise _fail(
            path,
            f"its compressed block ({packed} bytes of {len(data) - offset - 8}, {unpacked} unpacked) does not hold"
            f" {points} points of {dtype.itemsize} bytes",
            "an intact binary_compressed PCD",
        )
    return Body(points, None, compressed=True)
