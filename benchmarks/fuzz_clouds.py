"""Bad point cloud files, made from a seed, for the fuzz of ``read_cloud`` (``bench_fuzz.py --kind clouds``).

Each case is a small scan (a box on a table, 60 to 2500 points) written in one of six layouts (PLY ascii, binary
little and big endian; PCD ascii, binary, binary_compressed) and then spoilt one way. What a case must get is its
``expect``: ``clean`` (read without a word), ``flag`` (inconsistent: refused or read with a warning line) or
``any`` (a mutation that may or may not leave a valid file, such as a flipped byte: any one-line answer).
"""

from __future__ import annotations

import re
import sys
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

TESTS = Path(__file__).resolve().parents[1] / "tests"
if str(TESTS) not in sys.path:
    sys.path.insert(0, str(TESTS))

from cloud_writers import (  # noqa: E402  (the tests' own writers of the formats)
    pcd_ascii,
    pcd_binary,
    pcd_binary_compressed,
    ply_ascii,
    ply_binary,
)

Points = np.ndarray
LAYOUTS: dict[str, Callable[[Path, Points], Path]] = {
    "ply-ascii": lambda p, x: ply_ascii(p, x, extra=True),
    "ply-binary-le": ply_binary,
    "ply-binary-be": lambda p, x: ply_binary(p, x, big_endian=True),
    "pcd-ascii": pcd_ascii,
    "pcd-binary": pcd_binary,
    "pcd-binary-compressed": pcd_binary_compressed,
}
_COUNT = re.compile(rb"(element vertex |POINTS |WIDTH )(\d+)")


@dataclass(frozen=True)
class Case:
    """One fuzzed file: ``name`` (layout/mutation/index), its bytes, what it must get (``expect``)."""

    name: str
    data: bytes
    expect: str  # clean | flag | any


def scan(rng: np.random.Generator) -> Points:
    """A box of 0.1 to 0.5 m on a 1 m table near the origin, (n, 3) [m], n in [60, 2500]."""
    n = int(rng.integers(60, 2500))
    size = rng.uniform(0.1, 0.5, 3)
    on_box = rng.random(n) < 0.5
    p = rng.uniform(-0.5, 0.5, (n, 3)) * np.where(on_box[:, None], size, [1.0, 1.0, 0.0])
    face = rng.integers(0, 3, n)
    p[on_box, face[on_box]] = np.sign(rng.random(on_box.sum()) - 0.5) * size[face[on_box]] / 2
    p[on_box, 2] += size[2] / 2
    return p + rng.uniform(-1.0, 1.0, 3) * [1.0, 1.0, 0.2]


def _body_at(data: bytes) -> int:
    """Where the body starts (after ``end_header`` or the ``DATA`` line)."""
    for key in (b"end_header", b"\nDATA "):
        at = data.find(key)
        if at >= 0:
            return data.index(b"\n", at + 1) + 1
    return 0


def _write(layout: str, p: Points, tmp: Path) -> bytes:
    return LAYOUTS[layout](tmp, p).read_bytes()


def _set_count(data: bytes, n: int, keep_width: bool) -> bytes:
    head, body = data[: _body_at(data)], data[_body_at(data) :]
    return (
        _COUNT.sub(lambda m: m.group(0) if keep_width and m.group(1) == b"WIDTH " else m.group(1) + b"%d" % n, head)
        + body
    )


def _mutations() -> dict[str, Callable[[np.random.Generator, str, Points, Path], tuple[bytes, str]]]:
    def clean(rng: np.random.Generator, lay: str, p: Points, tmp: Path) -> tuple[bytes, str]:
        return _write(lay, p, tmp), "clean"

    def truncated(rng: np.random.Generator, lay: str, p: Points, tmp: Path) -> tuple[bytes, str]:
        data = _write(lay, p, tmp)
        at = _body_at(data)
        last = data.rstrip().rfind(b"\n") + 1 if "ascii" in lay else len(data)  # an ascii cut loses a whole row
        return data[: int(rng.integers(at, max(at + 1, last)))], "flag"

    def wrong_count(rng: np.random.Generator, lay: str, p: Points, tmp: Path) -> tuple[bytes, str]:
        n = len(p)
        wrong = int(rng.choice([n // 2, n - 1, n + 1, 2 * n, -1, -n, 10**15]))
        data = _set_count(_write(lay, p, tmp), wrong, keep_width=bool(rng.random() < 0.5))
        return data + (rng.bytes(int(rng.integers(1, 4))) if rng.random() < 0.3 else b""), "flag"  # and stray bytes

    def not_finite(rng: np.random.Generator, lay: str, p: Points, tmp: Path) -> tuple[bytes, str]:
        q = p.copy()
        rows = rng.choice(len(q), size=int(rng.integers(1, len(q) + 1)) if rng.random() < 0.2 else 3, replace=False)
        q[rows, rng.integers(0, 3, len(rows))] = rng.choice([np.nan, np.inf, -np.inf], len(rows))
        return _write(lay, q, tmp), "flag"

    def duplicated(rng: np.random.Generator, lay: str, p: Points, tmp: Path) -> tuple[bytes, str]:
        extra = p if rng.random() < 0.5 else p[rng.choice(len(p), size=int(rng.integers(1, 20)))]
        q = np.vstack([p, extra])
        return _write(lay, q[rng.permutation(len(q))] if rng.random() < 0.5 else q, tmp), "flag"

    def far(rng: np.random.Generator, lay: str, p: Points, tmp: Path) -> tuple[bytes, str]:
        if rng.random() < 0.3:  # the whole cloud in millimetres or worse, read as metres
            return _write(lay, p * float(rng.choice([1e3, 1e6, 1e30])), tmp), "flag"
        k = int(rng.integers(1, 4))
        way = rng.normal(size=(k, 3))
        stray = way / np.linalg.norm(way, axis=1, keepdims=True) * float(rng.choice([25.0, 100.0, 1e6, 1e30]))
        return _write(lay, np.vstack([p, stray]), tmp), "flag"

    def wrong_type(rng: np.random.Generator, lay: str, p: Points, tmp: Path) -> tuple[bytes, str]:
        data = _write(lay, p, tmp)
        at = _body_at(data)
        head, body = data[:at], data[at:]
        if lay.startswith("ply"):
            old, new = (b"property float x", b"property int x") if "ascii" in lay else (b"double x", b"float x")
            return head.replace(old, new) + body, "flag"
        if "ascii" in lay:
            return head.replace(b"TYPE F F F F", b"TYPE I F F F") + body, "flag"
        return head.replace(b"SIZE 4 4 4", b"SIZE 8 4 4") + body, "flag"  # the body no longer holds its rows

    def header_bytes(rng: np.random.Generator, lay: str, p: Points, tmp: Path) -> tuple[bytes, str]:
        data = bytearray(_write(lay, p, tmp))
        at = _body_at(bytes(data))
        for i in rng.integers(0, max(1, at), int(rng.integers(1, 4))):
            data[i] = int(rng.integers(0, 256))
        return bytes(data), "any"

    def body_bytes(rng: np.random.Generator, lay: str, p: Points, tmp: Path) -> tuple[bytes, str]:
        data = bytearray(_write(lay, p, tmp))
        at = _body_at(bytes(data))
        for i in rng.integers(at, len(data), int(rng.integers(1, 8))):
            data[i] = int(rng.integers(0, 256))
        return bytes(data), "any"

    def trailing(rng: np.random.Generator, lay: str, p: Points, tmp: Path) -> tuple[bytes, str]:
        data = _write(lay, p, tmp)
        if "ascii" in lay:
            rows = data[_body_at(data) :].splitlines(keepends=True)
            return data + b"".join(rows[: int(rng.integers(1, 5))]), "flag"  # rows the header does not count
        return data + rng.bytes(int(rng.integers(1, 200))), "flag"

    def empty(rng: np.random.Generator, lay: str, p: Points, tmp: Path) -> tuple[bytes, str]:
        data = _write(lay, p, tmp)
        pick = int(rng.integers(0, 4))
        if pick == 0:
            return b"", "flag"
        if pick == 1:
            return b" \n\r\n\t", "flag"
        if pick == 2:
            return _set_count(data[: _body_at(data)], 0, keep_width=False), "flag"
        return rng.bytes(int(rng.integers(1, 4096))), "flag"

    return {f.__name__: f for f in (clean, truncated, wrong_count, not_finite, duplicated, far, wrong_type,
                                    header_bytes, body_bytes, trailing, empty)}  # fmt: skip


MUTATIONS = _mutations()


def cases(seed: int, count: int, tmp: Path) -> Iterator[Case]:
    """``count`` cases from ``seed``: every mutation in turn, each on a random layout and scan (``tmp``: a
    scratch folder for the writers)."""
    rng = np.random.default_rng(seed)
    names = list(MUTATIONS)
    layouts = list(LAYOUTS)
    for i in range(count):
        mutation = names[i % len(names)]
        layout = layouts[int(rng.integers(len(layouts)))]
        data, expect = MUTATIONS[mutation](rng, layout, scan(rng), tmp / f"w{i}")
        yield Case(f"{layout}/{mutation}/{i}", data, expect)
