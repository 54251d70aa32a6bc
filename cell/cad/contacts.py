"""Where two bodies meet: the stretches of one body's sharp edges that lie on another body's face, with one face of
the edge resting on that face and the other forming a fillet with it, the receiving face going on past the edge,
and the fillet's corner open (no body in it). Frame ``M``, metres and radians.

The method and its thresholds are in docs/maps.md ("Your own CAD part")."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from cell.cad.model import Body, CurveKind, Edge
from cell.geometry import FloatArray
from cell.types import Polyhedron, pair_distance

ANTIPARALLEL_COS = math.cos(math.radians(5.0))  # the resting face against the receiving face: within 5 deg
MIN_DIHEDRAL = math.radians(30.0)  # the fillet's faces: sharper than this is no fillet
MAX_DIHEDRAL = math.radians(150.0)  # flatter than this is a butt, not a fillet
LEG_M = 0.002  # the receiving face goes on this far past the edge; the corner is open this far out [m]
OPEN_M = (0.002, 0.005)  # the points along the fillet's bisector that must lie in no body [m]
STEP_M = 0.001  # the edges are sampled this finely, then each stretch's ends found by bisection [m]
BISECTIONS = 12  # 1 mm / 2^12: the ends to 0.00025 mm
FLUSH_M = 0.0005  # past the edge the receiving face is this much farther than at it: it ended there (flush) [m]
MIN_STRETCH_M = 0.005  # a shorter stretch is where an edge grazes a body's border: no fillet, not listed [m]


@dataclass(frozen=True)
class Contact:
    """A stretch ``t0 .. t1`` (parameters in [0, 1], t0 > t1 when it wraps round a closed edge) of edge ``edge``
    of body ``a`` lying on body ``b``: at its middle, the resting face's and the free face's outward normals
    (``n_rest``, ``n_free``) and the receiving face's (``n_b``), and the dihedral [rad]."""

    a: int
    b: int
    edge: int
    t0: float
    t1: float
    n_rest: FloatArray
    n_free: FloatArray
    n_b: FloatArray
    dihedral: float


def _nearest(body: Body, p: FloatArray, reach: float) -> tuple[FloatArray, np.ndarray]:
    """Distance (n,) from each point to the body's surface, and the face (n,) of the nearest triangle; a point
    farther than ``reach`` [m] from every triangle gets infinity (and face -1)."""
    V, T = body.vertices, body.triangles
    tri = V[T]
    t_lo, t_hi = tri.min(axis=1) - reach, tri.max(axis=1) + reach
    d = np.full(len(p), np.inf)
    f = np.full(len(p), -1, dtype=np.intp)
    for s in range(0, len(p), 64):  # consecutive samples lie close together: each chunk meets few triangles
        q = p[s : s + 64]
        near = np.flatnonzero(np.all((t_hi >= q.min(axis=0)) & (t_lo <= q.max(axis=0)), axis=1))
        if len(near) == 0:
            continue
        i, j = np.divmod(np.arange(len(q) * len(near)), len(near))
        D = pair_distance(q[i], tri[near[j], 0], tri[near[j], 1], tri[near[j], 2]).reshape(len(q), len(near))
        k = np.argmin(D, axis=1)
        best = D[np.arange(len(q)), k]
        hit = best <= reach
        d[s : s + 64] = np.where(hit, best, np.inf)
        f[s : s + 64] = np.where(hit, body.triangle_face[near[k]], -1)
    return d, f


def _normals(body: Body, faces: np.ndarray, p: FloatArray) -> FloatArray:
    n = np.zeros((len(p), 3))
    for face in np.unique(faces[faces >= 0]):
        m = faces == face
        n[m] = body.normal_at(int(face), p[m])
    return n


class _Test:
    """The contact test of one edge of body A against body B, at any parameters along the edge."""

    def __init__(self, bodies: Sequence[Body], polys: Sequence[Polyhedron], a: int, b: int, edge: Edge, gap_m: float):
        self.A, self.B, self.edge, self.gap = bodies[a], bodies[b], edge, gap_m
        self.polys = polys
        self.others = [poly for i, poly in enumerate(polys) if i not in (a, b)]

    def __call__(self, t: FloatArray) -> tuple[np.ndarray, FloatArray, FloatArray, FloatArray, FloatArray]:
        """Whether each parameter passes, and the resting, free and receiving normals and dihedral there."""
        p = self.edge.at(t)
        reach = self.gap + 2.0 * LEG_M
        dist, fb = _nearest(self.B, p, reach)
        n_b = _normals(self.B, fb, p)
        pairs = np.array(self.edge.faces)[self.edge.piece(t)]
        n1, n2 = _normals(self.A, pairs[:, 0], p), _normals(self.A, pairs[:, 1], p)
        rest1 = np.einsum("ij,ij->i", n1, n_b) <= -ANTIPARALLEL_COS
        rest2 = np.einsum("ij,ij->i", n2, n_b) <= -ANTIPARALLEL_COS
        n_rest = np.where(rest1[:, None], n1, n2)
        n_free = np.where(rest1[:, None], n2, n1)
        cos = np.clip(np.einsum("ij,ij->i", n_free, n_b), -1.0, 1.0)
        dihedral = math.pi - np.arccos(cos)
        ok = (dist <= self.gap) & (rest1 ^ rest2) & (dihedral >= MIN_DIHEDRAL) & (dihedral <= MAX_DIHEDRAL)
        # The gap itself is empty: no washer between a bolt's head and the plate.
        between = p - 0.5 * np.where(ok, dist, 0.0)[:, None] * n_b
        for poly in self.others:
            ok &= ~poly.contains(between)
        # The receiving face goes on past the edge, on the free face's side (else the faces are flush: no fillet).
        u = n_free - cos[:, None] * n_b
        u /= np.maximum(np.linalg.norm(u, axis=1, keepdims=True), 1e-300)
        q = p + LEG_M * u
        d_q, f_q = _nearest(self.B, q, reach)
        same = np.einsum("ij,ij->i", _normals(self.B, f_q, q), n_b) >= ANTIPARALLEL_COS
        ok &= (d_q <= np.where(ok, dist, 0.0) + FLUSH_M) & same
        # The fillet's corner is open: no body (a third one covering the seam, or A or B themselves) in it.
        bis = n_free + n_b
        bis /= np.maximum(np.linalg.norm(bis, axis=1, keepdims=True), 1e-300)
        for r in OPEN_M:
            o = p + r * bis
            for poly in self.polys:
                ok &= ~poly.contains(o)
        return ok, n_rest, n_free, n_b, dihedral


def _refine(test: Callable[[FloatArray], np.ndarray], t_out: float, t_in: float) -> float:
    """The parameter between a failing and a passing one where the test starts to pass (bisection)."""
    for _ in range(BISECTIONS):
        mid = (t_out + t_in) / 2.0
        if bool(test(np.array([mid]))[0]):
            t_in = mid
        else:
            t_out = mid
    return t_in


def _runs(ok: np.ndarray, closed: bool) -> list[tuple[int, int]]:
    """Index ranges [i0, i1] of consecutive passing samples; a run over a closed edge's start joins its end's."""
    idx = np.flatnonzero(np.diff(np.concatenate([[0], ok.astype(int), [0]])))
    runs = [(int(s), int(e) - 1) for s, e in zip(idx[::2], idx[1::2], strict=True)]
    if closed and len(runs) > 1 and runs[0][0] == 0 and runs[-1][1] == len(ok) - 1:
        first, last = runs.pop(0), runs.pop()
        runs.append((last[0], first[1]))  # wraps: i0 > i1
    return runs


def _boxes_near(a: Body, b: Body, gap: float) -> bool:
    lo_a, hi_a = a.vertices.min(axis=0), a.vertices.max(axis=0)
    lo_b, hi_b = b.vertices.min(axis=0), b.vertices.max(axis=0)
    return bool(np.all(lo_a <= hi_b + gap) and np.all(lo_b <= hi_a + gap))


def contacts(bodies: Sequence[Body], polys: Sequence[Polyhedron], gap_m: float) -> list[Contact]:
    """Every stretch of a sharp edge of one body that lies on another within ``gap_m`` [m] as a fillet would."""
    found = []
    for a, A in enumerate(bodies):
        for b, B in enumerate(bodies):
            if a == b or not _boxes_near(A, B, gap_m):
                continue
            lo, hi = B.vertices.min(axis=0) - gap_m, B.vertices.max(axis=0) + gap_m
            for k, edge in enumerate(A.edges):
                pts = edge.at(np.linspace(0.0, 1.0, 9))
                if not np.any(np.all((pts >= lo - edge.length) & (pts <= hi + edge.length), axis=1)):
                    continue
                found += _edge_contacts(bodies, polys, a, b, k, gap_m)
    return found


def _edge_contacts(
    bodies: Sequence[Body], polys: Sequence[Polyhedron], a: int, b: int, k: int, gap_m: float
) -> list[Contact]:
    edge = bodies[a].edges[k]
    test = _Test(bodies, polys, a, b, edge, gap_m)
    n = max(9, math.ceil(edge.length / STEP_M) + 1)
    t = np.linspace(0.0, 1.0, n, endpoint=not edge.closed)  # a closed edge's t = 1 is its t = 0
    ok = test(t)[0]
    if not ok.any():
        return []
    if edge.closed and ok.all():
        spans = [(0.0, 1.0)]
    else:
        passes: Callable[[FloatArray], np.ndarray] = lambda tt: test(np.mod(tt, 1.0) if edge.closed else tt)[0]  # noqa: E731
        last, spans = len(t) - 1, []
        for i0, i1 in _runs(ok, edge.closed):
            if i0 == 0 and not edge.closed:
                t0 = 0.0
            else:
                before = float(t[i0 - 1]) if i0 > 0 else float(t[last]) - 1.0
                t0 = _refine(passes, before, float(t[i0]))
            if i1 == last and not edge.closed:
                t1 = 1.0
            else:
                after = float(t[i1 + 1]) if i1 < last else 1.0
                t1 = _refine(passes, after, float(t[i1]))
            spans.append((t0 % 1.0 if edge.closed else t0, t1 % 1.0 if edge.closed and t1 < 1.0 else t1))
    out = []
    for t0, t1 in spans:
        span = (t1 - t0) % 1.0 if t1 < t0 else t1 - t0
        if span * edge.length < MIN_STRETCH_M:
            continue
        mid = np.array([(t0 + span / 2.0) % 1.0])
        _, n_rest, n_free, n_b, dih = test(mid)
        out.append(Contact(a, b, k, t0, t1, n_rest[0], n_free[0], n_b[0], float(dih[0])))
    return out


def stretch(edge: Edge, t0: float, t1: float) -> Edge:
    """The part of ``edge`` from ``t0`` to ``t1`` (t1 < t0: round a closed edge's start) as an edge of its own."""
    span = (t1 - t0) % 1.0 if t1 < t0 else t1 - t0
    if edge.kind == CurveKind.ARC:
        start = edge.at(np.array([t0]))[0] - edge.centre
        return Edge(
            CurveKind.ARC,
            edge.at(np.array([t0, (t0 + span) % 1.0 if t1 < t0 else t1])),
            (edge.faces[0],),
            centre=edge.centre,
            axis=edge.axis,
            radius=edge.radius,
            start=start / np.linalg.norm(start),
            sweep=edge.sweep * span,
        )
    if edge.kind == CurveKind.LINE:
        return Edge(CurveKind.LINE, edge.at(np.array([t0, t1])), (edge.faces[0],))
    inner = edge.breaks[(edge.breaks > t0) & (edge.breaks < t1)]
    ts = np.unique(np.concatenate([[t0], np.linspace(t0, t1, 17), inner, [t1]]))
    return Edge(CurveKind.CURVE, edge.at(ts), (edge.faces[0],))
