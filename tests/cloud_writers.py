"""Point cloud files written by the tests themselves (PLY and PCD, ASCII and binary), for ``read_cloud`` and
``cell locate``: small writers of the formats' own layouts, independent of the reader under test."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import numpy.typing as npt

from cell.geometry import transform_points
from cell.types import WeldMap

Points = npt.NDArray[np.float64]


def ply_ascii(path: Path, p: Points, *, newline: str = "\n", extra: bool = True) -> Path:
    """ASCII PLY: float x y z (and a uchar ``intensity`` after them when ``extra``)."""
    head = ["ply", "format ascii 1.0", "comment written by the tests", f"element vertex {len(p)}"]
    head += [f"property float {c}" for c in "xyz"] + (["property uchar intensity"] if extra else [])
    head.append("end_header")
    rows = [" ".join(f"{v:.9g}" for v in row) + (" 7" if extra else "") for row in p]
    path.write_bytes(newline.join([*head, *rows, ""]).encode())
    return path


def ply_binary(path: Path, p: Points, *, big_endian: bool = False) -> Path:
    """Binary PLY: a uchar ``quality``, then double x y z, then a float ``intensity`` (extra fields around xyz)."""
    order = ">" if big_endian else "<"
    fmt = "binary_big_endian" if big_endian else "binary_little_endian"
    dtype = np.dtype([("q", "u1"), ("x", order + "f8"), ("y", order + "f8"), ("z", order + "f8"), ("i", order + "f4")])
    table = np.zeros(len(p), dtype=dtype)
    table["q"], table["i"] = 3, 0.5
    table["x"], table["y"], table["z"] = p[:, 0], p[:, 1], p[:, 2]
    head = (
        f"ply\nformat {fmt} 1.0\nelement vertex {len(p)}\nproperty uchar quality\nproperty double x\n"
        "property double y\nproperty double z\nproperty float intensity\nelement face 0\n"
        "property list uchar int vertex_indices\nend_header\n"
    )
    path.write_bytes(head.encode() + table.tobytes())
    return path


def _pcd_header(n: int, fields: str, size: str, type_: str, count: str, data: str) -> list[str]:
    return [
        "# .PCD v0.7 - Point Cloud Data file format",
        "VERSION 0.7",
        f"FIELDS {fields}",
        f"SIZE {size}",
        f"TYPE {type_}",
        f"COUNT {count}",
        f"WIDTH {n}",
        "HEIGHT 1",
        "VIEWPOINT 0 0 0 1 0 0 0",
        f"POINTS {n}",
        f"DATA {data}",
    ]


def pcd_ascii(path: Path, p: Points, *, newline: str = "\r\n") -> Path:
    """ASCII PCD (CRLF by default, as the real scans): x y z then an ``intensity`` field."""
    head = _pcd_header(len(p), "x y z intensity", "4 4 4 4", "F F F F", "1 1 1 1", "ascii")
    rows = [" ".join(f"{v:.9g}" for v in row) + " 1" for row in p]
    path.write_bytes(newline.join([*head, *rows, ""]).encode())
    return path


def _pcd_table(p: Points) -> npt.NDArray[np.void]:
    """x y z float32, a 3-float ``normal`` (COUNT 3) and padding ``_`` (uint8), row by row."""
    dtype = np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("normal", "<f4", (3,)), ("_", "u1")])
    table = np.zeros(len(p), dtype=dtype)
    table["x"], table["y"], table["z"] = p[:, 0], p[:, 1], p[:, 2]
    table["normal"] = [0.0, 0.0, 1.0]
    return table


_BIN = ("x y z normal _", "4 4 4 4 1", "F F F F U", "1 1 1 3 1")


def pcd_binary(path: Path, p: Points) -> Path:
    """Binary PCD (row by row, little endian) with a COUNT 3 field and a padding field."""
    head = "\n".join(_pcd_header(len(p), *_BIN, "binary")) + "\n"
    path.write_bytes(head.encode() + _pcd_table(p).tobytes())
    return path


def pcd_binary_compressed(path: Path, p: Points) -> Path:
    """binary_compressed PCD: the fields one after the other (column by column), as an LZF stream of literal runs
    only (a valid LZF block: a control byte below 32 is followed by that many plus one bytes as they are)."""
    table = _pcd_table(p)
    columns = b"".join(np.ascontiguousarray(table[name]).tobytes() for name in table.dtype.names or ())
    packed = b"".join(bytes([len(columns[i : i + 32]) - 1]) + columns[i : i + 32] for i in range(0, len(columns), 32))
    head = "\n".join(_pcd_header(len(p), *_BIN, "binary_compressed")) + "\n"
    sizes = np.array([len(packed), len(columns)], dtype="<u4").tobytes()
    path.write_bytes(head.encode() + sizes + packed)
    return path


def box_surface(rng: np.random.Generator, n: int, size_m: tuple[float, float, float]) -> Points:
    """``n`` points (n, 3) [m] on the surface of an axis-aligned box of ``size_m`` centred at the origin."""
    half = np.asarray(size_m) / 2.0
    p = rng.uniform(-half, half, size=(n, 3))
    axis = rng.integers(0, 3, size=n)
    p[np.arange(n), axis] = np.where(rng.random(n) < 0.5, -1.0, 1.0) * half[axis]
    return p


def map_cloud(
    weldmap: WeldMap,
    X_FM: npt.NDArray[np.float64],
    rng: np.random.Generator,
    *,
    pitch_m: float,
    noise_m: float,
    table_margin_m: float = 0.1,
) -> Points:
    """A scanner's cloud (n, 3) [m] in F of a map's parts lying at X_FM on a table (the plane z = 0 of M): points
    on every box face at about ``pitch_m`` spacing (uniformly at random), none inside another part or under the
    table, the table around the parts' footprint grown by ``table_margin_m``, Gaussian noise ``noise_m`` per axis."""
    clouds = []
    for part in weldmap.parts:
        box = part.box
        for axis in range(3):
            u, v = (a for a in range(3) if a != axis)
            n = max(1, int(box.size[u] * box.size[v] / pitch_m**2))
            for sign in (-1.0, 1.0):
                p_B = (rng.random((n, 3)) - 0.5) * box.size
                p_B[:, axis] = sign * box.size[axis] / 2.0
                clouds.append(transform_points(box.X_AB, p_B))
    p_M = np.vstack(clouds)
    inside = np.zeros(len(p_M), bool)
    for part in weldmap.parts:
        inside |= part.contains(p_M, margin=-1e-4)
    p_M = p_M[~inside & (p_M[:, 2] > 1e-4)]
    corners = np.vstack([part.vertices() for part in weldmap.parts])
    lo, hi = corners.min(axis=0)[:2] - table_margin_m, corners.max(axis=0)[:2] + table_margin_m
    n = int(np.prod(hi - lo) / pitch_m**2)
    table = np.column_stack([rng.uniform(lo, hi, size=(n, 2)), np.zeros(n)])
    under = np.zeros(n, bool)
    for part in weldmap.parts:
        under |= part.contains(table, margin=1e-4)
    p_M = np.vstack([p_M, table[~under]])
    return transform_points(X_FM, p_M) + rng.normal(0.0, noise_m, size=p_M.shape)


def seen_faces(weldmap: WeldMap, spacing_m: float) -> Points:
    """Points (n, 3) [m] in M on the map's box faces a scanner above the parts and to their side sees (normals up,
    along +y or along x), on a ``spacing_m`` grid (:func:`cell.perception.align.fit.sample_box_faces`), none inside
    another part."""
    from cell.perception.align.fit import sample_box_faces

    out = []
    for part in weldmap.parts:
        p, n = sample_box_faces(part.box, spacing_m)
        keep = (n[:, 2] > 0.5) | (n[:, 1] > 0.5) | (np.abs(n[:, 0]) > 0.5)
        for other in weldmap.parts:
            if other is not part:
                keep &= ~other.contains(p, 0.001)
        out.append(p[keep])
    return np.concatenate(out)
