"""Aligning the welding map to the point cloud (paper section 3.5): the map's visible faces sampled, a staged
point-to-plane ICP of the cloud onto them from the nominal placement, its inverse the map's correction; a fit that
tilts the part off the table or fits too little is refused."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from scipy.spatial import cKDTree

from cell.errors import AlignmentError, AlignmentFailure
from cell.geometry import FloatArray, invert, matrix_to_rpy, readonly, transform_points
from cell.perception import _open3d
from cell.perception.preprocess import downsample
from cell.scenario import PerceptionSpec
from cell.types import BOX_FACES, Box, Cloud, Part, WeldMap

MAX_TILT_RAD = math.radians(2.0)  # largest roll or pitch correction accepted for a part lying on the table
STAGES = (1.0, 0.25, 0.1)  # max correspondence per ICP stage, as fractions of spec.align_max_correspondence_m
# Fitness is judged within the middle stage's distance (5 mm by default): depth noise of 3-6 mm (D415 at
# 1.5-2 m, docs/reference.md section 2) leaves only about half of a well-aligned cloud within the finest 2 mm.
_FITNESS_STAGE = 1
_SPACING_PER_FINEST = 1.5  # map sample spacing, in units of the finest stage's max correspondence
# The stages before the last pair with map samples twice as far apart (6 mm by default): a cloud point's nearest
# sample on its face then lies at most 4.2 mm aside, inside the middle stage's 5 mm; the last stage, which sets
# the fit, keeps the fine samples. Same fits (fence1, fence2, extrinsics-off: within 4 um) for half the coarse
# stages' cost. Three times as far apart (9 mm, beyond the middle stage's reach) put fence2's fit 5 mm off.
_COARSE_SPACING = 2.0
_DOWN_COS = 0.5  # faces whose outward normal is within 60 deg of -z (R) point down into the table
_MAX_SOURCE = 30_000  # larger clouds are thinned to about this many points (finest-distance grid, then stride)
# Source points of each stage but the last, an even stride of the thinned cloud: a coarse stage only brings the
# fit into the next stage's reach. The last stage runs on the whole thinned cloud, and as it converges to the
# same fit from either start, the result is the same as with every point in every stage (fence1: to the um).
_COARSE_SOURCE = (8_000, 15_000)


@dataclass(frozen=True)
class Alignment:
    """The map-to-cloud fit.

    X_RR_corr : (4, 4) correction in R: aligned map = ``weldmap_R.transformed(X_RR_corr, "R")``.
    fitness : fraction of cloud points within the middle stage's max correspondence (5 mm by default) of the
        map's surfaces (distance to the tangent plane of the nearest surface sample, at most one sample
        spacing further away).
    rmse_m : RMS of those inliers' distances to the map's surfaces [m].
    """

    X_RR_corr: FloatArray
    fitness: float
    rmse_m: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "X_RR_corr", readonly(self.X_RR_corr))


def sample_box_faces(box: Box, spacing_m: float) -> tuple[FloatArray, FloatArray]:
    """Grid samples (at most ``spacing_m`` apart, edges included) of the six faces of ``box``.

    Returns points (n, 3) and outward unit normals (n, 3) in the frame A the box is given in.
    """
    points, normals = [], []
    for face in BOX_FACES:
        axis = "xyz".index(face[1])
        sign = 1.0 if face[0] == "+" else -1.0
        u_ax, v_ax = [a for a in range(3) if a != axis]
        nu = max(2, math.ceil(box.size[u_ax] / spacing_m) + 1)
        nv = max(2, math.ceil(box.size[v_ax] / spacing_m) + 1)
        uu, vv = np.meshgrid(
            np.linspace(-box.size[u_ax] / 2, box.size[u_ax] / 2, nu),
            np.linspace(-box.size[v_ax] / 2, box.size[v_ax] / 2, nv),
            indexing="ij",
        )
        p_B = np.zeros((nu * nv, 3))
        p_B[:, axis] = sign * box.size[axis] / 2
        p_B[:, u_ax] = uu.reshape(-1)
        p_B[:, v_ax] = vv.reshape(-1)
        n, _ = box.face_plane(face)
        points.append(transform_points(box.X_AB, p_B))
        normals.append(np.broadcast_to(n, (len(p_B), 3)))
    return np.concatenate(points), np.concatenate(normals)


def _in_polygon(uv: FloatArray, poly: FloatArray) -> npt.NDArray[np.bool_]:
    """Which 2D points (n, 2) lie inside the simple polygon (m, 2) (even-odd crossings)."""
    a, b = poly, np.roll(poly, -1, axis=0)
    x, y = uv[:, None, 0], uv[:, None, 1]
    straddle = (a[None, :, 1] > y) != (b[None, :, 1] > y)
    with np.errstate(divide="ignore", invalid="ignore"):
        x_cross = a[None, :, 0] + (y - a[None, :, 1]) * (b[None, :, 0] - a[None, :, 0]) / (
            b[None, :, 1] - a[None, :, 1]
        )
    return np.asarray(np.count_nonzero(straddle & (x < x_cross), axis=1) % 2 == 1)


def sample_part_faces(part: Part, spacing_m: float) -> tuple[FloatArray, FloatArray]:
    """Samples (at most ``spacing_m`` apart, edges included) of every face of any body; a box's as
    :func:`sample_box_faces`. Returns points (n, 3) and outward unit normals (n, 3) in the part's frame."""
    if part.is_box:
        return sample_box_faces(part.box, spacing_m)
    points, normals = [], []
    for face in part.face_names():
        poly = part.face_polygon(face)
        n, _ = part.face_plane(face)
        u = poly[1] - poly[0]
        u = u - (u @ n) * n
        u /= np.linalg.norm(u)
        v = np.cross(n, u)
        uv = (poly - poly[0]) @ np.stack([u, v], axis=1)
        lo, hi = uv.min(axis=0), uv.max(axis=0)
        nu, nv = (max(2, math.ceil(float(e) / spacing_m) + 1) for e in hi - lo)
        gu, gv = np.meshgrid(np.linspace(lo[0], hi[0], nu), np.linspace(lo[1], hi[1], nv), indexing="ij")
        grid = np.stack([gu.reshape(-1), gv.reshape(-1)], axis=1)
        inner = grid[_in_polygon(grid, uv)]
        rim = []  # the edges, at the same spacing
        for a, b in zip(uv, np.roll(uv, -1, axis=0), strict=True):
            k = max(1, math.ceil(float(np.linalg.norm(b - a)) / spacing_m))
            rim.append(a + np.linspace(0.0, 1.0, k, endpoint=False)[:, None] * (b - a))
        q = np.concatenate([inner, *rim])
        points.append(poly[0] + q[:, :1] * u + q[:, 1:] * v)
        normals.append(np.broadcast_to(n, (len(q), 3)))
    return np.concatenate(points), np.concatenate(normals)


def sample_map(weldmap: WeldMap, spacing_m: float, contact_margin_m: float) -> tuple[FloatArray, FloatArray]:
    """Visible-surface samples of the map's parts: points (n, 3), outward unit normals (n, 3), map frame.

    Leaves out faces pointing down (within 60 deg of -z) and samples within ``contact_margin_m`` of another
    part (faces in contact across the assembly gap).
    """
    points, normals = [], []
    for i, part in enumerate(weldmap.parts):
        p, n = sample_part_faces(part, spacing_m)
        keep = n[:, 2] > -_DOWN_COS
        for j, other in enumerate(weldmap.parts):
            # Parts whose bounding spheres lie apart cannot touch: only the others are asked about each sample.
            reach = part.radius + other.radius + contact_margin_m
            if j != i and float(np.linalg.norm(part.center - other.center)) <= reach:
                keep &= ~other.contains(p, contact_margin_m)
        points.append(p[keep])
        normals.append(n[keep])
    if not points:
        return np.zeros((0, 3)), np.zeros((0, 3))
    return np.concatenate(points), np.concatenate(normals)


def surface_fit(
    points: FloatArray, samples: FloatArray, normals: FloatArray, threshold_m: float, spacing_m: float
) -> tuple[float, float]:
    """(fitness, rmse [m]) of points (n, 3) against a surface given by samples (m, 3) with normals (m, 3).

    A point is an inlier when its nearest sample is within ``spacing_m + threshold_m`` and its distance to
    that sample's tangent plane is at most ``threshold_m``; fitness is the inlier fraction, rmse their RMS
    distance.
    """
    if len(points) == 0:
        return 0.0, 0.0
    # Every core answers (the same nearest samples). The tree stays balanced: samples on a box edge are there
    # twice (once per face, with its normal), and which of the two an unbalanced tree returns differs.
    dist, idx = cKDTree(samples).query(points, distance_upper_bound=spacing_m + threshold_m, workers=-1)
    near = np.isfinite(dist)
    d = np.abs(np.einsum("ij,ij->i", points[near] - samples[idx[near]], normals[idx[near]]))
    inlier = d <= threshold_m
    if not inlier.any():
        return 0.0, 0.0
    return float(inlier.sum() / len(points)), float(np.sqrt(np.mean(d[inlier] ** 2)))


def align_map(
    weldmap_R: WeldMap, cloud: Cloud, spec: PerceptionSpec, proceed: Callable[[], None] | None = None
) -> Alignment:
    """Fit the nominal map (already in R) to the cloud (in R); see the module docstring.

    proceed : called before each ICP stage; it may raise to stop a fit nobody will read (a speculation,
    :func:`cell.perception.perceive.perceive_then`).

    Pass the dense filtered cloud (``Perceived.dense``): 1 cm voxel centroids sit inside the parts at their
    edges and bias the fit by millimetres. Clouds over 30 000 points are first put on a grid of the finest
    correspondence distance (2 mm by default), then thinned to about 30 000 points; the coarse stages use an even
    stride of those (8 000 and 15 000 points) against map samples twice as far apart, the finest all of them.

    Raises :class:`AlignmentError` when the fit's fitness stays below ``spec.align_min_fitness`` or it tilts
    the map by more than 2 degrees.
    """
    if weldmap_R.frame != "R" or cloud.frame != "R":
        raise ValueError(f"align_map: map and cloud must be in R, not {weldmap_R.frame!r}, {cloud.frame!r}")
    if not weldmap_R.parts:
        raise AlignmentError(
            f"map {weldmap_R.source!r} has no parts to align to the cloud", code=AlignmentFailure.NO_PARTS
        )
    thresholds = [spec.align_max_correspondence_m * f for f in STAGES]
    finest = thresholds[-1]
    if len(cloud) > _MAX_SOURCE:  # thin a dense cloud: a grid of the finest distance, then every k-th point
        cloud = downsample(cloud, finest)
        cloud = cloud.select(np.arange(0, len(cloud), math.ceil(len(cloud) / _MAX_SOURCE)))
    if len(cloud) < 3:
        raise AlignmentError(
            f"map alignment needs a cloud of at least 3 points, got {len(cloud)}",
            code=AlignmentFailure.TOO_FEW_POINTS,
            value=len(cloud),
            needed=3,
        )
    target, target_normals = sample_map(weldmap_R, _SPACING_PER_FINEST * finest, finest)
    coarse = sample_map(weldmap_R, _COARSE_SPACING * _SPACING_PER_FINEST * finest, finest)
    X_MC = np.eye(4)  # moves cloud points onto the map (p_map = X_MC p_cloud)
    points = np.asarray(cloud.points)
    for stage, threshold in enumerate(thresholds):
        last = stage == len(thresholds) - 1
        limit = _COARSE_SOURCE[stage] if stage < min(len(_COARSE_SOURCE), len(thresholds) - 1) else len(points)
        source = points[:: max(1, math.ceil(len(points) / limit))]
        samples, normals = (target, target_normals) if last else coarse
        if proceed is not None:
            proceed()
        X_MC = _open3d.icp(source, samples, threshold, spec.align_iterations, X_MC, normals).X_TS
    band = thresholds[_FITNESS_STAGE]
    fitness, rmse = surface_fit(
        transform_points(X_MC, cloud.points), target, target_normals, band, _SPACING_PER_FINEST * finest
    )
    if fitness < spec.align_min_fitness:
        raise AlignmentError(
            f"map-to-cloud ICP reached fitness {fitness:.3f} within {band * 1000:.1f} mm, "
            f"needs at least {spec.align_min_fitness:.3f} (is the part on the table, inside the workspace?)",
            code=AlignmentFailure.LOW_FITNESS,
            value=fitness,
            needed=spec.align_min_fitness,
        )
    X_RR_corr = invert(X_MC)
    roll, pitch, _ = matrix_to_rpy(X_RR_corr[:3, :3])
    if max(abs(roll), abs(pitch)) > MAX_TILT_RAD:
        raise AlignmentError(
            f"map-to-cloud ICP tilts the part by roll {math.degrees(roll):.2f} / pitch "
            f"{math.degrees(pitch):.2f} deg; at most {math.degrees(MAX_TILT_RAD):.1f} deg is accepted "
            "for a part lying on the table",
            code=AlignmentFailure.TILTED,
            value=max(abs(roll), abs(pitch)),
            needed=MAX_TILT_RAD,
        )
    return Alignment(X_RR_corr, fitness, rmse)
