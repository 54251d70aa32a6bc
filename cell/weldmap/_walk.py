"""One pass over a drawing: seams (red or on a seam layer), straight and curved, and bodies, in drawing units.

Entities inside INSERTs (nested, MINSERT arrays too) are read with the INSERT's transform; an entity on layer
``0`` inside a block takes the INSERT's layer, a BYBLOCK colour the INSERT's colour (through every level).
"""

from __future__ import annotations

from collections import Counter, defaultdict
from collections.abc import Iterable
from dataclasses import dataclass, field

import numpy as np
from ezdxf import colors
from ezdxf.document import Drawing
from ezdxf.entities import DXFGraphic, Insert, Layer
from ezdxf.math import Vec3

from cell.errors import MapError
from cell.geometry import FloatArray
from cell.types import SampledCurve
from cell.weldmap._curves import CURVES, Curve, bulge_curve, entity_curve
from cell.weldmap._meshes import Mesh, UnreadableBodyError, body_meshes, face_points, is_body
from cell.weldmap.roles import LayerPatterns, matches

SEAM_APPID = "WELDCELL"
# Every colour index AutoCAD draws as pure red (#FF0000): 1 and 10 in the standard ACI table.
RED_ACI = frozenset(i for i in range(1, 256) if colors.aci2rgb(i) == (255, 0, 0))
_RED_RGB = 0xFF0000
_BYBLOCK, _BYLAYER = 0, 256
_MAX_NESTING = 16


@dataclass(frozen=True)
class Where:
    """An entity of the drawing, as a message names it: type, handle (INSERTs first) and layer."""

    kind: str
    handle: str
    layer: str

    def __str__(self) -> str:
        return f"{self.kind} {self.handle} on layer {self.layer}"


@dataclass(frozen=True)
class RawSeam:
    id: str
    a: FloatArray  # (3,) drawing units, frame M
    b: FloatArray
    where: Where


@dataclass(frozen=True)
class RawCurve:
    id: str
    curve: Curve  # drawing units, frame M
    where: Where


@dataclass(frozen=True)
class RawBody:
    name: str  # the layer's (or the block's, for a body on layer 0 in a block), in the drawing's case
    layer: str
    where: Where
    drawn_as: str
    mesh: Mesh | None  # None: unreadable (see reason)
    reason: str = ""


@dataclass(frozen=True)
class _Ctx:
    """Where an entity sits: transform to M (drawing units), what it inherits from its enclosing INSERT."""

    X: FloatArray  # (4, 4) block coordinates -> M
    layer: str | None = None  # layer of the innermost INSERT (for entities on layer "0")
    block_red: bool = False  # the innermost INSERT's effective colour (for BYBLOCK entities)
    block: str | None = None  # name of the innermost block
    handles: tuple[str, ...] = ()  # handles of the enclosing INSERTs
    depth: int = 0


@dataclass
class Found:
    """What the walk found, in drawing units."""

    seams: list[RawSeam] = field(default_factory=list)
    curves: list[RawCurve] = field(default_factory=list)  # curved seams
    bodies: list[RawBody] = field(default_factory=list)
    kinds: Counter[str] = field(default_factory=Counter)  # every entity type met (inside blocks too)
    red: int = 0  # red (or seam-layer) entities met


def _probe(curve: Curve) -> FloatArray:
    """A few points of a curve, to check its coordinates are finite."""
    if isinstance(curve, SampledCurve):
        return np.asarray(curve.points)
    with np.errstate(all="ignore"):
        return curve.at(np.linspace(0.0, 1.0, 3) * curve.sweep_rad + getattr(curve, "start_rad", 0.0))


def _layer_is_red(layer: Layer) -> bool:
    if layer.dxf.hasattr("true_color"):
        return int(layer.dxf.true_color) & 0xFFFFFF == _RED_RGB
    return abs(int(layer.dxf.color)) in RED_ACI  # a negative colour means the layer is off; it is still red


def _apply(X: FloatArray, p: FloatArray) -> FloatArray:
    with np.errstate(all="ignore"):  # an infinite coordinate gives NaN here: _finite names the entity
        return np.asarray(p @ X[:3, :3].T + X[:3, 3])


def _finite(p: FloatArray, where: Where, source: str) -> FloatArray:
    if not np.all(np.isfinite(p)):
        raise MapError(f"{source}: {where} has a NaN or infinite coordinate; every coordinate must be a finite number")
    return p


class Reader:
    """Collects seams and bodies of a drawing; ``layers`` says which layers are seam layers."""

    def __init__(self, doc: Drawing, source: str, layers: LayerPatterns) -> None:
        self.doc = doc
        self.source = source
        self.seam_layers = tuple(layers.seams)
        self.layer_red = {layer.dxf.name.lower(): _layer_is_red(layer) for layer in doc.layers}
        self.layer_name = {layer.dxf.name.lower(): str(layer.dxf.name) for layer in doc.layers}
        self.found = Found()
        self._faces: defaultdict[tuple[str, str, tuple[str, ...]], list[tuple[FloatArray, str]]] = defaultdict(list)

    def read(self, entities: Iterable[DXFGraphic]) -> Found:
        self._walk(entities, _Ctx(X=np.eye(4)))
        from cell.weldmap._meshes import group_faces

        for (name, layer, handles), faces in self._faces.items():
            points = [p for p, _ in faces]
            tol = 1e-6 * max(1.0, float(np.abs(np.concatenate(points)).max()))
            for mesh, members in group_faces(points, tol):
                first = ".".join((*handles, faces[members[0]][1]))
                more = f" (and {len(members) - 1} more)" if len(members) > 1 else ""
                where = Where("3DFACE", first + more, layer)
                self.found.bodies.append(RawBody(name, layer, where, "3DFACE", mesh))
        return self.found

    def _walk(self, entities: Iterable[DXFGraphic], ctx: _Ctx) -> None:
        for e in entities:
            kind = e.dxftype()
            self.found.kinds[kind] += 1
            if kind == "INSERT":
                self._insert(e, ctx)  # type: ignore[arg-type]
            elif kind in ("LINE", "LWPOLYLINE") or (kind == "POLYLINE" and not is_body(e)):
                if self._is_seam(e, ctx):
                    self._seam(e, ctx)
            elif kind in CURVES:
                if self._is_seam(e, ctx):
                    curve = entity_curve(e, ctx.X)
                    where = self._where(e, ctx)
                    _finite(_probe(curve), where, self.source)
                    self.found.curves.append(RawCurve(self._seam_id(e, ctx), curve, where))
            elif kind == "3DFACE":
                p = _finite(_apply(ctx.X, face_points(e)), self._where(e, ctx), self.source)
                self._faces[(self._name(e, ctx), self._layer(e, ctx), ctx.handles)].append((p, e.dxf.handle or "?"))
            elif is_body(e):
                self._body(e, ctx)

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
            if not np.all(np.isfinite(M)):
                raise MapError(
                    f"{self.source}: {self._where(insert, ctx)} has a NaN or infinite position, scale or rotation"
                )
            handle = insert.dxf.handle or "?"
            child = _Ctx(
                X=ctx.X @ M,
                layer=self._layer(insert, ctx),
                block_red=self._is_red(insert, ctx),
                block=name,
                handles=(*ctx.handles, handle if i == 0 else f"{handle}#{i}"),
                depth=ctx.depth + 1,
            )
            self._walk(block, child)

    def _layer(self, e: DXFGraphic, ctx: _Ctx) -> str:
        layer = str(e.dxf.layer)
        layer = ctx.layer if layer == "0" and ctx.layer is not None else layer
        return self.layer_name.get(layer.lower(), layer)  # the layer table's spelling

    def _name(self, e: DXFGraphic, ctx: _Ctx) -> str:
        return ctx.block if e.dxf.layer == "0" and ctx.block is not None else self._layer(e, ctx)

    def _where(self, e: DXFGraphic, ctx: _Ctx) -> Where:
        return Where(e.dxftype(), ".".join((*ctx.handles, e.dxf.handle or "?")), self._layer(e, ctx))

    def _is_red(self, e: DXFGraphic, ctx: _Ctx) -> bool:
        if e.dxf.hasattr("true_color"):  # a true colour overrides the colour index
            return int(e.dxf.true_color) & 0xFFFFFF == _RED_RGB
        aci = int(e.dxf.color)
        if aci == _BYLAYER:
            return self.layer_red.get(self._layer(e, ctx).lower(), False)
        if aci == _BYBLOCK:
            return ctx.block_red
        return aci in RED_ACI

    def _is_seam(self, e: DXFGraphic, ctx: _Ctx) -> bool:
        seam = self._is_red(e, ctx) or (bool(self.seam_layers) and matches(self._layer(e, ctx), self.seam_layers))
        self.found.red += seam
        return seam

    def _seam_id(self, e: DXFGraphic, ctx: _Ctx) -> str:
        if e.has_xdata(SEAM_APPID):
            for code, value in e.get_xdata(SEAM_APPID):
                if code == 1000 and str(value).strip():
                    return str(value).strip()
        return "seam-" + ".".join((*ctx.handles, e.dxf.handle or "?"))

    def _seam(self, e: DXFGraphic, ctx: _Ctx) -> None:
        where, seam_id, kind = self._where(e, ctx), self._seam_id(e, ctx), e.dxftype()
        if kind == "LINE":
            p = _finite(_apply(ctx.X, np.array([e.dxf.start, e.dxf.end], dtype=float)), where, self.source)
            self.found.seams.append(RawSeam(seam_id, p[0], p[1], where))
            return
        ocs, elevation = e.ocs(), 0.0
        if kind == "LWPOLYLINE":
            pts = [tuple(v) for v in e.vertices_in_wcs()]  # type: ignore[attr-defined]
            xyb = [(float(x), float(y), float(b)) for x, y, b in e.get_points("xyb")]  # type: ignore[attr-defined]
            closed = bool(e.closed)  # type: ignore[attr-defined]
            elevation = float(e.dxf.elevation)
        else:
            pts = [tuple(v) for v in e.points_in_wcs()]  # type: ignore[attr-defined]
            flat = bool(e.is_2d_polyline)  # type: ignore[attr-defined]  # a 3D polyline's bulges mean nothing
            xyb = [
                (float(v.dxf.location[0]), float(v.dxf.location[1]), float(v.dxf.get("bulge", 0.0)) if flat else 0.0)
                for v in e.vertices  # type: ignore[attr-defined]
            ]
            closed = bool(e.is_closed)  # type: ignore[attr-defined]
            elevation = float(Vec3(e.dxf.get("elevation", (0.0, 0.0, 0.0))).z)
        P = _finite(_apply(ctx.X, np.array(pts, dtype=float).reshape(-1, 3)), where, self.source)
        n = len(P) if closed else len(P) - 1
        for i in range(max(n, 0)):
            sid = f"{seam_id}.{i + 1}"
            if i < len(xyb) and xyb[i][2] != 0.0:
                j = (i + 1) % len(xyb)
                curve = bulge_curve(ctx.X, ocs, xyb[i][:2], xyb[j][:2], elevation, xyb[i][2])
                self.found.curves.append(
                    RawCurve(sid, curve, Where(where.kind, f"{where.handle} segment {i + 1}", where.layer))
                )
            else:
                self.found.seams.append(RawSeam(sid, P[i], P[(i + 1) % len(P)], where))

    def _body(self, e: DXFGraphic, ctx: _Ctx) -> None:
        where, name, layer = self._where(e, ctx), self._name(e, ctx), self._layer(e, ctx)
        drawn = "POLYFACE" if e.dxftype() == "POLYLINE" else e.dxftype()
        try:
            meshes = body_meshes(e, self.doc.dxfversion)
        except UnreadableBodyError as exc:
            self.found.bodies.append(RawBody(name, layer, where, drawn, None, exc.reason))
            return
        for v, f in meshes:
            self.found.bodies.append(
                RawBody(name, layer, where, drawn, (_finite(_apply(ctx.X, v), where, self.source), f))
            )
