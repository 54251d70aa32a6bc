"""DXF welding map -> :class:`~cell.types.WeldMap` (frame ``M``, metres). The only module importing ezdxf.

What a welding map holds (docs/reference.md section 6):

- seams: LINE entities whose effective colour is red (ACI 1, BYLAYER on a red layer, BYBLOCK in a red
  INSERT, or true colour ``#FF0000``); id from XDATA ``WELDCELL`` (group 1000), else ``seam-<handle>``
  (handles of the enclosing INSERTs first, joined by ``.``, for lines inside blocks);
- parts: 3DSOLID (ACIS), MESH and polyface POLYLINE bodies, each fitted by an oriented box; named after the
  layer (upper case), or after the block when the body sits on layer ``0`` inside a block;
- units from ``$INSUNITS`` (1 in, 4 mm, 5 cm, 6 m), else the caller's ``units`` (scenario key ``map.units``).

Entities inside INSERTs (nested, MINSERT arrays too) are read with the INSERT's transform. Block units
(``$INSUNITS`` of a block record) are *not* converted, as in ezdxf: a block is taken to be drawn in the
drawing's units. Every failure is a one-line :class:`~cell.errors.MapError` naming the file and the fix.
"""

from __future__ import annotations

import itertools
from collections import Counter
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

import ezdxf
import numpy as np
from ezdxf.acis import api as acis
from ezdxf.document import Drawing
from ezdxf.entities import DXFGraphic, Insert, Layer
from ezdxf.render import MeshBuilder

from cell.errors import MapError, MapUnitsError
from cell.geometry import FloatArray, make_pose, matrix_to_rpy
from cell.types import Box, MapSeam, Part, WeldMap

UNITS_BY_INSUNITS = {1: "in", 4: "mm", 5: "cm", 6: "m"}
METRES_PER_UNIT = {"mm": 1e-3, "cm": 1e-2, "m": 1.0, "in": 0.0254}
SEAM_APPID = "WELDCELL"
BOX_TOL = 1e-4  # a body must be a box within this [m] (0.1 mm)
MIN_SEAM_LENGTH = 1e-6  # [m]
FLAT_REL = 1e-6  # a drawing whose z extent is below this fraction of its extent is flat
_RED_ACI = 1
_RED_RGB = 0xFF0000
_BYBLOCK, _BYLAYER = 0, 256
_MAX_NESTING = 16
_SAME_DIRECTION = float(np.cos(np.radians(5.0)))  # face normals this close are one axis


@dataclass(frozen=True)
class _Ctx:
    """Where an entity sits: transform to M (drawing units), what it inherits from its enclosing INSERT."""

    X: FloatArray  # (4, 4) block coordinates -> M
    layer: str | None = None  # layer of the innermost INSERT (for entities on layer "0")
    block_red: bool = False  # the innermost INSERT's effective colour (for BYBLOCK entities)
    block: str | None = None  # name of the innermost block
    handles: tuple[str, ...] = ()  # handles of the enclosing INSERTs
    depth: int = 0


class _Reader:
    """One pass over a drawing, collecting raw seams and bodies in drawing units."""

    def __init__(self, doc: Drawing, source: str) -> None:
        self.doc = doc
        self.source = source
        self.layer_red = {layer.dxf.name.lower(): _layer_is_red(layer) for layer in doc.layers}
        self.seams: list[tuple[str, FloatArray, FloatArray]] = []
        self.bodies: list[tuple[str, FloatArray, list[tuple[int, ...]]]] = []

    def walk(self, entities: Iterable[DXFGraphic], ctx: _Ctx) -> None:
        for e in entities:
            kind = e.dxftype()
            if kind == "INSERT":
                self._insert(e, ctx)  # type: ignore[arg-type]
            elif kind == "LINE":
                if self._is_red(e, ctx):
                    p = _apply(ctx.X, np.array([e.dxf.start, e.dxf.end], dtype=float))
                    self.seams.append((self._seam_id(e, ctx), p[0], p[1]))
            elif kind in ("3DSOLID", "MESH", "POLYLINE"):
                for vertices, faces in self._meshes(e):
                    self.bodies.append((self._part_name(e, ctx), _apply(ctx.X, vertices), faces))

    def _insert(self, insert: Insert, ctx: _Ctx) -> None:
        if ctx.depth >= _MAX_NESTING:
            raise MapError(f"{self.source}: blocks nested over {_MAX_NESTING} deep (a block inserting itself?)")
        name = insert.dxf.name
        block = self.doc.blocks.get(name)
        if block is None:
            raise MapError(f"{self.source}: INSERT {insert.dxf.handle} references a missing block {name!r}")
        singles = insert.multi_insert() if insert.mcount > 1 else [insert]  # MINSERT: rows x columns
        for i, single in enumerate(singles):
            M = np.array(list(single.matrix44()), dtype=float).reshape(4, 4).T  # ezdxf uses row vectors
            handle = insert.dxf.handle or "?"
            child = _Ctx(
                X=ctx.X @ M,
                layer=self._layer(insert, ctx),
                block_red=self._is_red(insert, ctx),
                block=name,
                handles=(*ctx.handles, handle if i == 0 else f"{handle}#{i}"),
                depth=ctx.depth + 1,
            )
            self.walk(block, child)

    def _layer(self, e: DXFGraphic, ctx: _Ctx) -> str:
        layer: str = e.dxf.layer
        return ctx.layer if layer == "0" and ctx.layer is not None else layer

    def _is_red(self, e: DXFGraphic, ctx: _Ctx) -> bool:
        if e.dxf.hasattr("true_color"):  # a true colour overrides the colour index
            return int(e.dxf.true_color) & 0xFFFFFF == _RED_RGB
        aci = int(e.dxf.color)
        if aci == _BYLAYER:
            return self.layer_red.get(self._layer(e, ctx).lower(), False)
        if aci == _BYBLOCK:
            return ctx.block_red
        return aci == _RED_ACI

    def _seam_id(self, e: DXFGraphic, ctx: _Ctx) -> str:
        if e.has_xdata(SEAM_APPID):
            for code, value in e.get_xdata(SEAM_APPID):
                if code == 1000 and str(value).strip():
                    return str(value).strip()
        return "seam-" + ".".join((*ctx.handles, e.dxf.handle or "?"))

    def _part_name(self, e: DXFGraphic, ctx: _Ctx) -> str:
        if e.dxf.layer == "0" and ctx.block is not None:
            return ctx.block.upper()
        return self._layer(e, ctx).upper()

    def _meshes(self, e: DXFGraphic) -> Iterator[tuple[FloatArray, list[tuple[int, ...]]]]:
        kind = e.dxftype()
        builders: list[MeshBuilder]
        try:
            if kind == "3DSOLID":
                builders = [m for body in acis.load_dxf(e) for m in acis.mesh_from_body(body)]
            elif kind == "MESH":
                builders = [MeshBuilder.from_mesh(e)]  # type: ignore[arg-type]
            elif e.is_poly_face_mesh:  # type: ignore[attr-defined]
                builders = [MeshBuilder.from_polyface(e)]  # type: ignore[arg-type]
            else:
                return  # 2D/3D polylines are not bodies
        except (acis.AcisException, ezdxf.DXFError, ValueError, IndexError, TypeError) as exc:
            raise MapError(
                f"{self.source}: cannot read the {kind} {e.dxf.handle} on layer {e.dxf.layer} ({exc}); "
                "expected a polyhedral body (a box)"
            ) from None
        builders = [m for m in builders if m.vertices and m.faces]
        if not builders:  # e.g. a cylinder or sphere: ezdxf meshes only the flat faces of ACIS bodies
            raise MapError(
                f"{self.source}: the {kind} {e.dxf.handle} on layer {e.dxf.layer} has no flat faces; "
                "expected a polyhedral body (a box)"
            )
        for m in builders:
            yield np.array(m.vertices, dtype=float), [tuple(f) for f in m.faces]


def _layer_is_red(layer: Layer) -> bool:
    if layer.dxf.hasattr("true_color"):
        return int(layer.dxf.true_color) & 0xFFFFFF == _RED_RGB
    return abs(int(layer.dxf.color)) == _RED_ACI  # a negative colour means the layer is off; it is still red


def _apply(X: FloatArray, p: FloatArray) -> FloatArray:
    return np.asarray(p @ X[:3, :3].T + X[:3, 3])


def fit_box(vertices: FloatArray, faces: Sequence[Sequence[int]], name: str, tol: float = BOX_TOL) -> Box:
    """The oriented box of a polyhedral body, or MapError if the body is not a box within ``tol``.

    vertices : (n, 3) [m]; faces : vertex index tuples. The axes come from the face normals, ordered to be as
    close as possible to the frame's x, y, z (right-handed); the extents from the vertices.
    """
    vertices = np.asarray(vertices, dtype=float)
    if vertices.ndim != 2 or vertices.shape[1] != 3:
        raise ValueError(f"fit_box: vertices must be (n, 3), got {vertices.shape}")
    normals, areas, used = [], [], []
    for f in faces:
        p = vertices[list(f)]
        n = np.cross(p, np.roll(p, -1, axis=0)).sum(axis=0)  # Newell: |n| = 2 * area
        a = float(np.linalg.norm(n)) / 2.0
        if a > tol * tol:
            normals.append(n / (2.0 * a))
            areas.append(a)
            used.append(f)
    # Group the face normals into directions (up to sign) with a loose angle; the plane test below is strict.
    sums: list[FloatArray] = []  # area-weighted normal sum of each direction
    for n, a in zip(normals, areas, strict=True):
        for i, d in enumerate(sums):
            c = float(n @ d) / float(np.linalg.norm(d))
            if abs(c) > _SAME_DIRECTION:
                sums[i] = d + np.copysign(a, c) * n
                break
        else:
            sums.append(a * n)
    if len(sums) != 3:
        raise MapError(f"part {name} is not a box: its faces point in {len(sums)} directions, a box's in 3")
    D = np.array([d / np.linalg.norm(d) for d in sums])
    if np.max(np.abs(D @ D.T - np.eye(3))) > np.sin(np.radians(5.0)):
        raise MapError(f"part {name} is not a box: its face directions are not perpendicular")
    U, _, Vt = np.linalg.svd(D.T)  # nearest orthonormal set of axes (columns)
    A = U @ Vt
    perm = max(itertools.permutations(range(3)), key=lambda q: sum(abs(A[i, q[i]]) for i in range(3)))
    R = A[:, list(perm)]
    R = R * np.sign(np.where(np.diag(R) == 0.0, 1.0, np.diag(R)))  # each axis towards its M axis
    if np.linalg.det(R) < 0.0:  # make it right-handed: flip the axis furthest from its M axis
        k = int(np.argmin(np.abs(np.diag(R))))
        R[:, k] = -R[:, k]
    q = vertices @ R  # coordinates along the box axes
    lo, hi = q.min(axis=0), q.max(axis=0)
    size = hi - lo
    if np.any(size <= tol):
        raise MapError(f"part {name} is not a box: it is flat ({size.min() * 1000:.3f} mm thick)")
    # Every face must lie on one of the six planes of the box, and the faces must cover its surface once.
    axis_of = [int(np.argmax(np.abs(R.T @ normals[i]))) for i in range(len(used))]
    for f, k in zip(used, axis_of, strict=True):
        c = q[list(f), k]
        if not (np.all(np.abs(c - lo[k]) <= tol) or np.all(np.abs(c - hi[k]) <= tol)):
            raise MapError(f"part {name} is not a box within {tol * 1000:.1f} mm: a face lies inside it")
    surface = 2.0 * (size[0] * size[1] + size[1] * size[2] + size[2] * size[0])
    if abs(sum(areas) - surface) > tol * 4.0 * float(size.sum()):
        raise MapError(
            f"part {name} is not a closed box: its faces cover {sum(areas) * 1e6:.0f} mm^2 "
            f"of a {surface * 1e6:.0f} mm^2 box surface"
        )
    return Box(make_pose(R, R @ ((lo + hi) / 2.0)), size)


def _load(path: Path) -> Drawing:
    if not path.is_file():
        raise MapError(f"welding map {path} not found (or not a file); expected a DXF file")
    try:
        # Strict on purpose: ezdxf.recover "succeeds" on a truncated file, returning part of a drawing.
        return ezdxf.readfile(path)
    except ezdxf.DXFStructureError as exc:
        raise MapError(f"{path}: truncated or corrupt DXF ({exc}); expected a complete DXF file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise MapError(f"{path}: not a readable DXF file ({exc}); expected an ASCII or binary DXF") from None
    except Exception as exc:  # ezdxf raises assorted errors on malformed input; never show a traceback
        raise MapError(f"{path}: not a valid DXF file ({type(exc).__name__}: {exc})") from None


def _units(doc: Drawing, override: str | None, source: str) -> str:
    valid = ", ".join(METRES_PER_UNIT)
    if override is not None and override not in METRES_PER_UNIT:
        raise MapUnitsError(f"unknown map units {override!r} (scenario key map.units); valid: {valid}")
    code = int(doc.header.get("$INSUNITS", 0) or 0)
    if code in UNITS_BY_INSUNITS:
        return UNITS_BY_INSUNITS[code]
    if code != 0:
        raise MapUnitsError(
            f"{source}: $INSUNITS={code} is not supported; re-export the drawing in one of "
            "1 (in), 4 (mm), 5 (cm), 6 (m)"
        )
    if override is None:
        raise MapUnitsError(
            f"{source}: the drawing declares no units ($INSUNITS missing or 0); "
            f"set the scenario key map.units to one of {valid}"
        )
    return override


def read_map(path: str | Path, units: str | None = None) -> WeldMap:
    """Read a DXF welding map into a :class:`WeldMap` in frame ``M`` [m].

    units : ``"mm"``, ``"cm"``, ``"m"`` or ``"in"``; used only when the file declares no ``$INSUNITS``.
    Raises MapError (MapUnitsError for units) with a one-line message on any unreadable or unusable file.
    """
    path = Path(path)
    src = str(path)
    doc = _load(path)
    unit = _units(doc, units, src)
    scale = METRES_PER_UNIT[unit]
    reader = _Reader(doc, src)
    try:
        reader.walk(doc.modelspace(), _Ctx(X=np.eye(4)))
    except (ezdxf.DXFError, ValueError, KeyError, IndexError, TypeError) as exc:
        if isinstance(exc, MapError):
            raise
        raise MapError(f"{src}: malformed DXF content ({type(exc).__name__}: {exc})") from None
    what = "expected red 3D LINEs (colour 1, or on a red layer) and solid box parts (3DSOLID, MESH, POLYFACE)"
    if not reader.seams and not reader.bodies:
        empty = "the drawing is empty (truncated or blank?)" if len(doc.modelspace()) == 0 else "nothing found"
        raise MapError(f"{src}: {empty}; {what}")
    pts = [p for _, a, b in reader.seams for p in (a, b)] + [v for _, vs, _ in reader.bodies for v in vs]
    P = np.array(pts) * scale
    extent = float(np.ptp(P, axis=0).max())
    if float(np.ptp(P[:, 2])) <= FLAT_REL * extent:
        raise MapError(f"{src}: the drawing is flat (all z equal); {what} in 3D")
    if not reader.seams:
        raise MapError(f"{src}: no red weld seams; {what}")
    if not reader.bodies:
        raise MapError(f"{src}: no parts; {what}")
    seams = []
    for seam_id, a, b in reader.seams:
        s = MapSeam(seam_id, a * scale, b * scale)
        if s.length < MIN_SEAM_LENGTH:
            raise MapError(f"{src}: seam {seam_id} has zero length; every seam needs two distinct end points")
        seams.append(s)
    dup = [i for i, n in Counter(s.id for s in seams).items() if n > 1]
    if dup:
        raise MapError(f"{src}: seam id {dup[0]} appears {len(dup)} times; seam ids must be unique")
    count = Counter(name for name, _, _ in reader.bodies)
    index: Counter[str] = Counter()
    parts = []
    for name, vertices, faces in reader.bodies:
        index[name] += 1
        full = f"{name}_{index[name]}" if count[name] > 1 else name
        try:
            box = fit_box(vertices * scale, faces, full)
        except MapError as exc:
            raise MapError(f"{src}: {exc.message}") from None
        parts.append(Part(full, box))
    return WeldMap(parts=tuple(parts), seams=tuple(seams), units=unit, source=src, frame="M")


def _fmt(v: FloatArray, f: str = "8.1f") -> str:
    return "(" + ", ".join(format(float(x), f) for x in v) + ")"


def describe(weldmap: WeldMap) -> str:
    """Multi-line summary for ``cell map info``: file, units, parts (box size and centre [mm]), seams [mm]."""
    lines = [
        f"file:  {weldmap.source}",
        f"units: {weldmap.units} (shown in mm, frame {weldmap.frame})",
        f"parts: {len(weldmap.parts)}",
    ]
    width = max((len(p.name) for p in weldmap.parts), default=4)
    for p in weldmap.parts:
        size = " x ".join(f"{s * 1000:.1f}" for s in p.box.size)
        line = f"  {p.name:<{width}}  {size:>24} mm  centre {_fmt(p.box.center * 1000)}"
        R = p.box.X_AB[:3, :3]
        if not np.allclose(R, np.eye(3), atol=1e-9):
            line += "  rpy " + _fmt(np.degrees(matrix_to_rpy(R)), ".2f") + " deg"
        lines.append(line)
    lines.append(f"seams: {len(weldmap.seams)}")
    width = max((len(s.id) for s in weldmap.seams), default=4)
    for s in weldmap.seams:
        lines.append(
            f"  {s.id:<{width}}  {s.length * 1000:8.1f} mm  from {_fmt(s.p_start * 1000)}"
            f"  dir {_fmt(s.direction, '+.3f')}"
        )
    return "\n".join(lines)
