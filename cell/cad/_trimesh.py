"""STL, OBJ and PLY meshes in through trimesh: split into bodies by connectivity, flat faces grouped (trimesh's
facets), sharp edges chained into lines, circular arcs (a tessellated tube's rim) or other curves. The only module
that imports trimesh. Coordinates in the file's units (the caller scales them)."""

from __future__ import annotations

import itertools
import math
from collections import defaultdict
from pathlib import Path

import numpy as np
import trimesh

from cell.cad.model import Body, CurveKind, Edge, Face, SurfaceKind
from cell.errors import MapError
from cell.geometry import FloatArray

SHARP_RAD = math.radians(20.0)  # neighbouring triangles at a larger angle meet at a sharp edge
CORNER_RAD = math.radians(40.0)  # a chain of sharp edges turning more than this at a vertex is cut there
REL_TOL = 1e-3  # a chain is a line or circle when its points lie this close (times its size) to one


def _meshes(path: Path) -> list[tuple[str, trimesh.Trimesh]]:
    try:  # an OBJ's objects kept apart, by name, whatever their materials
        scene = trimesh.load_scene(str(path), split_objects=True, group_material=False, process=True)
    except Exception as exc:  # trimesh raises many types on a broken file (ValueError, KeyError, struct.error)
        raise MapError(f"{path}: not a readable mesh ({type(exc).__name__}: {exc})") from None
    meshes = sorted((str(n), g) for n, g in scene.geometry.items() if isinstance(g, trimesh.Trimesh) and len(g.faces))
    if not meshes:
        raise MapError(f"{path}: holds no triangle mesh (a point cloud?); export the part's surfaces as triangles")
    if len(meshes) == 1:
        return [(path.stem.upper(), meshes[0][1])]
    return meshes


def _faces(mesh: trimesh.Trimesh) -> tuple[list[Face], np.ndarray]:
    owner = np.full(len(mesh.faces), -1, dtype=np.intp)
    faces: list[Face] = []
    for members, n in zip(mesh.facets, mesh.facets_normal, strict=True):
        owner[members] = len(faces)
        faces.append(Face(SurfaceKind.PLANE, normal=n, offset=float(n @ mesh.vertices[mesh.faces[members[0], 0]])))
    for i in np.flatnonzero(owner < 0):
        n = mesh.face_normals[i]
        owner[i] = len(faces)
        faces.append(Face(SurfaceKind.PLANE, normal=n, offset=float(n @ mesh.vertices[mesh.faces[i, 0]])))
    return faces, owner


def _chains(segments: list[tuple[int, int]], V: FloatArray) -> list[list[int]]:
    """The segments (vertex pairs) joined into chains of vertices, cut where three meet or at a corner."""
    nbr: defaultdict[int, list[int]] = defaultdict(list)
    for a, b in segments:
        nbr[a].append(b)
        nbr[b].append(a)

    def corner(v: int) -> bool:
        if len(nbr[v]) != 2:
            return True
        d0, d1 = V[v] - V[nbr[v][0]], V[nbr[v][1]] - V[v]
        cos = float(d0 @ d1) / max(float(np.linalg.norm(d0) * np.linalg.norm(d1)), 1e-300)
        return math.acos(max(-1.0, min(1.0, cos))) > CORNER_RAD

    used: set[tuple[int, int]] = set()
    chains = []
    starts = [v for v in sorted(nbr) if corner(v)] + sorted(nbr)  # open chains first, then closed loops
    for s in starts:
        for nxt in nbr[s]:
            if (min(s, nxt), max(s, nxt)) in used:
                continue
            chain = [s]
            prev, cur = s, nxt
            while True:
                used.add((min(prev, cur), max(prev, cur)))
                chain.append(cur)
                if cur == s or corner(cur):
                    break
                step = [w for w in nbr[cur] if w != prev and (min(cur, w), max(cur, w)) not in used]
                if not step:
                    break
                prev, cur = cur, step[0]
            chains.append(chain)
    return chains


def _circle(P: FloatArray) -> tuple[FloatArray, FloatArray, float, float] | None:
    """Centre, unit normal, radius and largest residual of the circle through points P (n, 3), if it is one."""
    c0 = P.mean(axis=0)
    _, _, vt = np.linalg.svd(P - c0)
    n, u, v = vt[2], vt[0], vt[1]
    xy = np.stack([(P - c0) @ u, (P - c0) @ v], axis=1)
    A = np.column_stack([2.0 * xy, np.ones(len(xy))])
    sol, *_ = np.linalg.lstsq(A, (xy**2).sum(axis=1), rcond=None)
    cx, cy = sol[0], sol[1]
    r = math.sqrt(max(sol[2] + cx * cx + cy * cy, 0.0))
    centre = c0 + cx * u + cy * v
    res = np.abs(np.linalg.norm(P - centre - np.outer((P - centre) @ n, n), axis=1) - r)
    res = np.maximum(res, np.abs((P - centre) @ n))
    return centre, n, r, float(res.max())


def _edge(chain: list[int], V: FloatArray, pair_faces: dict[tuple[int, int], tuple[int, int]]) -> Edge:
    P = V[chain]
    seg = np.linalg.norm(np.diff(P, axis=0), axis=1)
    breaks = np.concatenate([[0.0], np.cumsum(seg)]) / max(float(seg.sum()), 1e-300)
    faces = tuple(pair_faces[(min(a, b), max(a, b))] for a, b in itertools.pairwise(chain))
    size = float(np.ptp(P, axis=0).max())
    d = P[-1] - P[0]
    if len(chain) == 2 or (
        np.linalg.norm(d) > 0
        and np.abs(np.cross(P - P[0], d / np.linalg.norm(d))).max() <= REL_TOL * float(np.linalg.norm(d))
    ):
        return Edge(CurveKind.LINE, P[[0, -1]], (faces[0],))  # one piece: a line's faces do not change
    fit = _circle(P) if len(chain) >= 5 else None
    if fit is not None and fit[3] <= REL_TOL * size:
        centre, n, r, _ = fit
        start = (P[0] - centre) / max(float(np.linalg.norm(P[0] - centre)), 1e-300)
        ang = np.unwrap(np.arctan2((P - centre) @ np.cross(n, start), (P - centre) @ start))
        if ang[-1] < 0:  # turn the normal so that the chain runs counter-clockwise about it
            n, ang = -n, -ang
        sweep = 2.0 * math.pi if chain[0] == chain[-1] else float(ang[-1])
        return Edge(
            CurveKind.ARC,
            P[[0, -1]],
            faces,
            ang / max(sweep, 1e-300) if sweep > 0 else breaks,
            centre,
            n,
            r,
            start,
            sweep,
        )
    return Edge(CurveKind.CURVE, P, faces, breaks)


def _body(name: str, mesh: trimesh.Trimesh) -> Body:
    faces, owner = _faces(mesh)
    sharp = mesh.face_adjacency_angles > SHARP_RAD
    pairs = mesh.face_adjacency[sharp]
    verts = mesh.face_adjacency_edges[sharp]
    pair_faces: dict[tuple[int, int], tuple[int, int]] = {}
    segments = []
    for (t0, t1), (a, b) in zip(pairs, verts, strict=True):
        if owner[t0] == owner[t1]:
            continue
        key = (int(min(a, b)), int(max(a, b)))
        pair_faces[key] = (int(owner[t0]), int(owner[t1]))
        segments.append(key)
    V = np.asarray(mesh.vertices, dtype=float)
    edges = tuple(_edge(c, V, pair_faces) for c in _chains(segments, V) if len(c) >= 2)
    return Body(name, tuple(faces), edges, V, np.asarray(mesh.faces), owner)


def read_mesh(path: Path) -> list[Body]:
    """The bodies of a mesh file: each connected piece of each mesh in it, named after the mesh (the file's stem
    for a single mesh) and a number. Raises MapError when the file holds no closed body."""
    bodies: list[Body] = []
    open_pieces = 0
    for name, mesh in _meshes(path):
        pieces = mesh.split(only_watertight=False)
        for k, piece in enumerate(pieces):
            if not piece.is_watertight:
                open_pieces += 1
                continue
            if piece.volume < 0:
                piece.invert()
            bodies.append(_body(name if len(pieces) == 1 else f"{name}_{k + 1}", piece))
    if not bodies:
        raise MapError(
            f"{path}: no closed body in the mesh ({open_pieces} open pieces); each part must be a closed surface"
        )
    return bodies
