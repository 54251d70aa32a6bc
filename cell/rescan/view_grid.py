"""Where the eye-in-hand camera may look at a seam from, without IK: the view grid and thresholds, what is looked at,
and the candidates that pass the geometric tests (docs/planning.md section 7). Frames: R the robot base, C the
camera's optical frame; lengths [m]."""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from cell.config.motion import ViewOptions
from cell.geometry import FloatArray, axis_angle_to_matrix, cross3, invert, make_pose, transform_points
from cell.motion.robot import RobotModel
from cell.types import Box, CameraIntrinsics, Part
from cell.types.plan import SeamTask


@dataclass(frozen=True)
class ViewTarget(SeamTask):
    """What a close-up looks at: a seam task (ends and weld-face normals in R) that has a fillet to look into."""

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.length < 1e-6:
            raise ValueError(f"seam {self.id}: a view target needs two distinct end points")
        if float(np.linalg.norm(self.n_a + self.n_b)) < 1e-6:
            raise ValueError(f"seam {self.id}: the weld faces are parallel, there is no fillet to look into")

    @property
    def mid(self) -> FloatArray:
        return np.asarray(0.5 * (self.p_start + self.p_end))

    @property
    def direction(self) -> FloatArray:
        d = self.p_end - self.p_start
        return np.asarray(d / np.linalg.norm(d))

    @property
    def bisector(self) -> FloatArray:
        s = self.n_a + self.n_b
        return np.asarray(s / np.linalg.norm(s))

    def samples(self, strip: float, end_margin: float, n: int = 5) -> tuple[FloatArray, FloatArray]:
        """Points that must be seen (m, 3) [m] and the outward normal of the surface each lies on (m, 3).

        The seam line (end margins included, normal the bisector) and, on each face, lines at 1/3, 2/3 and
        3/3 of ``strip`` from the seam (moving on face A away from B is along B's normal, and conversely).
        """
        t = self.direction
        s = np.linspace(-end_margin, float(np.linalg.norm(self.p_end - self.p_start)) + end_margin, n)
        line = self.p_start + np.outer(s, t)
        pts, normals = [line], [np.tile(self.bisector, (n, 1))]
        for n_on, n_other in ((self.n_a, self.n_b), (self.n_b, self.n_a)):
            e = n_other - float(n_other @ n_on) * n_on  # in the face, away from the other face
            e /= np.linalg.norm(e)
            for k in (1, 2, 3):
                pts.append(line + (strip * k / 3.0) * e)
                normals.append(np.tile(n_on, (n, 1)))
        return np.concatenate(pts), np.concatenate(normals)


@dataclass(frozen=True)
class ViewCandidate:
    """A geometrically acceptable camera pose X_RC (4, 4) in R with its grid angles [deg], the worst incidence on
    face A and B [deg] and its score (lower is better)."""

    X_RC: FloatArray
    distance: float
    tilt: float
    slant: float
    roll: float
    incidence: tuple[float, float]
    score: float


def torch_axis_in_camera(model: RobotModel, options: ViewOptions | None = None, n: int = 24) -> FloatArray:
    """Points (n, 3) [m] on the torch's axis (flange origin to TCP) in the camera's optical frame C.

    Both frames ride on the last link, so the result does not depend on the configuration.
    """
    o = options or ViewOptions()
    q = 0.5 * (model.limits.q_min + model.limits.q_max)
    X = model.fk_frames(q, (o.camera_frame, o.tcp_frame, o.flange_frame))
    X_CR = invert(X[o.camera_frame])
    a = transform_points(X_CR, X[o.flange_frame][:3, 3])
    b = transform_points(X_CR, X[o.tcp_frame][:3, 3])
    return np.asarray(a + np.linspace(0.0, 1.0, n)[:, None] * (b - a))


def _camera_pose(target: ViewTarget, u: FloatArray, distance: float, roll: float, offset: float) -> FloatArray:
    """X_RC (4, 4): camera at mid + distance u, the seam's midpoint ``offset`` [rad] above the image centre and
    the seam at angle ``roll`` [rad] to the image x axis (about the line of sight to the midpoint)."""
    z0 = -u
    x = target.direction - float(target.direction @ z0) * z0
    x /= np.linalg.norm(x)
    y0 = cross3(z0, x)
    # Midpoint direction = cos(offset) z - sin(offset) y: above the centre (image y points down).
    z = np.cos(offset) * z0 + np.sin(offset) * y0
    y = np.cos(offset) * y0 - np.sin(offset) * z0
    R = axis_angle_to_matrix(z0, roll) @ np.column_stack([x, y, z])
    return make_pose(R, target.mid + distance * u)


def _face_labels(m: int) -> npt.NDArray[np.int_]:
    """Which surface each of the m points of :meth:`ViewTarget.samples` lies on: 0 the seam line, 1 face A, 2 B."""
    n = m // 7
    return np.repeat(np.array([0, 1, 2]), [n, 3 * n, 3 * n])


def segments_hit_box(p0: FloatArray, p1: FloatArray, part: Part, margin: float) -> npt.NDArray[np.bool_]:
    """(m,) whether each segment p0 (3,) -> p1 (m, 3) crosses the part's box grown by ``margin`` (slab test); a part
    that is not a box: :meth:`~cell.types.Polyhedron.segments_hit`."""
    if not isinstance(part.body, Box):
        return part.body.segments_hit(p0, p1, margin)
    X_BA = invert(part.box.X_AB)
    a = transform_points(X_BA, p0)
    b = transform_points(X_BA, p1)
    half = part.box.size / 2.0 + margin
    d = b - a
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / d
        t0 = (-half - a) * inv
        t1 = (half - a) * inv
    lo = np.where(np.isnan(t0), -np.inf, np.minimum(t0, t1))
    hi = np.where(np.isnan(t1), np.inf, np.maximum(t0, t1))
    # A zero component: inside the slab (always) or outside (never): inv is +-inf, t0/t1 are +-inf or nan.
    flat = d == 0.0
    inside = np.abs(a) <= half
    lo = np.where(flat, np.where(inside, -np.inf, np.inf), lo)
    hi = np.where(flat, np.where(inside, np.inf, -np.inf), hi)
    enter = np.max(lo, axis=1)
    leave = np.min(hi, axis=1)
    return np.asarray((enter <= leave) & (leave >= 0.0) & (enter <= 1.0))


def _in_image(X_RC: FloatArray, pts: FloatArray, K: CameraIntrinsics, torch_C: FloatArray, o: ViewOptions) -> bool:
    """Whether every sample point (m, 3) lies in front of the camera, in the image with its margin and clear of
    the torch. No samples left (all under the table or inside other parts: a seam estimate of a part that is not
    there) is nothing seen."""
    if not len(pts):
        return False
    p_C = transform_points(invert(X_RC), pts)
    z = p_C[:, 2]
    if np.any(z <= 0.05):
        return False
    u = K.fx * p_C[:, 0] / z + K.cx
    v = K.fy * p_C[:, 1] / z + K.cy
    m = o.image_margin_px
    if np.any((u < m) | (u > K.width - 1 - m) | (v < m) | (v > K.height - 1 - m)):
        return False
    ahead = torch_C[torch_C[:, 2] > 0.02]
    if len(ahead):
        tu = K.fx * ahead[:, 0] / ahead[:, 2] + K.cx
        tv = K.fy * ahead[:, 1] / ahead[:, 2] + K.cy
        radius = K.fx * o.torch_radius_m / ahead[:, 2] + o.torch_margin_px
        near = np.hypot(u[:, None] - tu[None, :], v[:, None] - tv[None, :]) < radius[None, :]
        if np.any(near & (ahead[None, :, 2] < z[:, None])):
            return False
    return True


def _incidence(
    X_RC: FloatArray, pts: FloatArray, normals: FloatArray, face: npt.NDArray[np.int_]
) -> tuple[float, float, float]:
    """The worst angle [deg] between a line of sight and its sample's normal: over every sample, on face A's and
    on face B's."""
    sight = X_RC[:3, 3] - pts
    sight /= np.linalg.norm(sight, axis=1, keepdims=True)
    cos = np.einsum("ij,ij->i", sight, normals)
    inc = np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))
    return float(inc.max(initial=0.0)), float(inc[face == 1].max(initial=0.0)), float(inc[face == 2].max(initial=0.0))


def _seen(
    X_RC: FloatArray,
    pts: FloatArray,
    normals: FloatArray,
    face: npt.NDArray[np.int_],
    K: CameraIntrinsics,
    torch_C: FloatArray,
    o: ViewOptions,
) -> tuple[bool, tuple[float, float]]:
    """Whether every sample point is in the image, clear of the torch and seen at a good incidence (the tests
    before the line of sight); and the worst incidence on face A's and B's samples [deg] (90 when not in the
    image)."""
    if not _in_image(X_RC, pts, K, torch_C, o):
        return False, (90.0, 90.0)
    worst, inc_a, inc_b = _incidence(X_RC, pts, normals, face)
    return worst <= o.max_incidence_deg, (inc_a, inc_b)


def _occluded(eye: FloatArray, pts: FloatArray, normals: FloatArray, parts: Sequence[Part], margin: float) -> bool:
    """Whether a part of ``parts`` (its body grown by ``margin`` [m]) stands on the line of sight from the eye (3,)
    to a sample point (m, 3), taken just off its surface (so that its own part does not count). A part whose bounds
    cannot meet the sight lines' bounding box is not tested."""
    ends = pts + 0.002 * normals
    lo = np.minimum(ends.min(axis=0), eye)
    hi = np.maximum(ends.max(axis=0), eye)
    for part in parts:
        if part.is_box:
            box = part.box
            centre = box.center
            reach = np.abs(box.X_AB[:3, :3]) @ (box.size / 2.0 + margin)  # the grown box's axis-aligned half sizes
        else:  # any other body: its vertices' axis-aligned bounds, grown
            v = part.vertices()
            centre, reach = 0.5 * (v.max(axis=0) + v.min(axis=0)), 0.5 * np.ptp(v, axis=0) + margin
        if np.any(centre + reach < lo) or np.any(centre - reach > hi):
            continue
        if np.any(segments_hit_box(eye, ends, part, margin)):
            return True
    return False


def ranked_views(
    target: ViewTarget,
    intrinsics: CameraIntrinsics,
    torch_C: FloatArray,
    parts: Sequence[Part],
    table_z: float,
    options: ViewOptions | None = None,
) -> Iterator[ViewCandidate]:
    """:func:`view_candidates` one at a time, best score first: every grid pose gets the image, torch and
    incidence tests and its score, and the line-of-sight test (the costly one: a slab test per part) is done
    lazily, in the order of the score, on the candidates the caller asks for."""
    o = options or ViewOptions()
    b, t = target.bisector, target.direction
    w = np.cross(t, b)
    w /= np.linalg.norm(w)
    pts, normals, face = _samples(target, table_z, o, parts)
    offset = np.radians(o.image_offset_deg)
    seen: list[ViewCandidate] = []
    for distance in o.distances_m:
        for tilt in o.tilts_deg:
            for slant in o.slants_deg:
                ta, sl = np.radians(tilt), np.radians(slant)
                u = np.cos(sl) * (np.cos(ta) * b + np.sin(ta) * w) + np.sin(sl) * t
                if float((target.mid + distance * u)[2]) < table_z + 0.05:
                    continue
                for roll in o.rolls_deg:
                    X_RC = _camera_pose(target, u, distance, np.radians(roll), offset)
                    ok, inc = _seen(X_RC, pts, normals, face, intrinsics, torch_C, o)
                    if ok:
                        score = max(inc) + o.distance_weight_deg_per_m * abs(distance - o.preferred_distance_m)
                        seen.append(ViewCandidate(X_RC, distance, tilt, slant, roll, inc, score))
    seen.sort(key=lambda c: c.score)  # stable: ties keep the grid order (sorting before the last test keeps it)
    for c in seen:
        if not _occluded(c.X_RC[:3, 3], pts, normals, parts, o.occlusion_margin_m):
            yield c


_COVERED_M = 0.005  # a sample this near another part lies on a face that part covers or shades [m]


def _samples(
    target: ViewTarget, table_z: float, o: ViewOptions, parts: Sequence[Part] = ()
) -> tuple[FloatArray, FloatArray, npt.NDArray[np.int_]]:
    """The target's sample points (m, 3), their normals (m, 3) and surfaces (m,) (:meth:`ViewTarget.samples`),
    those below the table top ``table_z`` [m] dropped, and the face strips' samples within :data:`_COVERED_M` of
    one of ``parts``: a face strip that another part covers (a brace's end 21 mm below a rail leaves the post's
    face a 21 mm strip) is seen where it is free, or no view could ever pass the line-of-sight test. The seam
    line's samples are all kept (a seam running into another part still has no view)."""
    pts, normals = target.samples(o.face_strip_m, o.end_margin_m)
    face = _face_labels(len(pts))
    keep = pts[:, 2] >= table_z + 0.001
    for part in parts:
        near = (face > 0) & (np.linalg.norm(pts - part.center, axis=1) <= part.radius + _COVERED_M)
        if np.any(near & keep):
            keep[near] &= ~part.contains(pts[near], margin=_COVERED_M)
    return pts[keep], normals[keep], face[keep]


def sees(
    X_RC: FloatArray,
    target: ViewTarget,
    intrinsics: CameraIntrinsics,
    torch_C: FloatArray,
    parts: Sequence[Part],
    table_z: float,
    options: ViewOptions | None = None,
) -> tuple[float, float] | None:
    """The worst incidence on face A's and B's samples [deg] when a camera at X_RC (4, 4) in R sees ``target``
    as well as a view candidate must (every test of :func:`view_candidates`: in the image with its margin, clear
    of the torch, incidence, line of sight past ``parts``), else None. A close-up taken for one seam serves
    every other seam it sees this way."""
    o = options or ViewOptions()
    pts, normals, face = _samples(target, table_z, o, parts)
    ok, inc = _seen(X_RC, pts, normals, face, intrinsics, torch_C, o)
    if not ok or _occluded(X_RC[:3, 3], pts, normals, parts, o.occlusion_margin_m):
        return None
    return inc


def view_candidates(
    target: ViewTarget,
    intrinsics: CameraIntrinsics,
    torch_C: FloatArray,
    parts: Sequence[Part],
    table_z: float,
    options: ViewOptions | None = None,
) -> list[ViewCandidate]:
    """The geometrically acceptable camera poses for ``target``, best score first (deterministic order).

    torch_C : (n, 3) points on the torch axis in the camera frame (:func:`torch_axis_in_camera`).
    parts : the map's parts in R that may stand in the line of sight (not the joint's own two: the incidence
    test keeps their faces turned to the camera, and the seam estimate may lie inside their drawn boxes);
    table_z : the table top in R [m] (the camera stays above it; samples below it are dropped).
    All of :func:`ranked_views` (which the view planner reads lazily, as far as it needs).
    """
    return list(ranked_views(target, intrinsics, torch_C, parts, table_z, options))
