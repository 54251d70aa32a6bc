"""Static bodies of the simulated cell: a box as PyBullet's box, any other closed body rendered and collided from its
mesh about its centroid (docs/bodies.md section 1). Every body is static; poses and vertices in the world W [m]."""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np
from scipy.spatial.transform import Rotation

from cell.geometry import FloatArray
from cell.sim.quiet import BulletClient, pybullet
from cell.types import Box, Part

Rgba = tuple[float, float, float, float]


def _place(client: BulletClient, collision: int, visual: int, position: FloatArray, R: FloatArray) -> int:
    # scipy and PyBullet both order quaternions (x, y, z, w): no conversion needed.
    quat = Rotation.from_matrix(R).as_quat()
    body = client.createMultiBody(
        baseMass=0.0,
        baseCollisionShapeIndex=collision,
        baseVisualShapeIndex=visual,
        basePosition=[float(v) for v in position],
        baseOrientation=[float(v) for v in quat],
    )
    return int(body)


def add_box(client: BulletClient, box_W: Box, rgba: Rgba) -> int:
    """A static box body (its pose and size in W) coloured ``rgba``; returns the PyBullet body id."""
    half = [float(h) for h in box_W.size / 2.0]
    collision = client.createCollisionShape(pybullet.GEOM_BOX, halfExtents=half)
    visual = client.createVisualShape(pybullet.GEOM_BOX, halfExtents=half, rgbaColor=list(rgba))
    return _place(client, collision, visual, box_W.center, box_W.X_AB[:3, :3])


def add_floor(client: BulletClient, box_W: Box, rgba: Rgba, *, drawn: bool = False) -> int:
    """The floor: a static body that collides as the thin box ``box_W`` (axis-aligned, its top face the floor);
    returns the PyBullet body id. The cameras' images get it from :class:`cell.sim.floor.Floor` after TinyRenderer
    has drawn the rest (docs/bodies.md section 1); ``drawn`` (a GUI's view) gives it a visual shape too: its top
    face alone (two triangles, normals up), since nothing in the cell looks at the floor from below or beside it."""
    half = box_W.size / 2.0
    collision = client.createCollisionShape(pybullet.GEOM_BOX, halfExtents=[float(h) for h in half])
    if not drawn:  # a clear speck: with no visual shape at all TinyRenderer would draw the collision box
        speck = client.createVisualShape(pybullet.GEOM_BOX, halfExtents=[1e-3] * 3, rgbaColor=[0.0, 0.0, 0.0, 0.0])
        return _place(client, collision, speck, box_W.center, box_W.X_AB[:3, :3])
    hx, hy, hz = (float(h) for h in half)
    top = [[-hx, -hy, hz], [hx, -hy, hz], [hx, hy, hz], [-hx, hy, hz]]
    visual = client.createVisualShape(
        pybullet.GEOM_MESH,
        vertices=top,
        indices=[0, 1, 2, 0, 2, 3],
        normals=[[0.0, 0.0, 1.0]] * 4,
        rgbaColor=list(rgba),
    )
    return _place(client, collision, visual, box_W.center, box_W.X_AB[:3, :3])


def add_mesh(client: BulletClient, vertices_W: FloatArray, triangles: np.ndarray, rgba: Rgba) -> int:
    """A static body from a closed triangle mesh: vertices (k, 3) [m] in W, triangles (t, 3) vertex indices with
    outward winding; placed at the vertices' mean. Returns the PyBullet body id."""
    v = np.asarray(vertices_W, dtype=float)
    origin = v.mean(axis=0)
    local = [[float(c) for c in p] for p in v - origin]
    idx = [int(i) for i in np.asarray(triangles, dtype=int).ravel()]
    collision = client.createCollisionShape(
        pybullet.GEOM_MESH, vertices=local, indices=idx, flags=pybullet.GEOM_FORCE_CONCAVE_TRIMESH
    )
    visual = client.createVisualShape(pybullet.GEOM_MESH, vertices=local, indices=idx, rgbaColor=list(rgba))
    return _place(client, collision, visual, origin, np.eye(3))


def add_part(client: BulletClient, part_W: Part, rgba: Rgba) -> int:
    """A part (or fixture) in W as a static body: its box when it is a box, else its mesh."""
    if part_W.is_box:
        return add_box(client, part_W.box, rgba)
    vertices, triangles = part_W.triangles()
    return add_mesh(client, vertices, triangles, rgba)


def move_bodies(client: BulletClient, bodies: Iterable[int], X_W_new_old: FloatArray) -> None:
    """Move each body by the rigid motion X_W_new_old (4, 4) in W (their poses composed in one batch)."""
    ids = list(bodies)
    if not ids:
        return
    poses = [client.getBasePositionAndOrientation(b) for b in ids]
    X = np.asarray(X_W_new_old, dtype=float)
    R_W = X[:3, :3] @ Rotation.from_quat([q for _, q in poses]).as_matrix()  # (n, 3, 3)
    p_W = np.array([p for p, _ in poses], dtype=float) @ X[:3, :3].T + X[:3, 3]
    quats = Rotation.from_matrix(R_W).as_quat()
    for body, p, q in zip(ids, p_W.tolist(), quats.tolist(), strict=True):
        client.resetBasePositionAndOrientation(body, p, q)
