"""The only module of the cell that imports open3d: numpy in, numpy out. Open3D's core is loaded on first use, and
its threads are one setting for the process: one for every ICP, every core for the calls whose answer does not
depend on it while no ICP is in flight (docs/perception.md, "One thread for the ICP")."""

from __future__ import annotations

import threading
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray


class _ThreadSetting:
    """open3d's thread setting as the cell uses it (module docstring): ``lock`` guards the setting and ``icps``, the
    ICPs in flight; ``cores`` is open3d's default count (every core), read at the load."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.icps = 0
        self.cores = 1


_THREADS = _ThreadSetting()
_LOADING = threading.Lock()  # the first load, once: a second thread waits for the whole core, never half of it


def _o3d() -> Any:
    """open3d's compiled core (``open3d.pybind``: geometry, pipelines, core, io, utility, t), loaded on first use;
    threads that ask for it at once get it when it is whole (:func:`_load`)."""
    with _LOADING:
        return _load()


@cache
def _load() -> Any:
    """Load open3d's compiled core (called under ``_LOADING``).

    The core is one extension module next to the package's ``__init__`` (which imports the visualization, dash
    and plotly: docs/perception.md); it is loaded from its file without running the package (when open3d is already
    imported, its own is taken). Everything this module uses lives in it.
    """
    import importlib.machinery
    import importlib.util
    import sys

    core = sys.modules.get("open3d.pybind")
    if core is None:
        spec = importlib.util.find_spec("open3d")
        if spec is None or not spec.submodule_search_locations:
            raise ImportError("open3d is not installed (pip install open3d)")
        folder = Path(next(iter(spec.submodule_search_locations)))
        found = [folder / f"pybind{s}" for s in importlib.machinery.EXTENSION_SUFFIXES]
        path = next((p for p in found if p.is_file()), None)
        core_spec = importlib.util.spec_from_file_location("open3d.pybind", path) if path else None
        if core_spec is None or core_spec.loader is None:
            import open3d  # an unusual layout: the whole package, visualization and all

            core = open3d.pybind
        else:
            core = importlib.util.module_from_spec(core_spec)
            sys.modules["open3d.pybind"] = core  # a later ``import open3d`` takes this one, never a second copy
            try:
                core_spec.loader.exec_module(core)
            except BaseException:
                del sys.modules["open3d.pybind"]
                raise
    # open3d prints warnings on stdout; the cell reports through returned values instead.
    core.utility.set_verbosity_level(core.utility.VerbosityLevel.Error)
    _THREADS.cores = core.utility.get_max_threads()
    core.utility.set_max_threads(1)  # see the module docstring
    return core


@contextmanager
def _one_thread() -> Iterator[None]:
    """Held around an ICP: open3d stays on one thread until it ends (other ICPs may run meanwhile)."""
    with _THREADS.lock:
        _THREADS.icps += 1
    try:
        yield
    finally:
        with _THREADS.lock:
            _THREADS.icps -= 1


@contextmanager
def _every_core() -> Iterator[None]:
    """Held around a call whose answer does not depend on the thread count: every core while no ICP is in flight
    (an ICP asked for meanwhile waits until the call ends), else one thread, as the ICP needs."""
    o3d = _o3d()
    with _THREADS.lock:
        if _THREADS.icps == 0:
            o3d.utility.set_max_threads(_THREADS.cores)
            try:
                yield
            finally:
                o3d.utility.set_max_threads(1)
            return
    yield


def _array(a: npt.ArrayLike, dtype: type = np.float64) -> npt.NDArray:
    """C-contiguous and writeable (open3d refuses the read-only arrays of the cell's frozen values)."""
    return np.require(a, dtype=dtype, requirements=["C", "W"])


def _legacy_cloud(points: npt.ArrayLike, normals: npt.ArrayLike | None = None) -> Any:
    o3d = _o3d()
    pc = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(_array(points)))
    if normals is not None:
        pc.normals = o3d.utility.Vector3dVector(_array(normals))
    return pc


@dataclass(frozen=True)
class IcpResult:
    """One ICP run.

    X_TS : (4, 4) transform that moves the source points onto the target (p_T = X_TS p_S).
    fitness : fraction of source points with a target point within the final max correspondence distance.
    rmse_m : RMS residual of those inlier correspondences [m] (point-to-point or point-to-plane as run).
    """

    X_TS: FloatArray
    fitness: float
    rmse_m: float


def _criteria(iterations: int) -> Any:
    """Stop after ``iterations`` or when fitness and RMSE stop changing (relative change 1e-9)."""
    reg = _o3d().pipelines.registration
    return reg.ICPConvergenceCriteria(relative_fitness=1e-9, relative_rmse=1e-9, max_iteration=int(iterations))


def _result(result: Any) -> IcpResult:
    return IcpResult(np.array(result.transformation), float(result.fitness), float(result.inlier_rmse))


def icp(
    source: npt.ArrayLike,
    target: npt.ArrayLike,
    max_correspondence_m: float,
    iterations: int,
    init: FloatArray | None = None,
    target_normals: npt.ArrayLike | None = None,
    tukey_k_m: float | None = None,
) -> IcpResult:
    """Rigid ICP of ``source`` (n, 3) onto ``target`` (m, 3) (``registration_icp``).

    Point-to-point when ``target_normals`` is None, point-to-plane (with those unit normals (m, 3)) otherwise;
    ``tukey_k_m`` [m] (point-to-plane only) weights the residuals with open3d's ``TukeyLoss(k)`` (a residual
    beyond k weighs nothing). ``init`` is the starting X_TS (identity by default). Stops after ``iterations``
    or when fitness and RMSE stop changing (relative change 1e-9).
    """
    reg = _o3d().pipelines.registration
    if target_normals is None:
        if tukey_k_m is not None:
            raise ValueError("icp: a robust kernel (tukey_k_m) needs target normals (point-to-plane)")
        method = reg.TransformationEstimationPointToPoint()
    elif tukey_k_m is None:
        method = reg.TransformationEstimationPointToPlane()
    else:
        method = reg.TransformationEstimationPointToPlane(reg.TukeyLoss(k=float(tukey_k_m)))
    X0 = np.eye(4) if init is None else _array(init)
    src, tgt = _legacy_cloud(source), _legacy_cloud(target, target_normals)
    # On one thread: open3d sums the normal equations over its threads in an order that changes from run to run, so
    # the same clouds gave poses up to 11 um apart (the bracket's thin plates); one thread gives one answer.
    with _one_thread():
        X = reg.registration_icp(src, tgt, float(max_correspondence_m), X0, method, _criteria(iterations))
    return _result(X)


def estimate_normals(points: npt.ArrayLike, radius_m: float, max_neighbours: int) -> FloatArray:
    """Unit normals (n, 3), unoriented, of a plane fit to each point's neighbours within ``radius_m`` [m] (at
    most the ``max_neighbours`` nearest): open3d's ``estimate_normals`` with a hybrid KD-tree search."""
    o3d = _o3d()
    pc = _legacy_cloud(points)
    # open3d holds the interpreter lock throughout (the cell's other threads wait): on every core it is over soonest.
    with _every_core():
        pc.estimate_normals(o3d.geometry.KDTreeSearchParamHybrid(radius=float(radius_m), max_nn=int(max_neighbours)))
    return np.asarray(pc.normals, dtype=np.float64).reshape(-1, 3)


def radius_outlier_mask(points: npt.ArrayLike, radius_m: float, min_neighbours: int) -> npt.NDArray[np.bool_]:
    """(n,) True for points with at least ``min_neighbours`` other points within ``radius_m``."""
    pts = np.asarray(points, dtype=np.float64)
    keep = np.zeros(len(pts), dtype=bool)
    if len(pts) == 0:
        return keep
    # open3d keeps a point when its neighbour count *including itself* exceeds nb_points.
    cloud = _legacy_cloud(pts)
    with _every_core():
        _, index = cloud.remove_radius_outlier(nb_points=int(min_neighbours), radius=float(radius_m))
    keep[np.asarray(index, dtype=np.intp)] = True
    return keep


def neighbour_counts(points: npt.ArrayLike, queries: npt.ArrayLike, radius_m: float) -> npt.NDArray[np.int64]:
    """(q,) number of ``points`` (n, 3) within ``radius_m`` of each of ``queries`` (q, 3), itself included."""
    o3d = _o3d()
    nns = o3d.core.nns.NearestNeighborSearch(o3d.core.Tensor(_array(points)))
    with _every_core():
        nns.fixed_radius_index(float(radius_m))
        _, _, splits = nns.fixed_radius_search(o3d.core.Tensor(_array(queries)), float(radius_m))
    return np.diff(splits.numpy()).astype(np.int64)


def write_ply(path: Path, points: FloatArray, camera: npt.NDArray[np.integer] | None) -> None:
    """Binary PLY with double x, y, z and, when given, an int ``camera`` vertex property."""
    o3d = _o3d()
    pc = o3d.t.geometry.PointCloud()
    pc.point.positions = o3d.core.Tensor(_array(points))
    if camera is not None:
        # open3d's PLY writer has no int16: the index is stored as int32.
        pc.point.camera = o3d.core.Tensor(_array(np.reshape(camera, (-1, 1)), np.int32))
    if not o3d.t.io.write_point_cloud(str(path), pc, write_ascii=False):
        raise OSError(f"open3d could not write {str(path)!r}")


def read_ply(path: Path) -> tuple[FloatArray, npt.NDArray[np.int32] | None]:
    """Points (n, 3) float64 and the ``camera`` vertex property (n,) if the file has one."""
    o3d = _o3d()
    pc = o3d.t.io.read_point_cloud(str(path))
    if "positions" not in pc.point:
        return np.zeros((0, 3)), None
    points = pc.point.positions.numpy().astype(np.float64).reshape(-1, 3)
    camera = pc.point.camera.numpy().astype(np.int32).reshape(-1) if "camera" in pc.point else None
    return points, camera


def fpfh_ransac(
    source: npt.ArrayLike,
    source_normals: npt.ArrayLike,
    target: npt.ArrayLike,
    target_normals: npt.ArrayLike,
    voxel_m: float,
    seed: int,
    iterations: int = 100_000,
) -> FloatArray:
    """(4, 4) X_TS from a global registration of ``source`` onto ``target`` (points (n, 3) with oriented unit
    normals (n, 3), both on a grid of about ``voxel_m``): FPFH features (radius 5 voxels) matched by RANSAC
    (open3d's ``registration_ransac_based_on_feature_matching``, 3-point hypotheses, inliers within 1.5 voxels,
    edge-length and distance checkers), ``iterations`` hypotheses at most, open3d's random stream seeded with
    ``seed`` (open3d's only generator; the result may still vary with thread scheduling)."""
    o3d = _o3d()
    reg = o3d.pipelines.registration
    o3d.utility.random.seed(int(seed))
    src, tgt = _legacy_cloud(source, source_normals), _legacy_cloud(target, target_normals)
    search = o3d.geometry.KDTreeSearchParamHybrid(radius=5.0 * float(voxel_m), max_nn=100)
    distance = 1.5 * float(voxel_m)
    with _every_core():
        f_src = reg.compute_fpfh_feature(src, search)
        f_tgt = reg.compute_fpfh_feature(tgt, search)
        result = reg.registration_ransac_based_on_feature_matching(
            src,
            tgt,
            f_src,
            f_tgt,
            True,
            distance,
            reg.TransformationEstimationPointToPoint(False),
            3,
            [reg.CorrespondenceCheckerBasedOnEdgeLength(0.9), reg.CorrespondenceCheckerBasedOnDistance(distance)],
            reg.RANSACConvergenceCriteria(int(iterations), 0.999),
        )
    return np.array(result.transformation)


def read_pcd(path: Path) -> FloatArray:
    """Points (n, 3) float64 of a PCD file, as written (NaN rows kept; read as PCD whatever its name)."""
    o3d = _o3d()
    pc = o3d.t.io.read_point_cloud(str(path), format="pcd", remove_nan_points=False, remove_infinite_points=False)
    if "positions" not in pc.point:
        return np.zeros((0, 3))
    return np.asarray(pc.point.positions.numpy(), dtype=np.float64).reshape(-1, 3)


def rays_hit(
    vertices: npt.ArrayLike,
    triangles: npt.ArrayLike,
    origins: npt.ArrayLike,
    directions: npt.ArrayLike,
    max_t: npt.ArrayLike | None = None,
) -> npt.NDArray[np.bool_]:
    """(n,) whether each ray (origins (n, 3) [m], directions (n, 3)) meets the triangle mesh ``vertices`` (v, 3)
    [m], ``triangles`` (t, 3) vertex indices at a distance t >= 0 (open3d's ``RaycastingScene``, Embree; single
    precision, so about 0.1 um at a metre), and below ``max_t`` (n,) or scalar (in units of each direction's length;
    None: anywhere along the ray)."""
    o3d = _o3d()
    o = np.asarray(origins, dtype=np.float64).reshape(-1, 3)
    tri = np.asarray(triangles, dtype=np.uint32).reshape(-1, 3)
    if not len(o) or not len(tri):
        return np.zeros(len(o), dtype=bool)
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(o3d.core.Tensor(_array(vertices, np.float32)), o3d.core.Tensor(_array(tri, np.uint32)))
    rays = np.hstack([o, np.asarray(directions, dtype=np.float64).reshape(-1, 3)])
    t_hit = scene.cast_rays(o3d.core.Tensor(_array(rays, np.float32)))["t_hit"].numpy()
    if max_t is None:
        return np.asarray(np.isfinite(t_hit))
    return np.asarray(np.isfinite(t_hit) & (t_hit < np.asarray(max_t, dtype=np.float64)))
