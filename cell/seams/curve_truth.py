"""Ground truth of a curved seam of the part as really built (simulation only; exact, no noise): the intersection
curve of the two as-built surfaces it lies on (a round part's cylinder, a flat face's plane), sampled finely. A tube
standing square on a plate gives a circle, a leaning one an ellipse, a branch on a run pipe a saddle (docs/bodies.md
section 8)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from cell.errors import MapError
from cell.geometry import FloatArray, invert, transform_points
from cell.seams.curved.surfaces import CylinderModel, Implicit, PlaneModel, intersect
from cell.types import CurvedSeam, Cylinder, Part, Polyhedron, Surface, WeldMap
from cell.weldmap.curved_joints import holding_face
from cell.weldmap.cylinders import recognise_cylinder

STEP_M = 0.0005  # [m] the true curve's samples are at most this far apart


def _cylinder_surface(c: Cylinder) -> Implicit:
    return CylinderModel(np.asarray(c.p_base), np.asarray(c.axis), c.radius).implicit(np.zeros(CylinderModel.size))


def _plane_surface(n: FloatArray, d: float) -> Implicit:
    return PlaneModel(n * d, n).implicit(np.zeros(PlaneModel.size))


def rigid_motion(design: FloatArray, built: FloatArray) -> FloatArray:
    """X (4, 4) the rigid motion that best carries the points ``design`` (k, 3) onto ``built`` (k, 3) (Kabsch)."""
    a, b = design.mean(axis=0), built.mean(axis=0)
    U, _, Vt = np.linalg.svd((design - a).T @ (built - b))
    D = np.diag([1.0, 1.0, float(np.sign(np.linalg.det(Vt.T @ U.T)))])
    X = np.eye(4)
    X[:3, :3] = Vt.T @ D @ U.T
    X[:3, 3] = b - X[:3, :3] @ a
    return X


def _as_built(parts: Sequence[Part], name: str) -> Part:
    for p in parts:
        if p.name == name:
            return p
    raise MapError(f"the as-built parts have no part {name!r}; they have: {', '.join(p.name for p in parts)}")


def _surface(design: Part, built: Part, kind: Surface, p_M: FloatArray, X_WD: FloatArray) -> Implicit:
    """The as-built surface that stands for the design surface of ``kind`` holding the seam points ``p_M``."""
    if kind is Surface.CYLINDER:
        c = recognise_cylinder(built.body) if isinstance(built.body, Polyhedron) else None
        if c is None:  # bowed or reshaped: the design's round moved as the part moved
            assert design.cylinder is not None
            c = design.cylinder.transformed(X_WD)
        return _cylinder_surface(c)
    face = holding_face(design, p_M)
    if face is None:
        raise MapError(f"no face of part {design.name} holds the curved seam")
    n, d = built.face_plane(face)
    return _plane_surface(n, d)


def true_curve_W(design_M: WeldMap, seam: CurvedSeam, parts_as_built_W: Sequence[Part], X_WM: FloatArray) -> FloatArray:
    """(n, 3) the true curve of one curved seam in the world W [m], at most :data:`STEP_M` apart, in the drawn
    seam's order. ``design_M``: the designed map (frame M); ``X_WM``: the map's nominal placement."""
    joint = seam.joint
    if joint is None:
        raise MapError(f"curved seam {seam.id!r} has no joint ({seam.note}); its truth needs the two parts it joins")
    p_M = seam.sample(STEP_M)
    surfaces = []
    moves = []
    for name, kind in ((joint.abutting, joint.abutting_surface), (joint.receiving, joint.receiving_surface)):
        design, built = design_M.part(name), _as_built(parts_as_built_W, name)
        X_WD = rigid_motion(transform_points(X_WM, design.vertices()), built.vertices()) @ X_WM
        moves.append(X_WD)
        surfaces.append(_surface(design, built, kind, p_M, X_WD))
    return intersect(transform_points(moves[0], p_M), surfaces[0], surfaces[1])


def true_curves(
    design_M: WeldMap, parts_as_built_W: Sequence[Part], X_WM: FloatArray, X_WR: FloatArray
) -> dict[str, FloatArray]:
    """Seam id -> the true curve (n, 3) in the robot frame R of every curved seam of ``design_M`` with a joint."""
    X_RW = invert(np.asarray(X_WR, dtype=float))
    return {
        s.id: transform_points(X_RW, true_curve_W(design_M, s, parts_as_built_W, X_WM))
        for s in design_M.curved
        if s.joint is not None
    }
