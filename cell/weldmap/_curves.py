"""Curved seam entities (ARC, CIRCLE, ELLIPSE, SPLINE, HELIX, a bulged polyline segment) as typed curves in the map
frame, in drawing units: the entity's OCS and the enclosing INSERTs' transform applied with ezdxf's own tools
(``OCS``, ``bulge_to_arc``, ``ConstructionEllipse``, ``BSpline.flattening``)."""

from __future__ import annotations

import math

import numpy as np
from ezdxf.entities import DXFGraphic
from ezdxf.math import OCS, ConstructionEllipse, Matrix44, Vec3, bulge_to_arc

from cell.geometry import FloatArray
from cell.types import ArcCurve, EllipseCurve, SampledCurve

CURVES = ("ARC", "CIRCLE", "ELLIPSE", "SPLINE", "HELIX")
SPLINE_CHORD_REL = 1e-4  # a spline is flattened within this fraction of its extent (0.1 mm over a metre)
_SIMILAR_REL = 1e-9  # a transform whose columns differ in length by less than this (relative) keeps circles round

Curve = ArcCurve | EllipseCurve | SampledCurve


def _matrix44(X: FloatArray) -> Matrix44:
    """ezdxf's Matrix44 (row vectors) of our (4, 4) column-vector transform."""
    return Matrix44(np.asarray(X, dtype=float).T.reshape(-1).tolist())


def _similar_scale(X: FloatArray) -> float | None:
    """The scale of X's linear part when it is a similarity (rotation, mirror and one scale), else None."""
    A = np.asarray(X, dtype=float)[:3, :3]
    G = A.T @ A
    s2 = float(np.trace(G)) / 3.0
    return math.sqrt(s2) if s2 > 0 and np.allclose(G, s2 * np.eye(3), atol=_SIMILAR_REL * s2) else None


def _arc(X: FloatArray, centre: Vec3, x: Vec3, y: Vec3, radius: float, sweep: float) -> ArcCurve | EllipseCurve:
    """An arc (centre, x and y unit directions of its plane in block coordinates, radius, sweep about x cross y)
    carried by X into the map: an arc when X is a similarity, else the ellipse it becomes."""
    A, t = np.asarray(X)[:3, :3], np.asarray(X)[:3, 3]
    c, u, v = A @ np.array(centre) + t, A @ np.array(x), A @ np.array(y)
    s = _similar_scale(X)
    if s is not None:  # a mirror flips x cross y: the normal follows, so the arc still turns the drawn way
        return ArcCurve(c, np.cross(u, v), u, radius * s, sweep)
    ce = ConstructionEllipse.from_arc(Vec3(0, 0, 0), radius, Vec3(0, 0, 1), 0.0, math.degrees(sweep))
    return _ellipse(
        _matrix44(np.column_stack([np.append(u, 0), np.append(v, 0), np.append(np.cross(u, v), 0), np.append(c, 1)])),
        ce,
    )


def _ellipse(M: Matrix44, ce: ConstructionEllipse) -> EllipseCurve:
    ce.transform(M)  # ezdxf re-derives the axes (Rytz) under any affine map
    sweep = (ce.end_param - ce.start_param) % (2.0 * math.pi) or 2.0 * math.pi
    return EllipseCurve(np.array(ce.center), np.array(ce.major_axis), np.array(ce.minor_axis), ce.start_param, sweep)


def entity_curve(e: DXFGraphic, X: FloatArray) -> Curve:
    """The curve of an ARC, CIRCLE, ELLIPSE, SPLINE or HELIX, in the map (drawing units); ``X`` (4, 4) the
    enclosing INSERTs' transform (block coordinates to the map)."""
    kind = e.dxftype()
    if kind in ("ARC", "CIRCLE"):
        ocs = OCS(e.dxf.extrusion)
        a0 = math.radians(float(e.dxf.start_angle)) if kind == "ARC" else 0.0
        sweep = 2.0 * math.pi
        if kind == "ARC":
            sweep = math.radians((float(e.dxf.end_angle) - float(e.dxf.start_angle)) % 360.0) or 2.0 * math.pi
        centre = ocs.to_wcs(Vec3(e.dxf.center))
        x = ocs.to_wcs(Vec3(math.cos(a0), math.sin(a0), 0.0))  # OCS directions: to_wcs of a vector is a rotation
        y = ocs.to_wcs(Vec3(-math.sin(a0), math.cos(a0), 0.0))
        return _arc(X, centre, x, y, float(e.dxf.radius), sweep)
    if kind == "ELLIPSE":
        return _ellipse(_matrix44(X), e.construction_tool())  # type: ignore[attr-defined]
    spline = e.construction_tool()  # type: ignore[attr-defined]  # SPLINE and HELIX: a BSpline
    ctrl = np.array(spline.control_points, dtype=float)
    extent = float(np.ptp(ctrl, axis=0).max()) if len(ctrl) else 0.0
    chord = max(extent * SPLINE_CHORD_REL, 1e-9)
    P = np.array([tuple(p) for p in spline.flattening(chord, segments=8)], dtype=float)
    A = np.asarray(X)[:3, :3]
    P = P @ A.T + np.asarray(X)[:3, 3]
    closed = bool(e.closed) or (len(P) > 2 and np.allclose(P[0], P[-1], atol=chord))  # type: ignore[attr-defined]
    if closed and len(P) > 2 and np.allclose(P[0], P[-1], atol=chord):
        P = P[:-1]
    return SampledCurve(P, chord * float(np.linalg.svd(A, compute_uv=False).max()), closed)


def bulge_curve(
    X: FloatArray, ocs: OCS, start: tuple[float, float], end: tuple[float, float], elevation: float, bulge: float
) -> ArcCurve | EllipseCurve:
    """The arc of a polyline segment with a bulge, from ``start`` to ``end`` (OCS x, y at ``elevation``), in the map;
    a positive bulge turns counter-clockwise about the OCS z axis, a negative one clockwise."""
    centre2, _, _, radius = bulge_to_arc(start, end, bulge)
    centre = ocs.to_wcs(Vec3(centre2.x, centre2.y, elevation))
    p0 = ocs.to_wcs(Vec3(start[0], start[1], elevation))
    x = (p0 - centre).normalize()
    z = ocs.uz if bulge > 0 else -ocs.uz
    return _arc(X, centre, x, z.cross(x), float(radius), 4.0 * math.atan(abs(bulge)))
