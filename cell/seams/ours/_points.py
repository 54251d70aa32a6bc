"""The points our locator looks at for one seam (frame R, metres): a tube of the dense cloud about it, from a share
of its points (:class:`~cell.seams._index.CloudIndex`), and which of them may support a plane (above the table,
away from every other part of the map)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray
from cell.seams._index import cloud_box, dense_index
from cell.seams.ours._bodies import face_planes
from cell.seams.ours.options import OursOptions
from cell.types import Box, Joint, Part, SeamScene

BoolArray = npt.NDArray[np.bool_]
IntArray = npt.NDArray[np.intp]
_SPHERES_KEY = "cell.seams.ours.part_spheres"
_SUPPORT_KEY = "cell.seams.ours.support_planes"


@dataclass(frozen=True)
class Points:
    """The points looked at for one seam: coordinates xyz (3, n) [m], camera index (n,), usable mask (n,)."""

    xyz: FloatArray
    cam: IntArray
    ok: BoolArray  # above the table and away from every other part
    pitch: float  # point pitch of these points on a well-seen surface [m] (the sample's, thinned)
    share: float  # the share of the dense cloud's points these are
    n_cams: int  # camera indices run 0 .. n_cams - 1
    eyes: FloatArray | None = None  # (n_cams, 3) each camera's optical centre [m] (NaN: not known); None: none known
    _along: dict[bytes, FloatArray] = field(default_factory=dict, compare=False, repr=False)  # memo of along()

    def least(self, dense_points: int) -> int:
        """How many of these points stand for ``dense_points`` of the dense cloud (at least 3)."""
        return max(3, math.ceil(dense_points * self.share))

    def along(self, n: FloatArray) -> FloatArray:
        """P @ n (n,) [m], computed once per direction (most planes keep the map's normal)."""
        key = np.asarray(n, np.float64).tobytes()
        out = self._along.get(key)
        if out is None:
            out = self._along[key] = n @ self.xyz
        return out

    def facing(self, n: FloatArray, d: float) -> BoolArray:
        """(n,) which points may lie on a face in the plane n . p = d (outward unit normal ``n`` (3,), [m]): those
        whose camera lies in front of it (a camera sees a face only from its front: the inside of a hollow tube's
        wall, seen down its bore, faces the other way); every point whose camera's centre is not known."""
        if self.eyes is None:
            return np.ones(len(self.cam), bool)
        h = self.eyes @ np.asarray(n, float) - d  # (n_cams,) each camera's height over the plane
        return np.asarray(~(h <= 0.0))[self.cam]  # NaN (unknown) passes

    @property
    def P(self) -> FloatArray:
        """The points (n, 3) [m]."""
        return self.xyz.T


def gather(
    scene: SeamScene,
    a: FloatArray,
    b: FloatArray,
    radius: float,
    extend: float,
    joint: Joint,
    rng: np.random.Generator,
    o: OursOptions,
    share: float | None = None,
) -> Points:
    """The dense cloud's points in the tube of ``radius`` around the segment a-b (3,) extended by
    ``extend`` [m], and which of them may support a plane (above the table, away from other parts); from
    the sample of ``share`` of the dense cloud (None: ``o.sample_share``); more than ``o.max_points`` are
    subsampled with ``rng``."""
    index = dense_index(scene)
    share = o.sample_share if share is None else share
    xyz, cam = index.tube(a, b, radius, extend, share)
    kept = 1.0
    if len(cam) > o.max_points:
        kept = o.max_points / len(cam)
        pick = np.sort(rng.choice(len(cam), o.max_points, replace=False))
        xyz, cam = xyz[:, pick], cam[pick]
    cam = np.where(cam < 0, int(cam.max(initial=0)) + 1, cam)  # mixed / unknown captures: their own group
    ok = xyz[2] >= scene.table_z + o.corner_band_m
    reach = radius + extend + 0.5 * float(np.linalg.norm(b - a)) + o.map_tolerance_m
    centres, radii = _part_spheres(scene)
    near = np.linalg.norm(centres - 0.5 * (a + b), axis=1) <= reach + radii
    bodies = _bodies(scene)
    for k in np.flatnonzero(near):
        part = bodies[k]
        if part.name in (joint.abutting, joint.receiving):
            continue
        if not part.is_box:
            # Only points within the body's bounds and behind every supporting face plane (both grown by the margin)
            # can be near the body: the exact (costly) test on those alone, of the points still usable.
            N, D, lo, hi = _support_planes(scene, int(k))
            m = o.map_tolerance_m
            cand = np.flatnonzero(ok & _in_bounds(xyz, lo - m, hi + m))
            cand = cand[np.all(N @ xyz[:, cand] <= (D + m)[:, None], axis=0)]
            if len(cand):
                ok[cand] &= ~part.contains(xyz[:, cand].T, margin=m)
            continue
        R, c = part.box.X_AB[:3, :3], part.box.center
        q = R.T @ xyz - (R.T @ c)[:, None]  # in the part's frame
        h = 0.5 * part.box.size + o.map_tolerance_m
        ok &= (np.abs(q[0]) > h[0]) | (np.abs(q[1]) > h[1]) | (np.abs(q[2]) > h[2])
    n_cams = int(cam.max(initial=0)) + 1
    return Points(xyz, cam, ok, index.pitch(share * kept), share * kept, n_cams, _eyes(scene, n_cams))


def crop_box(scene: SeamScene, o: OursOptions) -> Box:
    """Where the cloud was cropped: the workspace (in R) when the options give it, else the cloud's bounds."""
    ws = o.workspace_R
    return ws if ws is not None else cloud_box(scene)


def _bodies(scene: SeamScene) -> tuple[Part, ...]:
    """The map's parts, then its fixtures (a clamp near a seam is no face of it either), as the caches index them."""
    return (*scene.weldmap.parts, *scene.weldmap.fixtures)


def _part_spheres(scene: SeamScene) -> tuple[FloatArray, FloatArray]:
    """Centres (P, 3) and radii (P,) of the spheres around the map's parts and fixtures [m], cached per scene."""
    out = scene.cache.get(_SPHERES_KEY)
    if out is None:
        parts = _bodies(scene)
        centres = np.array([p.center for p in parts]).reshape(-1, 3)
        radii = np.array([p.radius for p in parts])
        out = scene.cache[_SPHERES_KEY] = (centres, radii)
    return out


def _support_planes(scene: SeamScene, k: int) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Normals (f, 3) and offsets (f,) [m] of part ``k``'s faces that have the whole body behind them (the faces on
    its convex hull: a plate's top, bottom and outer walls, not its hole's), and the body's bounds along the axes
    of R (lowest and highest corner (3,) [m]), cached per scene."""
    out = scene.cache.get(_SUPPORT_KEY)
    if out is None:
        out = []
        for part in _bodies(scene):
            V = part.vertices()
            N, D = face_planes(part)
            kept = (V @ N.T).max(axis=0) <= D + 1e-9
            out.append((N[kept].reshape(-1, 3), D[kept], V.min(axis=0), V.max(axis=0)))
        scene.cache[_SUPPORT_KEY] = out
    N, D, lo, hi = out[k]
    return N, D, lo, hi


def _in_bounds(xyz: FloatArray, lo: FloatArray, hi: FloatArray) -> BoolArray:
    """(n,) which points xyz (3, n) lie within the axis-aligned bounds lo, hi (3,) [m]."""
    inside = (xyz[0] >= lo[0]) & (xyz[0] <= hi[0])
    for k in (1, 2):
        inside &= (xyz[k] >= lo[k]) & (xyz[k] <= hi[k])
    return inside


def _eyes(scene: SeamScene, n_cams: int) -> FloatArray | None:
    """(n_cams, 3) the optical centre [m] of each camera index of the dense cloud (NaN where not known: a mixed or
    unknown capture), or None when the scene knows no camera's centre."""
    if not scene.eyes_R:
        return None
    eyes = np.full((max(n_cams, len(scene.dense.cameras)), 3), np.nan)
    for k, name in enumerate(scene.dense.cameras):
        if name in scene.eyes_R:
            eyes[k] = np.asarray(scene.eyes_R[name], float)
    return eyes
