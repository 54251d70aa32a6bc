"""The vertices and faces of a DXF body entity (3DSOLID, MESH, polyface or polygon-mesh POLYLINE, 3DFACE groups)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from ezdxf.acis import api as acis
from ezdxf.entities import DXFGraphic
from ezdxf.render import MeshBuilder

from cell.geometry import FloatArray
from cell.weldmap._load import MALFORMED, kind_of

Mesh = tuple[FloatArray, list[tuple[int, ...]]]
BODY_TYPES = ("3DSOLID", "MESH", "POLYLINE", "3DFACE")
_R2013 = "AC1027"  # from this version on, ACIS bodies are stored as binary SAB in a data section


class UnreadableBodyError(Exception):
    """A body entity whose geometry cannot be had; ``reason`` says why and what the user can do."""

    def __init__(self, reason: str) -> None:
        super().__init__(reason)
        self.reason = reason


def is_body(e: DXFGraphic) -> bool:
    """Whether ``e`` is a body (a POLYLINE only when it is a polyface or polygon mesh)."""
    kind = e.dxftype()
    if kind == "POLYLINE":
        return bool(e.is_poly_face_mesh or e.is_polygon_mesh)  # type: ignore[attr-defined]
    return kind in ("3DSOLID", "MESH")


def body_meshes(e: DXFGraphic, dxfversion: str) -> list[Mesh]:
    """The meshes of one body entity, in its own coordinates. Raises UnreadableBodyError."""
    kind = e.dxftype()
    builders: list[MeshBuilder]
    try:
        if kind == "3DSOLID":
            builders = [m for body in acis.load_dxf(e) for m in acis.mesh_from_body(body)]
        elif kind == "MESH":
            builders = [MeshBuilder.from_mesh(e)]  # type: ignore[arg-type]
        else:
            builders = [MeshBuilder.from_polyface(e)]  # type: ignore[arg-type]
    except (acis.AcisException, *MALFORMED) as exc:
        hint = "expected a polyhedral body (a box)"
        if kind == "3DSOLID" and dxfversion >= _R2013:
            hint = (
                "ezdxf cannot read this binary ACIS solid: save the drawing as DXF R2000-R2010 or export bodies as MESH"
            )
        raise UnreadableBodyError(f"cannot be read ({kind_of(exc)}: {exc}); {hint}") from None
    builders = [m for m in builders if m.vertices and m.faces]
    if not builders:  # e.g. a cylinder or sphere: ezdxf meshes only the flat faces of ACIS bodies
        raise UnreadableBodyError("has no flat faces (a curved solid?); expected a polyhedral body (a box)")
    return [(np.array(m.vertices, dtype=float), [tuple(f) for f in m.faces]) for m in builders]


def face_points(e: DXFGraphic) -> FloatArray:
    """A 3DFACE's corners (3 or 4, a repeated last corner dropped), in its coordinates."""
    p = np.array([tuple(e.dxf.get(f"vtx{i}", (0.0, 0.0, 0.0))) for i in range(4)], dtype=float)
    return p[:3] if np.array_equal(p[3], p[2]) else p


def group_faces(faces: Sequence[FloatArray], tol: float) -> list[tuple[Mesh, list[int]]]:
    """3DFACEs (each (k, 3), one frame) grouped into bodies by shared corners (within ``tol``): each body's mesh and
    the indices of its faces in ``faces``."""
    if not faces:
        return []
    pts = np.concatenate(faces)
    key = np.round(pts / tol).astype(np.int64)
    _, ids = np.unique(key, axis=0, return_inverse=True)
    ids = ids.reshape(-1)
    parent = list(range(int(ids.max()) + 1))

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    spans, at = [], 0
    for f in faces:
        v = [int(i) for i in ids[at : at + len(f)]]
        spans.append(v)
        at += len(f)
        for a in v[1:]:
            parent[root(a)] = root(v[0])
    groups: dict[int, list[list[int]]] = {}
    members: dict[int, list[int]] = {}
    for k, v in enumerate(spans):
        groups.setdefault(root(v[0]), []).append(v)
        members.setdefault(root(v[0]), []).append(k)
    first = {int(g): n for n, g in reversed(list(enumerate(ids)))}  # a point of each merged corner
    meshes: list[tuple[Mesh, list[int]]] = []
    for r, face_ids in groups.items():
        used = sorted({i for v in face_ids for i in v})
        local = {g: k for k, g in enumerate(used)}
        vertices = np.array([pts[first[g]] for g in used])
        meshes.append(((vertices, [tuple(local[i] for i in v) for v in face_ids]), members[r]))
    return meshes
