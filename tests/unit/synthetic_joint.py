"""A synthetic T joint rendered with numpy, for the locators' tests (test_locators.py, test_locator_contract.py).

A post A (80 x 300 x 80 mm, along y) abuts the -y face of a rail B (400 x 100 x 100 mm, along x) with a 1 mm
gap, like fence1's POST_L > TOP_RAIL. Depth cameras are ray-cast (pixel footprint ~1.4 mm at ~1.3 m,
occlusion, dropout at grazing incidence), with Gaussian noise along the ray, a few % of flying pixels and a
missing band at the corner. The as-built parts differ from the map by a few mm, so a locator that returns the
map's seam fails. Everything is in the robot frame R, metres.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from cell.geometry import FloatArray, invert, look_at, make_pose, rot_x, rot_z, transform_points
from cell.types import Box, Cloud, Joint, MapSeam, Part, Polyhedron, SeamScene, WeldMap

TOP = "A>B:+z"  # along x, on A's top
SIDE = "A>B:+x"  # along z, on A's +x side
JOINTS = {
    TOP: Joint(TOP, "A", "B", "+z", "-y", "+y"),
    SIDE: Joint(SIDE, "A", "B", "+x", "-y", "+y"),
}
CAMERAS = (
    ((0.75, -0.65, 1.0), (0.0, -0.02, 0.05)),
    ((-0.7, -0.7, 1.05), (0.0, -0.02, 0.05)),
    ((0.1, -1.0, 1.1), (0.0, -0.02, 0.05)),
)  # (eye, target) [m], in the joint's frame


def box(lo: Sequence[float], hi: Sequence[float]) -> Box:
    lo_, hi_ = np.asarray(lo, float), np.asarray(hi, float)
    return Box(make_pose(p=(lo_ + hi_) / 2.0), hi_ - lo_)


NOMINAL = {
    "A": box((-0.04, -0.301, 0.0), (0.04, -0.001, 0.08)),
    "B": box((-0.2, 0.0, 0.0), (0.2, 0.1, 0.1)),
}
# As built [m]: A 2 mm to +x, 0.6 mm wider, 0.7 mm taller, 1.5 mm to -y; B's face 1.5 mm nearer A (gap still
# 1 mm).
AS_BUILT = {
    "A": box((-0.0383, -0.3025, 0.0), (0.0423, -0.0025, 0.0807)),
    "B": box((-0.2, -0.0015, 0.0), (0.2, 0.1, 0.1)),
}


def seam_of(boxes: dict[str, Box], joint: Joint) -> tuple[FloatArray, FloatArray]:
    """The seam of ``joint``: where A's weld face plane meets B's, between A's two side faces across it."""
    a, b = boxes[joint.abutting], boxes[joint.receiving]
    n_a, d_a = a.face_plane(joint.face_abutting)
    n_b, d_b = b.face_plane(joint.face_receiving)
    t = np.cross(n_a, n_b)
    t /= np.linalg.norm(t)
    p0 = np.linalg.solve(np.vstack([n_a, n_b, t]), np.array([d_a, d_b, float(t @ a.center)]))
    k = int(np.argmax(np.abs(a.X_AB[:3, :3].T @ t)))
    ax = a.X_AB[:3, k] * np.sign(a.X_AB[:3, k] @ t)
    half = a.size[k] / 2.0
    s = sorted(((ax @ a.center + sg * half) - ax @ p0) / (ax @ t) for sg in (-1.0, 1.0))
    return p0 + s[0] * t, p0 + s[1] * t


def _ray_boxes(eye: FloatArray, D: FloatArray, boxes: Sequence[Box]) -> tuple[FloatArray, FloatArray, np.ndarray]:
    """Nearest hit distance (m,) along unit rays D (m, 3) from ``eye``, the outward normal there (m, 3) and the
    index of the box hit (m,) (-1: none)."""
    best = np.full(len(D), np.inf)
    normal = np.zeros((len(D), 3))
    which = np.full(len(D), -1)
    for i, box in enumerate(boxes):
        R = box.X_AB[:3, :3]
        o = R.T @ (eye - box.center)
        d = D @ R
        d = np.where(np.abs(d) < 1e-12, 1e-12, d)
        h = box.size / 2.0
        t1, t2 = (-h - o) / d, (h - o) / d
        tn, tf = np.minimum(t1, t2), np.maximum(t1, t2)
        near, axis = tn.max(axis=1), tn.argmax(axis=1)
        hit = (near <= tf.min(axis=1)) & (near > 0.0) & (near < best)
        best[hit] = near[hit]
        which[hit] = i
        sign = -np.sign(d[hit, axis[hit]])
        normal[hit] = sign[:, None] * R[:, axis[hit]].T
    return best, normal, which


@dataclass(frozen=True)
class Render:
    sigma_m: float = 0.002  # depth noise along the ray
    pixel_rad: float = 0.0011  # angular pixel pitch (about 1.4 mm at 1.3 m)
    flying: float = 0.03  # fraction of pixels returned anywhere up to 40 mm behind the surface
    corner_band_m: float = 0.0025  # no returns this close to the seams (gap, shadow)
    table: bool = True
    turn_cameras: bool = True  # the cameras turn with the parts (else they stay put, only shifted with them)
    hide_top_of: str = ""  # no returns from this part's top face (as a face seen at grazing incidence drops out)


def render(boxes: dict[str, Box], X: FloatArray, opts: Render, rng: np.random.Generator) -> Cloud:
    """Ray-cast the boxes (and the table z = 0) from CAMERAS, all moved by the pose X (4, 4); frame R."""
    pts, cams = [], []
    moved = [b.transformed(X) for b in boxes.values()]
    corners = np.vstack([b.corners() for b in moved])
    lines = [seam_of({k: b.transformed(X) for k, b in boxes.items()}, j) for j in JOINTS.values()]
    X_cam = X if opts.turn_cameras else make_pose(p=X[:3, 3])
    for c, (eye, target) in enumerate(CAMERAS):
        eye_R = transform_points(X_cam, eye)
        target_R = transform_points(X_cam, target)
        X_RC = look_at(tuple(eye_R), tuple(target_R), up=tuple(X_cam[:3, 2]))
        q = transform_points(invert(X_RC), corners)
        uv = q[:, :2] / q[:, 2:3]
        u = np.arange(uv[:, 0].min(), uv[:, 0].max(), opts.pixel_rad)
        v = np.arange(uv[:, 1].min(), uv[:, 1].max(), opts.pixel_rad)
        U, V = np.meshgrid(u, v)
        D = np.column_stack([U.ravel(), V.ravel(), np.ones(U.size)]) @ X_RC[:3, :3].T
        D /= np.linalg.norm(D, axis=1, keepdims=True)
        dist, normal, which = _ray_boxes(eye_R, D, moved)
        hidden = np.zeros(len(D), bool)
        if opts.hide_top_of:
            hidden = (which == list(boxes).index(opts.hide_top_of)) & (normal @ X[:3, 2] > 0.9)
        if opts.table:  # the table top z = 0 of the joint's frame, X being a turn about z
            tz = (X[2, 3] - eye_R[2]) / np.where(D[:, 2] < -1e-9, D[:, 2], -1e-9)
            on_table = tz < dist
            hidden &= ~on_table
            dist = np.where(on_table, tz, dist)
            normal[on_table] = (0.0, 0.0, 1.0)
        ok = np.isfinite(dist) & (np.abs(np.einsum("ij,ij->i", D, normal)) > np.cos(np.radians(80.0))) & ~hidden
        dist, D = dist[ok], D[ok]
        dist = dist + opts.sigma_m * rng.standard_normal(len(dist))
        fly = rng.random(len(dist)) < opts.flying
        dist[fly] += rng.uniform(-0.005, 0.04, int(fly.sum()))
        p = eye_R + D * dist[:, None]
        for a, b in lines:
            t = (b - a) / np.linalg.norm(b - a)
            q2 = p - a
            perp = q2 - np.outer(q2 @ t, t)
            p = p[np.linalg.norm(perp, axis=1) > opts.corner_band_m]
        pts.append(p)
        cams.append(np.full(len(p), c, np.int16))
    return Cloud(np.vstack(pts), "R", np.concatenate(cams), tuple(f"cam{i}" for i in range(len(CAMERAS))))


def make_scene(X: FloatArray | None = None, opts: Render = Render(), seed: int = 0) -> tuple[SeamScene, dict]:
    """The T joint moved by X (4, 4): the scene (map = nominal boxes) and the true seams {id: (p0, p1)}."""
    X = np.eye(4) if X is None else X
    rng = np.random.default_rng(seed)
    dense = render(AS_BUILT, X, opts, rng)
    parts = tuple(Part(k, b.transformed(X)) for k, b in NOMINAL.items())
    nominal = {k: b.transformed(X) for k, b in NOMINAL.items()}
    built = {k: b.transformed(X) for k, b in AS_BUILT.items()}
    seams = tuple(MapSeam(j, *seam_of(nominal, JOINTS[j])) for j in JOINTS)
    truth = {j: seam_of(built, JOINTS[j]) for j in JOINTS}
    weldmap = WeldMap(parts, seams, "mm", "synthetic", frame="R")
    table_z = float(X[2, 3]) if opts.table else -1.0
    return SeamScene(dense, dense, weldmap, JOINTS, table_z), truth


def errors(est_start: FloatArray, est_end: FloatArray, truth: tuple[FloatArray, FloatArray]) -> tuple[float, float]:
    """(largest lateral distance of the estimated ends from the true line, largest end error along it) [m]."""
    a, b = truth
    t = (b - a) / np.linalg.norm(b - a)
    lat, along = 0.0, 0.0
    for p, q in ((est_start, a), (est_end, b)):
        v = p - a
        lat = max(lat, float(np.linalg.norm(v - (v @ t) * t)))
        along = max(along, abs(float((p - q) @ t)))
    return lat, along


def pose(R: FloatArray, p: Sequence[float] = (0.3, -0.2, 0.9)) -> FloatArray:
    return make_pose(R, p)


CASES = {
    "axis-aligned": (pose(np.eye(3)), Render()),
    "rotated 30 deg about z": (pose(rot_z(np.radians(30.0))), Render(turn_cameras=False)),
    "tilted 20 deg about x": (pose(rot_x(np.radians(20.0))), Render(table=False)),
}


def thinned(scene: SeamScene, keep: np.ndarray) -> SeamScene:
    """``scene`` with only the dense points ``keep`` (n,) (its cloud the same points)."""
    dense = scene.dense.select(keep)
    return SeamScene(dense, dense, scene.weldmap, scene.joints, scene.table_z)


def scene_with(boxes: dict[str, Box], opts: Render, seed: int = 0) -> tuple[SeamScene, dict]:
    """Like :func:`make_scene` (axis-aligned case) with other as-built boxes; the map stays NOMINAL."""
    X = CASES["axis-aligned"][0]
    dense = render(boxes, X, opts, np.random.default_rng(seed))
    parts = tuple(Part(k, b.transformed(X)) for k, b in NOMINAL.items())
    nominal = {k: b.transformed(X) for k, b in NOMINAL.items()}
    seams = tuple(MapSeam(j, *seam_of(nominal, JOINTS[j])) for j in JOINTS)
    truth = {j: seam_of({k: b.transformed(X) for k, b in boxes.items()}, JOINTS[j]) for j in JOINTS}
    weldmap = WeldMap(parts, seams, "mm", "synthetic", frame="R")
    return SeamScene(dense, dense, weldmap, JOINTS, float(X[2, 3])), truth


def a_taller(dz: float) -> dict[str, Box]:
    """The as-built boxes with A ``dz`` [m] taller."""
    a = AS_BUILT["A"]
    lo, hi = a.center - a.size / 2.0, a.center + a.size / 2.0 + np.array([0.0, 0.0, dz])
    return {"A": box(lo.tolist(), hi.tolist()), "B": AS_BUILT["B"]}


def voxel_cloud(cloud: Cloud, voxel: float) -> Cloud:
    """The centroid of the points in each occupied voxel (the paper's 1 cm downsampling)."""
    ijk = np.floor(cloud.points / voxel).astype(np.int64)
    _, inverse, counts = np.unique(ijk, axis=0, return_inverse=True, return_counts=True)
    inverse = inverse.reshape(-1)
    sums = np.stack([np.bincount(inverse, cloud.points[:, i]) for i in range(3)], axis=1)
    return Cloud(sums / counts[:, None], cloud.frame)


def square_tube(center: np.ndarray, outer: float, wall: float, height: float) -> Polyhedron:
    """A vertical square tube (its bore open top and bottom) as a closed polyhedron [m]."""
    o, i = outer / 2.0, outer / 2.0 - wall
    square = [(-1, -1), (1, -1), (1, 1), (-1, 1)]
    v = [
        (center[0] + h * x, center[1] + h * y, center[2] + z) for z in (0.0, height) for h in (o, i) for x, y in square
    ]
    # 0-3 outer bottom, 4-7 inner bottom, 8-11 outer top, 12-15 inner top
    faces = []
    for k in range(4):
        j = (k + 1) % 4
        faces.append((k, j, 8 + j, 8 + k))  # outer wall, outward
        faces.append((4 + j, 4 + k, 12 + k, 12 + j))  # inner wall, facing the bore
        faces.append((j, k, 4 + k, 4 + j))  # bottom ring, facing down
        faces.append((8 + k, 8 + j, 12 + j, 12 + k))  # top ring, facing up
    return Polyhedron(np.array(v, float), tuple(faces))
