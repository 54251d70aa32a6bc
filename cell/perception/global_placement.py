"""Where the welding map lies in an unorganised cloud when no usable placement is given: candidate poses on the table
(a height-image search over turns and shifts, then FPFH + RANSAC if those fit poorly), each to be refined by the
staged ICP and the best kept by its fitness (docs/locate.md, "From the cloud to the seams")."""

from __future__ import annotations

import math

import numpy as np
import scipy.fft as sfft
from scipy.spatial import cKDTree

from cell.geometry import FloatArray, make_pose, rpy_to_matrix, transform_points
from cell.perception import _open3d
from cell.perception.align import sample_map, sample_part_faces
from cell.perception.preprocess import downsample
from cell.perception.unorganised import orient_normals
from cell.types import Cloud, WeldMap

YAW_STEP_DEG = 5.0  # turns tried by the height-image search
CELL_M, CELL_MAX_M = 0.005, 0.02  # its cells: the map's footprint diagonal over CELLS_ACROSS, within these
CELLS_ACROSS = 100
TOP_TURNS = 4  # turns whose best shift is proposed, ...
DISTINCT_DEG, DISTINCT_M = 20.0, 0.03  # ... each this far from a better one in turn or in shift


def flatten_to_yaw(X: FloatArray, pivot: FloatArray | None = None) -> FloatArray:
    """(4, 4) the rigid motion X with its rotation reduced to its turn about z (roll and pitch dropped), moving
    ``pivot`` (3,) where X moves it (None: the frame's origin)."""
    yaw = math.atan2(float(X[1, 0]), float(X[0, 0]))
    out = make_pose(rpy_to_matrix((0.0, 0.0, yaw)))
    c = np.zeros(3) if pivot is None else np.asarray(pivot, dtype=np.float64)
    out[:3, 3] = X[:3, :3] @ c + X[:3, 3] - out[:3, :3] @ c
    return out


def on_table(X_LM: FloatArray, weldmap: WeldMap, table_z: float) -> FloatArray:
    """(4, 4) the placement X_LM (frame L: levelled, the table at height ``table_z`` [m]) of ``weldmap`` flattened
    to a turn about z, its lowest part corner on the table: a part rests on the table."""
    X = flatten_to_yaw(X_LM)
    low = min(float(transform_points(X, p.vertices())[:, 2].min()) for p in weldmap.parts)
    X[2, 3] += table_z - low
    return X


def _map_height(weldmap: WeldMap, table_z: float) -> float:
    """How high the map's parts stand on the table [m] (as drawn, flat on it)."""
    X = on_table(np.eye(4), weldmap, table_z)
    return max(float(transform_points(X, p.vertices())[:, 2].max()) for p in weldmap.parts) - table_z


def part_points(points_L: FloatArray, weldmap: WeldMap, table_z: float, margin_m: float = 0.01) -> FloatArray:
    """The points (n, 3) of ``points_L`` no higher above the table than the map's parts (+ ``margin_m``): anything
    higher is something else (an arm, a lamp)."""
    P = np.asarray(points_L)
    return P[P[:, 2] <= table_z + _map_height(weldmap, table_z) + margin_m]


def height_candidates(points_L: FloatArray, weldmap: WeldMap, table_z: float) -> list[FloatArray]:
    """Candidate X_LM (4, 4) from the height-image correlation (module docstring), best first."""
    P = part_points(points_L, weldmap, table_z)
    if len(P) == 0:
        return []
    top = _map_height(weldmap, table_z)
    X0 = on_table(np.eye(4), weldmap, table_z)
    v = np.vstack([transform_points(X0, p.vertices()) for p in weldmap.parts])
    cell = min(CELL_MAX_M, max(CELL_M, float(np.linalg.norm(np.ptp(v[:, :2], axis=0))) / CELLS_ACROSS))
    # The map's height image about its origin: its parts' tops on a grid of half cells over their footprints.
    samples = []
    for part in weldmap.parts:
        h = float(transform_points(X0, part.vertices())[:, 2].max()) - table_z
        if not part.is_box:  # any body: samples of its upward faces, half a cell apart
            q, n = sample_part_faces(part.transformed(X0), cell / 2)
            q = q[n[:, 2] > 0.5]
            samples.append(np.column_stack([q[:, :2], np.full(len(q), h)]))
            continue
        box = part.box
        u = np.arange(-box.size[0] / 2, box.size[0] / 2 + 1e-9, cell / 2)
        w = np.arange(-box.size[1] / 2, box.size[1] / 2 + 1e-9, cell / 2)
        uu, ww = np.meshgrid(u, w, indexing="ij")
        q_B = np.column_stack([uu.ravel(), ww.ravel(), np.full(uu.size, box.size[2] / 2)])
        q = transform_points(X0 @ box.X_AB, q_B)
        samples.append(np.column_stack([q[:, :2], np.full(len(q), h)]))
    S = np.vstack(samples)
    R = math.ceil(float(np.linalg.norm(S[:, :2], axis=1).max()) / cell) + 1
    # The cloud's height image, padded by the map's reach R: the map's origin may sit on any cell of the points.
    lo = P[:, :2].min(axis=0) - R * cell
    shape = tuple(int(v) for v in np.ceil((P[:, :2].max(axis=0) + R * cell - lo) / cell) + 1)
    C = np.zeros(shape)
    ij = np.floor((P[:, :2] - lo) / cell).astype(int)
    np.maximum.at(C, (ij[:, 0], ij[:, 1]), np.clip(P[:, 2] - table_z, 0.0, top))
    size = (shape[0] + 2 * R, shape[1] + 2 * R)
    F_C = sfft.rfft2(C, s=size)
    found = []
    for yaw in np.radians(np.arange(0.0, 360.0, YAW_STEP_DEG)):
        c, s = math.cos(yaw), math.sin(yaw)
        xy = S[:, :2] @ np.array([[c, s], [-s, c]])
        K = np.zeros((2 * R + 1, 2 * R + 1))
        kij = np.floor(xy / cell + 0.5).astype(int) + R
        np.maximum.at(K, (kij[:, 0], kij[:, 1]), S[:, 2])
        # score[u] = sum_a C[u + a] K[a]: the map's origin (K's centre R) on C's cell u + R.
        score = sfft.irfft2(F_C * np.conj(sfft.rfft2(K, s=size)), s=size)[: shape[0] - 2 * R, : shape[1] - 2 * R]
        best = np.unravel_index(int(np.argmax(score)), score.shape)
        found.append((float(score[best]), yaw, lo + (np.array(best, dtype=np.float64) + R + 0.5) * cell))
    found.sort(key=lambda f: -f[0])
    kept: list[tuple[float, FloatArray]] = []
    for _, yaw, xy in found:  # the best turns that differ from a better one (by DISTINCT_DEG or DISTINCT_M)
        turn = [abs((yaw - y + math.pi) % (2 * math.pi) - math.pi) for y, _ in kept]
        shift = [float(np.linalg.norm(xy - q)) for _, q in kept]
        if all(t > math.radians(DISTINCT_DEG) or d > DISTINCT_M for t, d in zip(turn, shift, strict=True)):
            kept.append((yaw, xy))
        if len(kept) == TOP_TURNS:
            break
    out = []
    for yaw, xy in kept:
        X = make_pose(rpy_to_matrix((0.0, 0.0, yaw)), (xy[0], xy[1], 0.0)) @ X0
        out.append(on_table(X, weldmap, table_z))
    return out


def fpfh_candidates(
    points_L: FloatArray,
    weldmap: WeldMap,
    table_z: float,
    viewpoint_L: FloatArray | None,
    rng: np.random.Generator,
    *,
    voxel_m: float = 0.005,
    tries: int = 4,
) -> list[FloatArray]:
    """Candidate X_LM (4, 4) from FPFH + RANSAC (module docstring): the map put on the table at the points'
    median, ``tries`` matches on a ``voxel_m`` grid (normals by
    :func:`~cell.perception.unorganised.orient_normals`), each flattened, refined by ICP (4, 2 and 0.6 voxels) and
    put back on the table; ordered by the share of the map's samples within a voxel of a point."""
    cloud = downsample(Cloud(part_points(points_L, weldmap, table_z), "L"), voxel_m).points
    if len(cloud) < 10:
        return []
    normals = orient_normals(_open3d.estimate_normals(cloud, 2.5 * voxel_m, 30), cloud, viewpoint_L)
    centre = np.median(cloud, axis=0)
    X0 = on_table(make_pose(p=(centre[0], centre[1], 0.0)), weldmap, table_z)
    samples, sample_normals = sample_map(weldmap.transformed(X0, "L"), voxel_m, voxel_m)
    tree = cKDTree(cloud)
    pivot = samples.mean(axis=0)  # the map's samples turn about their centre, not about L's far origin
    scored = []
    for _ in range(tries):
        seed = int(rng.integers(0, 2**31 - 1))
        X = flatten_to_yaw(_open3d.fpfh_ransac(samples, sample_normals, cloud, normals, voxel_m, seed), pivot)
        for k in (4.0, 2.0, 0.6):
            X = flatten_to_yaw(_open3d.icp(samples, cloud, k * voxel_m, 30, X, None).X_TS, pivot)
        fit = float(np.mean(np.isfinite(tree.query(transform_points(X, samples), distance_upper_bound=voxel_m)[0])))
        scored.append((fit, on_table(X @ X0, weldmap, table_z)))
    scored.sort(key=lambda f: -f[0])
    return [X for _, X in scored]
