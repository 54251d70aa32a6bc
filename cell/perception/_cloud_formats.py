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
_MAX_COUNT = 1 << 12  # values of one PCD field in a row (a 308-bin FPFH histogram is among the largest)


@dataclass(frozen=True)
class Body:
    """What a file holds: ``count`` points, their coordinates (count, 3) as written (None when ``compressed``), and
    one line per harmless inconsistency read past (``notes``: stray bytes after the last row)."""

    count: int
    xyz: npt.NDArray[np.float64] | None
    compressed: bool = False
    notes: tuple[str, ...] = ()


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


def _typed(path: Path, table: npt.NDArray[np.float64], columns: list[tuple[str, str]]) -> npt.NDArray[np.float64]:
    """``table`` (rows, columns) of an ASCII body, once each integer column (``columns``: name, numpy kind) is
    checked to hold whole numbers its type can hold."""
    for j, (name, kind) in enumerate(columns):
        if kind[0] not in "iu":
            continue
        info, col = np.iinfo(kind), table[:, j]
        bad = ~np.isfinite(col) | (col != np.round(col)) | (col < info.min) | (col > info.max)
        if bad.any():
            raise _fail(
                path,
                f"its {name!r} values are of type {kind} but {int(bad.sum())} are not (e.g. {col[bad][0]:g})",
                f"whole numbers from {info.min} to {info.max}, or a float type",
            )
    return table


def _is_number(token: bytes) -> bool:
    try:
        float(token)
    except ValueError:
        return False
    return True


def _too_short(path: Path, got: int, n: int, unit: str) -> CloudFileError:
    return _fail(path, f"its body holds {got} {unit} where its header says {n} points (truncated?)", "a whole file")


def _rest(path: Path, extra: int, row: int, n: int, what: str) -> tuple[str, ...]:
    """What ``extra`` bytes after the ``n`` rows of ``row`` bytes the header accounts for mean: nothing, a note
    (less than a row: stray bytes, read past), or a CloudFileError (whole rows the header does not count)."""
    if extra <= 0:
        return ()
    if extra >= row:
        raise _fail(
            path,
            f"its body holds {extra} bytes (at least {extra // row} more rows) after the {n} points its {what} says",
            f"a {what} that counts every row",
        )
    return (f"point cloud {str(path)!r}: {extra} stray bytes after its {n} points ignored",)


def _element_bytes(data: bytes, at: int, n: int, props: list[tuple[str, str]], order: str) -> int:
    """The size in bytes of a binary PLY element of ``n`` rows starting at ``at`` (list properties walked: a row of
    one list with the same length everywhere, a mesh's faces, in one step); -1 when the data ends first."""
    if all(not k.startswith("list") for _, k in props):
        return n * np.dtype([(f"p{i}", order + k) for i, (_, k) in enumerate(props)]).itemsize
    if len(props) == 1 and n > 0:
        _, c_type, i_type = props[0][1].split(":")
        c_size, i_size = np.dtype(c_type).itemsize, np.dtype(i_type).itemsize
        if at + c_size > len(data):
            return -1
        first = int(np.frombuffer(data, dtype=order + c_type, count=1, offset=at)[0])
        stride = c_size + first * i_size
        if at + n * stride <= len(data):
            rows = np.ndarray((n,), dtype=order + c_type, buffer=data, offset=at, strides=(stride,))
            if np.all(rows == first):
                return n * stride
    start = at
    if at + n > len(data):  # every row takes at least a byte: the data ends before the rows do
        return -1
    for _ in range(n):  # mixed list lengths: row by row
        for _, kind in props:
            if not kind.startswith("list"):
                at += np.dtype(kind).itemsize
                continue
            _, c_type, i_type = kind.split(":")
            if at + np.dtype(c_type).itemsize > len(data):
                return -1
            length = int(np.frombuffer(data, dtype=order + c_type, count=1, offset=at)[0])
            at += np.dtype(c_type).itemsize + max(length, 0) * np.dtype(i_type).itemsize
        if at > len(data):
            return -1
    return at - start


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
            types = words[2:4] if words[1] == "list" and len(words) == 5 else words[1:2]
            if any(t not in _PLY_TYPES for t in types) or (words[1] == "list" and len(types) != 2):
                raise _fail(path, f"property type {' '.join(words[1:-1])!r}", f"one of {', '.join(_PLY_TYPES)}")
            kind = ":".join(["list", *(_PLY_TYPES[t] for t in types)]) if words[1] == "list" else _PLY_TYPES[types[0]]
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
    if any(columns.count(c) > 1 for c in "xyz"):
        raise _fail(path, f"its vertex properties {', '.join(columns)[:60]} name a coordinate twice", "x, y, z once")
    if any(kind.startswith("list") for e in elements[: v + 1] for _, kind in e[2]):
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
        if len(rows) > sum(e[1] for e in elements):
            raise _fail(
                path,
                f"its body holds {len(rows)} rows where its elements count {sum(e[1] for e in elements)}",
                "element counts that count every row",
            )
        tokens = b" ".join(mine).split()
        if len(tokens) != count * len(props):
            raise _fail(path, f"its vertex rows hold {len(tokens)} values, not {count} x {len(props)}", "whole rows")
        values = _typed(path, _floats(path, tokens).reshape(count, len(props)), list(props))
        return Body(count, values[:, cols])
    order = _PLY_FORMATS[fmt]
    for _, n, eprops in elements[:v]:
        offset += n * np.dtype([(f"p{i}", order + k) for i, (_, k) in enumerate(eprops)]).itemsize
    dtype = np.dtype([(f"p{i}", order + k) for i, (_, k) in enumerate(props)])
    got = max(0, len(data) - offset) // dtype.itemsize
    if got < count:
        raise _too_short(path, got, count, "vertices")
    end = offset + count * dtype.itemsize
    for name, n, eprops in elements[v + 1 :]:
        size = _element_bytes(data, end, n, eprops, order)
        if size < 0 or end + size > len(data):
            raise _fail(path, f"its {name} element ({n} rows) is cut short", "a whole file")
        end += size
    notes = _rest(path, len(data) - end, dtype.itemsize, count, "PLY header")
    table = np.frombuffer(data, dtype=dtype, count=count, offset=offset)
    return Body(count, np.stack([table[f"p{c}"].astype(np.float64) for c in cols], axis=1), notes=notes)


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
    if any(fields.count(c) > 1 for c in "xyz"):
        raise _fail(path, f"its PCD FIELDS {' '.join(fields)[:60]} name a coordinate twice", "x, y and z once each")
    counts = head.get("COUNT", ["1"] * len(fields))
    sizes, types = head.get("SIZE", []), head.get("TYPE", [])
    if not len(sizes) == len(types) == len(counts) == len(fields):
        raise _fail(path, "its PCD SIZE, TYPE and COUNT do not match FIELDS", "one SIZE, TYPE and COUNT per field")
    try:
        n_count = [int(c) for c in counts]
        if "POINTS" not in head and not {"WIDTH", "HEIGHT"} <= set(head):
            raise KeyError("POINTS")
        points = int(head["POINTS"][0]) if "POINTS" in head else int(head["WIDTH"][0]) * int(head["HEIGHT"][0])
        width = int(head["WIDTH"][0]) if "WIDTH" in head else points
        height = int(head["HEIGHT"][0]) if "HEIGHT" in head else 1
    except (KeyError, IndexError, ValueError):
        raise _fail(path, "its PCD POINTS (or WIDTH and HEIGHT) are missing or not whole numbers", "POINTS N") from None
    if min(width, height, points) < 0 or width * height != points:
        raise _fail(
            path,
            f"its PCD WIDTH {width} x HEIGHT {height} and POINTS {points} disagree",
            "whole numbers >= 0 with WIDTH x HEIGHT = POINTS",
        )
    kinds = []
    for f, s, t, c in zip(fields, sizes, types, n_count, strict=True):
        kind = {"F": "f", "I": "i", "U": "u"}.get(t.upper(), "?") + s
        if kind not in ("f4", "f8", "i1", "i2", "i4", "i8", "u1", "u2", "u4", "u8"):
            raise _fail(path, f"field {f!r} has TYPE {t} SIZE {s}", "TYPE F (SIZE 4, 8), I or U (SIZE 1, 2, 4, 8)")
        if (f in ("x", "y", "z") and c != 1) or not 1 <= c <= _MAX_COUNT:
            raise _fail(path, f"field {f!r} has COUNT {c}", f"COUNT 1 for x, y, z, 1 to {_MAX_COUNT} for others")
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
        columns = [(f, k) for f, (k, c) in zip(fields, kinds, strict=True) for _ in range(c)]
        return Body(points, _typed(path, _floats(path, tokens).reshape(points, width), columns)[:, cols])
    dtype = np.dtype([(f"f{i}", "<" + k, (c,)) if c > 1 else (f"f{i}", "<" + k) for i, (k, c) in enumerate(kinds)])
    if mode == "binary":
        got = max(0, len(data) - offset) // dtype.itemsize
        if got < points:
            raise _too_short(path, got, points, "rows")
        notes = _rest(path, len(data) - offset - points * dtype.itemsize, dtype.itemsize, points, "PCD POINTS")
        table = np.frombuffer(data, dtype=dtype, count=points, offset=offset)
        xyz = np.stack([table[f"f{fields.index(c)}"].astype(np.float64) for c in "xyz"], axis=1)
        return Body(points, xyz, notes=notes)
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
    notes = _rest(path, len(data) - offset - 8 - packed, dtype.itemsize, points, "compressed block")
    return Body(points, None, compressed=True, notes=notes)
