"""The paper's prioritised merge (section 3.3), generalised to any number of cameras and surface directions: each
cube of space and surface direction takes its points from the camera with the lowest predicted noise there
(docs/perception.md, "The splice's order, its ICP and the prioritised merge")."""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray

_MIN_PLANE_POINTS = 6  # points a plane fit needs to give a normal worth snapping to an axis
MAX_INCIDENCE_DEG = 80.0  # stereo matching drops pixels seen more obliquely (the sensor model's grazing dropout)
_COS_MAX_INCIDENCE = math.cos(math.radians(MAX_INCIDENCE_DEG))
_DIRECTION_SAMPLE = 40_000  # normals the dominant directions are found from (an even stride)


def predicted_noise(
    depth_m: npt.ArrayLike, cos_incidence: npt.ArrayLike, fx_px: npt.ArrayLike, cos_off_axis: npt.ArrayLike = 1.0
) -> FloatArray:
    """Relative standard error (lower is better) of a surface's position per unit area, seen by an active-stereo
    camera of focal length ``fx_px`` [px] at optical depth ``depth_m`` [m], at an incidence of cosine
    ``cos_incidence`` (1: head on), along a ray at an angle of cosine ``cos_off_axis`` off the optical axis.

    z^3 sqrt(cos(theta) / cos(alpha)) / f^2 (see the module docstring); incidence capped at
    :data:`MAX_INCIDENCE_DEG`.
    """
    z = np.asarray(depth_m, dtype=np.float64)
    cos_t = np.clip(np.asarray(cos_incidence, dtype=np.float64), _COS_MAX_INCIDENCE, 1.0)
    cos_a = np.clip(np.asarray(cos_off_axis, dtype=np.float64), 1e-3, 1.0)
    f = np.asarray(fx_px, dtype=np.float64)
    return np.asarray(z**3 * np.sqrt(cos_t / cos_a) / (f * f))


def _group(keys: npt.NDArray[np.int64]) -> tuple[npt.NDArray[np.intp], int]:
    _, inverse = np.unique(keys, return_inverse=True)
    inverse = inverse.reshape(-1)
    return inverse, int(inverse.max()) + 1 if len(inverse) else 0


def _cell_keys(points: FloatArray, cell_m: float, camera: npt.NDArray[np.integer] | None) -> npt.NDArray[np.int64]:
    """One int64 per (camera, cell) so that np.unique can group points."""
    ijk = np.floor(points / cell_m).astype(np.int64)
    ijk -= ijk.min(axis=0)
    dims = ijk.max(axis=0) + 1
    key = (ijk[:, 0] * dims[1] + ijk[:, 1]) * dims[2] + ijk[:, 2]
    if camera is not None:
        key = key + np.asarray(camera, dtype=np.int64) * int(np.prod(dims))
    return np.asarray(key)


def _plane_normals(
    points: FloatArray, camera: npt.NDArray[np.integer], cell_m: float
) -> tuple[FloatArray, npt.NDArray[np.intp]]:
    """Per point: the (unoriented) normal of a plane fit to its camera's points in its cell, and how many."""
    inverse, n_groups = _group(_cell_keys(points, cell_m, camera))
    count = np.bincount(inverse, minlength=n_groups)
    # Moments about each point's cell corner: small values, no loss of precision far from the origin.
    q = points - np.floor(points / cell_m) * cell_m
    mean = np.stack([np.bincount(inverse, q[:, i], n_groups) for i in range(3)], axis=1) / count[:, None]
    cov = np.empty((n_groups, 3, 3))
    for i in range(3):
        for j in range(i, 3):
            cov[:, i, j] = np.bincount(inverse, q[:, i] * q[:, j], n_groups) / count - mean[:, i] * mean[:, j]
            cov[:, j, i] = cov[:, i, j]
    _, vecs = np.linalg.eigh(cov)
    return vecs[:, :, 0][inverse], count[inverse]  # eigenvector of the smallest eigenvalue


def surface_normals(
    points: FloatArray,
    camera: npt.NDArray[np.integer],
    p_RC: Mapping[int, FloatArray],
    normal_cell_m: float,
    coarse_cell_m: float,
) -> FloatArray:
    """Unit normals (n, 3) from plane fits of each camera's own points, turned towards that camera.

    points : (n, 3) in R [m]; camera : (n,) index of the capture of each point; p_RC : camera index -> (3,)
    position of that camera in R. The fit is per sub-cell of ``normal_cell_m``; where a camera has too few
    points in a sub-cell, per cell of ``coarse_cell_m``; where it has too few there too, the direction to it.
    """
    n, count = _plane_normals(points, camera, normal_cell_m)
    sparse = count < _MIN_PLANE_POINTS
    if sparse.any():
        n_coarse, count_coarse = _plane_normals(points, camera, coarse_cell_m)
        n[sparse] = n_coarse[sparse]
        sparse &= count_coarse < _MIN_PLANE_POINTS
    cams = np.asarray(camera, dtype=np.intp)
    eyes = np.zeros((int(cams.max()) + 1 if len(cams) else 0, 3))
    for index, p in p_RC.items():
        if 0 <= index < len(eyes):
            eyes[index] = p
    to_camera = eyes[cams] - points
    to_camera /= np.maximum(np.linalg.norm(to_camera, axis=1, keepdims=True), 1e-12)
    n[sparse] = to_camera[sparse]
    flip = np.einsum("ij,ij->i", n, to_camera) < 0.0
    n[flip] *= -1.0
    return np.asarray(n)


def prioritised_merge(
    points: FloatArray,
    camera: npt.NDArray[np.integer],
    X_RC: Mapping[int, FloatArray],
    fx_px: Mapping[int, float],
    cell_m: float,
    normal_cell_m: float,
    normals: FloatArray | None = None,
) -> npt.NDArray[np.bool_]:
    """(n,) True for the points to keep: in each (cell, surface direction) only the best camera's points.

    points : (n, 3) in R [m], from several captures; camera : (n,) capture index of each point (>= 0);
    X_RC : capture index -> (4, 4) pose of its optical frame in R; fx_px : capture index -> focal length [px].
    normals : (n, 3) the points' :func:`surface_normals` when already computed (else computed here).
    """
    n_points = len(points)
    if n_points == 0:
        return np.zeros(0, dtype=bool)
    cams = np.asarray(camera, dtype=np.int64)
    missing = sorted(set(np.unique(cams).tolist()) - set(X_RC))
    if missing:
        raise ValueError(f"prioritised_merge: no camera pose for capture index(es) {missing}")
    if normals is None:
        normals = surface_normals(points, cams, {i: X[:3, 3] for i, X in X_RC.items()}, normal_cell_m, cell_m)
    axis = np.argmax(np.abs(normals), axis=1)
    sign = normals[np.arange(n_points), axis] < 0.0
    direction = axis * 2 + sign  # one of six classes: +x, -x, +y, -y, +z, -z
    unit_keys = _cell_keys(points, cell_m, None) * 6 + direction
    unit, n_units = _group(unit_keys)
    # Groups of (unit, camera): each scored by the camera's predicted noise at the group's centroid.
    n_cams = int(cams.max()) + 1
    group, n_groups = _group(unit.astype(np.int64) * n_cams + cams)
    count = np.bincount(group, minlength=n_groups).astype(np.float64)
    sums = np.stack([np.bincount(group, points[:, i], n_groups) for i in range(3)], axis=1)
    centroid = sums / count[:, None]
    sums = np.stack([np.bincount(group, normals[:, i], n_groups) for i in range(3)], axis=1)
    normal = sums / np.maximum(np.linalg.norm(sums, axis=1, keepdims=True), 1e-12)
    first = np.zeros(n_groups, dtype=np.intp)
    first[group] = np.arange(n_points)  # any member: every member shares the group's unit and camera
    group_unit = unit[first]
    group_cam = cams[first]
    eyes = np.zeros((n_cams, 3))
    axes_z = np.zeros((n_cams, 3))
    fxs = np.ones(n_cams)
    for c in np.unique(cams).tolist():
        eyes[c], axes_z[c], fxs[c] = X_RC[c][:3, 3], X_RC[c][:3, 2], float(fx_px[c])
    eye, axis_z = eyes[group_cam], axes_z[group_cam]
    ray = eye - centroid
    dist = np.maximum(np.linalg.norm(ray, axis=1), 1e-12)
    depth = np.einsum("ij,ij->i", centroid - eye, axis_z)
    cos_inc = np.einsum("ij,ij->i", normal, ray) / dist
    score = predicted_noise(depth, cos_inc, fxs[group_cam], depth / dist)
    # Best group per unit: sort by (unit, score) and take the first of each unit.
    order = np.lexsort((score, group_unit))
    best = np.zeros(n_units, dtype=np.intp)
    is_first = np.ones(len(order), dtype=bool)
    is_first[1:] = group_unit[order][1:] != group_unit[order][:-1]
    best[group_unit[order][is_first]] = order[is_first]
    return np.asarray(best[unit] == group)
