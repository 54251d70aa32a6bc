"""The same clouds give the same ICP pose in every run: open3d's threads sum the normal equations in an order that
changes from run to run, so the adapter runs its ICP on one thread, and its other calls on every core only while no
ICP is in flight (cell/perception/_open3d.py)."""

from __future__ import annotations

import numpy as np

from cell.perception import _open3d


def test_icp_on_a_thin_plate_gives_one_pose_bit_for_bit() -> None:
    rng = np.random.default_rng(0)
    n = 20_000  # a 12 mm plate's noisy top and one rim: a problem ill-conditioned along the plate
    top = np.column_stack([rng.uniform(0, 0.4, n), rng.uniform(0, 0.25, n), 0.012 + rng.normal(0, 0.0015, n)])
    rim = np.column_stack([0.4 + rng.normal(0, 0.0015, 1000), rng.uniform(0, 0.25, 1000), rng.uniform(0, 0.012, 1000)])
    gx, gy = np.meshgrid(np.arange(0, 0.4, 0.003), np.arange(0, 0.25, 0.003))
    target = np.concatenate(
        [np.column_stack([gx.ravel(), gy.ravel(), np.full(gx.size, 0.012)]),
         np.column_stack([np.full(84, 0.4), np.linspace(0, 0.25, 84), np.full(84, 0.006)])]
    )  # fmt: skip
    normals = np.concatenate([np.tile([0.0, 0.0, 1.0], (gx.size, 1)), np.tile([1.0, 0.0, 0.0], (84, 1))])
    source = np.concatenate([top, rim])
    poses = [_open3d.icp(source, target, 0.002, 60, None, normals).X_TS for _ in range(4)]
    assert all(np.array_equal(X, poses[0]) for X in poses[1:])
    assert abs(poses[0][2, 3]) < 5e-4  # and it is the fit: the plate's top brought onto the target within noise


def _plate() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(1)
    n = 20_000
    source = np.column_stack([rng.uniform(0, 0.4, n), rng.uniform(0, 0.25, n), 0.012 + rng.normal(0, 0.0015, n)])
    gx, gy = np.meshgrid(np.arange(0, 0.4, 0.003), np.arange(0, 0.25, 0.003))
    target = np.column_stack([gx.ravel(), gy.ravel(), np.full(gx.size, 0.012)])
    return source, target, np.tile([0.0, 0.0, 1.0], (gx.size, 1))


def test_open3d_stays_on_one_thread_while_an_icp_is_in_flight_and_uses_every_core_otherwise() -> None:
    o3d = _open3d._o3d()
    assert o3d.utility.get_max_threads() == 1  # from the load on
    with _open3d._every_core():
        assert o3d.utility.get_max_threads() == _open3d._THREADS.cores
    assert o3d.utility.get_max_threads() == 1
    with _open3d._one_thread(), _open3d._every_core():  # an ICP in flight on another of the cell's threads
        assert o3d.utility.get_max_threads() == 1


def test_icps_and_normals_on_two_threads_give_the_poses_they_give_alone() -> None:
    from concurrent.futures import ThreadPoolExecutor

    source, target, normals = _plate()
    alone = _open3d.icp(source, target, 0.004, 60, None, normals).X_TS
    normals_alone = _open3d.estimate_normals(source, 0.02, 50)
    with ThreadPoolExecutor(max_workers=3) as pool:
        icps = [pool.submit(_open3d.icp, source, target, 0.004, 60, None, normals) for _ in range(4)]
        fits = [pool.submit(_open3d.estimate_normals, source, 0.02, 50) for _ in range(4)]
        assert all(np.array_equal(f.result().X_TS, alone) for f in icps)
        assert all(np.array_equal(f.result(), normals_alone) for f in fits)
    assert _open3d._o3d().utility.get_max_threads() == 1 and _open3d._THREADS.icps == 0
