"""The shapes' geometry, part of the coal adapter: the torch's shapes cut back near the wire tip, the obstacles'
coal shapes (box, convex polyhedron or triangle mesh, each grown by its margin) and the contacts of many TCP poses
in one broad-phase query, with a point-in-body test where a mesh reads clear (docs/bodies.md section 2); the arm's
shapes' bounds (each one's sphere, each joint's radius) for the checker's broad phase and path steps."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import NamedTuple

import coal
import numpy as np
import numpy.typing as npt
import pinocchio as pin

from cell.config.motion import CollisionOptions
from cell.geometry import FloatArray, invert, readonly
from cell.motion.collision.contact import Contact, sphere_box_distance
from cell.motion.collision.grow import bounding_box, grown_convex, grown_mesh, is_convex
from cell.types import Part, Polyhedron


def trim_near_tcp(model: pin.Model, geom: pin.GeometryModel, tcp: int, r_ex: float) -> None:
    """Cut the torch cylinders coaxial with the wire (on the TCP frame ``tcp``'s joint) back to ``r_ex`` [m] (the
    options' ``tcp_clearance``) behind the wire tip; a cylinder wholly within it is removed."""
    frame = model.frames[tcp]
    X_JT = np.array(frame.placement.homogeneous)  # TCP in its parent joint's frame
    drop = []
    for i, obj in enumerate(geom.geometryObjects):
        if obj.parentJoint != frame.parentJoint or not isinstance(obj.geometry, coal.Cylinder):
            continue
        X_JG = np.array(obj.placement.homogeneous)
        X_TG = invert(X_JT) @ X_JG  # the shape in the TCP frame: coaxial shapes lie on -z
        axis, c = X_TG[:3, 2], X_TG[:3, 3]
        if np.linalg.norm(c[:2]) > 1e-6 or abs(abs(axis[2]) - 1.0) > 1e-6:
            continue
        half = float(obj.geometry.halfLength)
        front, back = -c[2] - half, -c[2] + half  # distances behind the tip [m]
        if front >= r_ex:
            continue
        if back <= r_ex:
            drop.append(i)
            continue
        new_half = (back - r_ex) / 2.0
        X_TG_new = X_TG.copy()
        X_TG_new[:3, 3] = [0.0, 0.0, -(r_ex + new_half)]
        obj.geometry = coal.Cylinder(float(obj.geometry.radius), 2.0 * new_half)
        obj.placement = pin.SE3(X_JT @ X_TG_new)
    for i in reversed(drop):
        geom.removeGeometryObject(geom.geometryObjects[i].name)


@dataclass(frozen=True)
class ToolShapes:
    """The tool-side collision shapes: their poses X_TG (m, 4, 4) in the TCP frame, bounding spheres (centre in
    G (m, 3), radius (m,)) [m], and the coal shapes."""

    X_TG: FloatArray
    centre_G: FloatArray
    radius: FloatArray
    shapes: tuple[object, ...]

    @staticmethod
    def build(m: pin.Model, data: pin.Data, geom: pin.GeometryModel, tcp_frame: int, ids: Sequence[int]) -> ToolShapes:
        """The shapes ``ids`` of ``geom`` (those rigid with the flange), placed at the neutral configuration."""
        gdata = pin.GeometryData(geom)
        q = pin.neutral(m)
        pin.forwardKinematics(m, data, q)
        pin.updateFramePlacements(m, data)
        pin.updateGeometryPlacements(m, data, geom, gdata)
        X_TR = invert(np.array(data.oMf[tcp_frame].homogeneous))
        X, cen, rad, shapes = [], [], [], []
        for i in ids:
            g = geom.geometryObjects[i].geometry
            g.computeLocalAABB()
            lo, hi = np.array(g.aabb_local.min_), np.array(g.aabb_local.max_)
            X.append(X_TR @ np.array(gdata.oMg[i].homogeneous))
            cen.append((lo + hi) / 2.0)
            rad.append(float(np.linalg.norm(hi - lo)) / 2.0)
            shapes.append(g)
        return ToolShapes(np.array(X).reshape(-1, 4, 4), np.array(cen).reshape(-1, 3), np.array(rad), tuple(shapes))


def joint_radii(model: pin.Model, robot_shapes: Sequence[pin.GeometryObject]) -> FloatArray:
    """r_j (dof,): bound on the distance of any point of the arm's collision shapes from joint j's axis [m]."""
    r = np.zeros(model.njoints - 1)
    for obj in robot_shapes:
        # radius of a ball around the shape's origin that holds the shape
        g = obj.geometry
        if isinstance(g, coal.Box):
            rad = float(np.linalg.norm(g.halfSide))
        elif isinstance(g, coal.Cylinder):
            rad = float(np.hypot(g.radius, g.halfLength))
        else:
            g.computeLocalAABB()
            rad = float(np.linalg.norm(g.aabb_local.max_ - g.aabb_local.min_) / 2.0)
        j = obj.parentJoint
        reach = float(np.linalg.norm(obj.placement.translation)) + rad
        while j > 0:  # the shape's distance from each joint up the chain, by the triangle inequality
            r[j - 1] = max(r[j - 1], reach)
            reach += float(np.linalg.norm(model.jointPlacements[j].translation))
            j = model.parents[j]
    return readonly(r)


def local_spheres(robot_shapes: Sequence[pin.GeometryObject]) -> tuple[FloatArray, FloatArray]:
    """Each of the arm's shapes' bounding sphere in its own frame (the centre of its local box): centres (n, 3)
    and radii (n,) [m], the broad phase of a check."""
    centres, radii = [], []
    for obj in robot_shapes:
        obj.geometry.computeLocalAABB()
        lo, hi = np.array(obj.geometry.aabb_local.min_), np.array(obj.geometry.aabb_local.max_)
        centres.append((lo + hi) / 2.0)
        radii.append(float(np.linalg.norm(hi - lo)) / 2.0)
    return np.array(centres).reshape(-1, 3), np.array(radii)


Solids = Mapping[int, Polyhedron]  # obstacle index -> a non-convex body whose coal shape is its surface only


def surface_only(part: Part) -> bool:
    """Whether the obstacle's coal shape is a triangle mesh (a body neither a box nor convex)."""
    return not part.is_box and isinstance(part.body, Polyhedron) and not is_convex(part.body)


def signed(distance: float, solid: Polyhedron | None, centre_R: FloatArray) -> float:
    """A surface distance [m] made a penetration (negative) when the shape's centre (3,) lies inside ``solid``."""
    if solid is None or distance <= 0.0 or not bool(solid.contains(centre_R.reshape(1, 3))[0]):
        return distance
    return -distance


class Bound(NamedTuple):
    """A box that holds an obstacle's grown shape, in R: rotation R_RB (3, 3), centre (3,), half sizes (3,) [m]."""

    R_RB: FloatArray
    centre: FloatArray
    half: FloatArray


def obstacle_shape(part: Part, grow: float) -> tuple[object, FloatArray, Bound]:
    """The coal shape of an obstacle grown by ``grow`` [m], its placement X_RG (4, 4) and a box that holds it.

    A box is a ``coal.Box`` at its pose (its bound: itself); any other body's vertices are given in R (placement
    the identity): ``coal.Convex`` of its grown hull when it is convex, else a ``coal.BVHModelOBBRSS`` of its
    triangles grown along the vertex normals; its bound is the grown vertices' axis-aligned box."""
    if part.is_box:
        box = part.box
        size = np.asarray(box.size, dtype=float) + 2.0 * grow
        X = np.asarray(box.X_AB, dtype=float)
        return coal.Box(size), X, Bound(X[:3, :3], X[:3, 3], size / 2.0)
    body = part.body
    assert isinstance(body, Polyhedron)
    if is_convex(body):
        pts = grown_convex(body, grow)
        vec = coal.StdVec_Vec3s()
        for p in pts:
            vec.append(np.asarray(p, dtype=float))
        shape: object = coal.Convex.convexHull(vec, True, "Qt")  # keep its triangles: qhull triangulates facets
    else:
        pts, tris = grown_mesh(body, grow)
        bvh = coal.BVHModelOBBRSS()
        bvh.beginModel(len(tris), len(pts))
        bvh.addVertices(np.asarray(pts, dtype=float))
        bvh.addTriangles(np.asarray(tris, dtype=np.int64))
        bvh.endModel()
        shape = bvh
    return shape, np.eye(4), Bound(*bounding_box(pts))


def add_obstacles(
    geom: pin.GeometryModel, obstacles: Sequence[Part], options: CollisionOptions
) -> tuple[list[Bound], dict[int, Polyhedron]]:
    """Add every obstacle to ``geom`` (fixed to the universe, named by its part) as its coal shape grown by its margin
    (``table_inflation`` for the part named ``table_name``, else ``part_inflation``). Returns one bound per obstacle
    and the bodies whose shape is a surface only, by obstacle index (:data:`Solids`)."""
    bounds: list[Bound] = []
    solids: dict[int, Polyhedron] = {}
    for i, part in enumerate(obstacles):
        grow = options.table_inflation if part.name == options.table_name else options.part_inflation
        shape, X_RG, bound = obstacle_shape(part, grow)
        geom.addGeometryObject(pin.GeometryObject(part.name, 0, 0, pin.SE3(X_RG), shape))
        bounds.append(bound)
        if surface_only(part) and isinstance(part.body, Polyhedron):
            solids[i] = part.body
    return bounds, solids


@dataclass(frozen=True)
class Boxes:
    """The obstacles' bounding boxes as placed in R: rotation R_RB (k, 3, 3), centre (k, 3), half sizes (k, 3) [m]
    (grown; for a box obstacle the box itself), and the obstacles' coal shapes and transforms."""

    R_RB: FloatArray
    centre: FloatArray
    half: FloatArray
    shapes: tuple[object, ...]
    T: tuple[object, ...]

    @staticmethod
    def build(geom: pin.GeometryModel, ids: Sequence[int], bounds: Sequence[Bound]) -> Boxes:
        """The obstacles ``ids`` of ``geom`` with their bounds (one per obstacle, same order)."""
        objs = [geom.geometryObjects[k] for k in ids]
        R = np.array([b.R_RB for b in bounds], dtype=float).reshape(-1, 3, 3)
        c = np.array([b.centre for b in bounds], dtype=float).reshape(-1, 3)
        half = np.array([b.half for b in bounds], dtype=float).reshape(-1, 3)
        T = tuple(coal.Transform3s(np.array(o.placement.rotation), np.array(o.placement.translation)) for o in objs)
        return Boxes(R, c, half, tuple(o.geometry for o in objs), T)

    def sphere_distance(self, c_R: FloatArray, radius: FloatArray) -> FloatArray:
        """(m, k) [m]: :func:`cell.motion.collision.contact.sphere_box_distance` to each of these boxes."""
        return sphere_box_distance(self.R_RB, self.centre, self.half, c_R, radius)


def torch_contacts(
    tool: ToolShapes,
    boxes: Boxes,
    tool_ids: Sequence[int],
    obstacle_ids: Sequence[int],
    link_of: Sequence[str],
    min_clearance: float,
    X_RT: npt.ArrayLike,
    q_ref: npt.ArrayLike,
    first: bool = False,
    solids: Solids | None = None,
) -> list[Contact | None]:
    """The deepest contact (or with ``first`` the first found) of the tool's shapes against the boxes for every
    TCP pose X_RT (m, 4, 4) [m], None where a pose is clear by ``min_clearance``. tool_ids / obstacle_ids: the
    shapes' and boxes' indices in the checker's geometry model, link_of its names by index (for the contact);
    solids: the obstacles (by their index among the boxes) whose shape is a surface (see :func:`signed`)."""
    X_RT = np.asarray(X_RT, dtype=float).reshape(-1, 4, 4)
    X_RG = X_RT[:, None] @ tool.X_TG[None]  # (m, shapes, 4, 4)
    c_R = np.einsum("msij,sj->msi", X_RG[..., :3, :3], tool.centre_G) + X_RG[..., :3, 3]
    m, n_s = X_RG.shape[:2]
    lower = boxes.sphere_distance(c_R.reshape(-1, 3), np.tile(tool.radius, m)).reshape(m, n_s, -1)
    req = coal.DistanceRequest()
    q = readonly(np.asarray(q_ref, dtype=float))
    best: list[Contact | None] = [None] * m
    for p, a, k in zip(*np.nonzero(lower <= min_clearance), strict=True):
        if first and best[p] is not None:
            continue
        i, j = tool_ids[a], obstacle_ids[k]
        Tg = coal.Transform3s(X_RG[p, a, :3, :3], X_RG[p, a, :3, 3])
        res = coal.DistanceResult()
        dist = coal.distance(tool.shapes[a], Tg, boxes.shapes[k], boxes.T[k], req, res)
        if solids:
            dist = signed(dist, solids.get(int(k)), c_R[p, a])
        b = best[p]
        if dist <= min_clearance and (b is None or dist < b.depth):
            pt = readonly(np.array(res.getNearestPoint1()))
            best[p] = Contact(link_of[i], link_of[j], float(dist), pt, q)
    return best
