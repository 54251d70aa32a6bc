"""Round bodies in tessellated parts: a polyhedron whose side faces all stand parallel to one axis with their corners
on one circle about it (and on a second, smaller one for a tube's bore) is a :class:`~cell.types.Cylinder`: a tube,
a pipe or a round bar as CAD exporters write them (MESH, 3DFACE, POLYFACE). Its ends may be cut square, at a slant
(a leaning brace's foot) or coped (a branch's saddle). Numpy only (docs/maps.md section 2b)."""

from __future__ import annotations

import math

import numpy as np

from cell.geometry import FloatArray
from cell.types import Cylinder, Polyhedron

MIN_FACETS = 12  # fewer flat sides is a prism (a hexagon bar), not a round body
SIDE_DEG = 0.5  # a side face's normal is within this of perpendicular to the axis
MAX_GAP_DEG = 45.0  # the side faces' normals leave no gap wider than this around the axis (a full round)
RADIUS_REL = 2e-3  # every corner of the round side lies within this fraction of the radius of one circle
RADIUS_ABS_M = 2e-5  # ... or within this [m], whichever is larger
_TRIES = 6  # axis directions tried, most side faces first (a coped end's saddle is itself round about another axis)


def _normals_areas(body: Polyhedron) -> tuple[FloatArray, FloatArray]:
    N, A = [], []
    for name in body.face_names():
        poly = body.face_polygon(name)
        w = np.cross(poly, np.roll(poly, -1, axis=0)).sum(axis=0)  # Newell: 2 x area along the normal
        a = float(np.linalg.norm(w))
        N.append(w / a if a > 0 else np.zeros(3))
        A.append(a / 2.0)
    return np.array(N), np.array(A)


def _candidates(N: FloatArray, A: FloatArray) -> FloatArray:
    """Axis directions to try: the cross products of the largest face's normal with the others (the axis, when it
    is a side face) and every face's normal (the axis, when it is a cap)."""
    big = N[int(np.argmax(A))]
    C = np.cross(big, N)
    keep = np.linalg.norm(C, axis=1) > 0.05
    C = C[keep] / np.linalg.norm(C[keep], axis=1, keepdims=True)
    return np.vstack([C, N[np.linalg.norm(N, axis=1) > 0]])


def _circle(uv: FloatArray) -> tuple[FloatArray, float]:
    """The least-squares circle through 2D points (n, 2) (Kasa's algebraic fit): centre (2,) and radius."""
    M = np.column_stack([2.0 * uv, np.ones(len(uv))])
    sol, *_ = np.linalg.lstsq(M, (uv**2).sum(axis=1), rcond=None)
    c = sol[:2]
    return c, math.sqrt(max(float(sol[2] + c @ c), 0.0))


def _max_gap(angles: FloatArray) -> float:
    a = np.sort(np.mod(angles, 2.0 * math.pi))
    return float(np.max(np.diff(np.append(a, a[0] + 2.0 * math.pi))))


def recognise_cylinder(body: Polyhedron) -> Cylinder | None:
    """The cylinder a tessellated body stands for, or None when it is no round body (fewer than
    :data:`MIN_FACETS` side faces, sides not around one axis, corners off one circle, a gap in the round)."""
    N, A = _normals_areas(body)
    if len(N) < MIN_FACETS + 2:
        return None
    C = _candidates(N, A)
    side_tol = math.sin(math.radians(SIDE_DEG))
    directions = np.unique(np.round(N, 3), axis=0)  # a cap split into many drawn faces counts once
    counts = (np.abs(C @ directions.T) < side_tol).sum(axis=1)
    tried: list[FloatArray] = []
    for k in np.argsort(-counts, kind="stable"):
        if counts[k] < MIN_FACETS or len(tried) >= _TRIES:
            break
        if any(abs(float(C[k] @ t)) > 1.0 - 1e-9 for t in tried):
            continue
        tried.append(C[k])
        found = _fit(body, N, C[k], side_tol)
        if found is not None:
            return found
    return None


def _fit(body: Polyhedron, N: FloatArray, axis: FloatArray, side_tol: float) -> Cylinder | None:
    """The cylinder about ``axis`` (a direction) the body stands for, or None."""
    side = np.abs(N @ axis) < side_tol
    if int(side.sum()) < MIN_FACETS:
        return None
    axis = axis * (1.0 if axis[int(np.argmax(np.abs(axis)))] > 0 else -1.0)
    e1 = np.cross(axis, np.eye(3)[int(np.argmin(np.abs(axis)))])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(axis, e1)
    names = body.face_names()
    V = np.asarray(body.vertices, dtype=float)
    side_ids = np.flatnonzero(side)
    corners = np.unique(np.concatenate([body.faces[i] for i in side_ids]))
    uv = np.column_stack([V[corners] @ e1, V[corners] @ e2])
    centre, _ = _circle(uv)
    # Outer faces look away from the axis, a bore's faces towards it.
    mid = np.array([body.face_polygon(names[i]).mean(axis=0) for i in side_ids])
    mid_uv = np.column_stack([mid @ e1, mid @ e2]) - centre
    n_uv = np.column_stack([N[side_ids] @ e1, N[side_ids] @ e2])
    outward = np.einsum("ij,ij->i", mid_uv, n_uv) > 0
    radii = []
    for group in (outward, ~outward):
        if not group.any():
            radii.append(0.0)
            continue
        ids = np.unique(np.concatenate([body.faces[side_ids[k]] for k in np.flatnonzero(group)]))
        r = np.linalg.norm(np.column_stack([V[ids] @ e1, V[ids] @ e2]) - centre, axis=1)
        tol = max(RADIUS_REL * float(r.mean()), RADIUS_ABS_M)
        if float(np.ptp(r)) > tol or _max_gap(np.arctan2(n_uv[group, 1], n_uv[group, 0])) > math.radians(MAX_GAP_DEG):
            return None
        radii.append(float(r.mean()))
    radius, bore = radii
    if radius <= bore or int(outward.sum()) < MIN_FACETS:
        return None
    r_all = np.linalg.norm(np.column_stack([V @ e1, V @ e2]) - centre, axis=1)
    if float(r_all.max()) > radius + max(RADIUS_REL * radius, RADIUS_ABS_M):
        return None  # something sticks out of the round: not a plain tube or bar
    h = V @ axis
    p_base = centre[0] * e1 + centre[1] * e2 + float(h.min()) * axis
    return Cylinder(p_base, axis, radius, float(np.ptp(h)), bore, int(outward.sum()))
