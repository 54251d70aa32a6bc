"""The vectorised plane fits and the cloud index on the voxel table that make our locator fast."""

from __future__ import annotations

import numpy as np

from cell.seams import _batch, _index, _robust
from cell.types import Cloud
from cell.voxels import in_box, voxel_order


def test_fit_offsets_recovers_each_plane_despite_outliers_and_weighs_cameras_by_their_noise() -> None:
    rng = np.random.default_rng(0)
    truth = np.array([0.0021, -0.0013, 0.0004])
    r, cam, lengths = [], [], []
    for j, off in enumerate(truth):
        n = 1500 + 500 * j
        c = rng.integers(0, 2, n)  # camera 1 is five times noisier than camera 0
        x = off + np.where(c == 0, 0.0005, 0.0025) * rng.standard_normal(n)
        out = rng.random(n) < 0.1  # 10 % of another surface 6 mm behind
        x[out] = off - 0.006 + 0.0005 * rng.standard_normal(int(out.sum()))
        r.append(x)
        cam.append(c)
        lengths.append(n)
    fit = _batch.fit_offsets(np.concatenate(r), lengths, np.concatenate(cam), 2, mode_half_width=0.015, rescale_after=3)
    assert np.all(np.abs(fit.offset - truth) < 4.0 * fit.se), (fit.offset - truth, fit.se)
    assert np.all(fit.se < 3e-5)
    # Weighted by camera: far better than the plain mean of the inliers would be (sigma ~1.8 mm / sqrt(n)).
    assert np.all(fit.se < 0.6 * 0.0018 / np.sqrt(np.array(lengths)))
    # The quiet camera's outliers get no weight (beyond its biweight cut-off, not the noisy camera's); the noisy
    # camera's inliers a twenty-fifth of the quiet one's.
    w = np.split(fit.weights, np.cumsum(lengths)[:-1])
    for j in range(3):
        inl = np.abs(r[j] - truth[j]) < 0.0005
        quiet, noisy = np.median(w[j][inl & (cam[j] == 0)]), np.median(w[j][inl & (cam[j] == 1)])
        assert 10.0 < quiet / noisy < 60.0
        assert np.all(w[j][(np.abs(r[j] - (truth[j] - 0.006)) < 0.001) & (cam[j] == 0)] == 0.0)


def test_group_medians() -> None:
    a = np.array([3.0, 1.0, 2.0, 10.0, 20.0, 0.5])
    g = np.array([0, 0, 0, 2, 2, 2])
    med, counts = _batch.group_medians(a, g, 4)
    assert list(counts) == [3, 0, 3, 0]
    assert np.allclose(med, [2.0, 0.0, 10.0, 0.0], rtol=1e-12)


def test_cloud_index_tube_is_the_cylinder_and_its_layers_are_nested_shares() -> None:
    rng = np.random.default_rng(1)
    P = rng.uniform(-0.3, 0.3, (200_000, 3))
    cam = rng.integers(0, 3, len(P)).astype(np.int16)
    index = _index.index_of(Cloud(P, "R", cam), voxel_m=0.02)
    a, b, radius, extend = np.array([-0.1, 0.02, 0.0]), np.array([0.12, -0.05, 0.07]), 0.04, 0.01
    t = (b - a) / np.linalg.norm(b - a)
    s = (P - (a - extend * t)) @ t
    d = np.linalg.norm(P - (a - extend * t) - np.outer(s, t), axis=1)
    inside = (s >= 0.0) & (s <= np.linalg.norm(b - a) + 2 * extend) & (d <= radius)
    xyz, c = index.tube(a, b, radius, extend, 1.0)
    assert xyz.shape[1] == int(inside.sum())
    got = {tuple(p) for p in xyz.T}
    assert got == {tuple(p) for p in P[inside]}
    camera_of = {tuple(p): k for p, k in zip(P[inside], cam[inside], strict=True)}
    assert all(camera_of[tuple(p)] == k for p, k in zip(xyz.T, c, strict=True))  # each point keeps its camera
    quarter, _ = index.tube(a, b, radius, extend, 0.25)
    half, _ = index.tube(a, b, radius, extend, 0.5)
    assert {tuple(p) for p in quarter.T} <= {tuple(p) for p in half.T} <= got
    assert abs(quarter.shape[1] / inside.sum() - 0.25) < 0.03 and abs(half.shape[1] / inside.sum() - 0.5) < 0.03
    # The density of a uniform volume is not a surface's, but the pitch must follow the share.
    assert np.isclose(index.pitch(0.25), 2.0 * index.pitch(1.0))


def test_tilt_fits_match_a_weighted_least_squares_of_each_plane_and_recover_the_tilt() -> None:
    rng = np.random.default_rng(3)
    prior = np.tan(np.radians(0.05))
    truth = [(0.0004, 6e-4, -3e-4), (-0.0011, -2e-4, 8e-4)]  # offset [m] and slopes: within the prior
    r, u, v, w = [], [], [], []
    for c0, a, b in truth:
        uj, vj = rng.uniform(0.005, 0.06, 3000), rng.uniform(-0.05, 0.05, 3000)
        r.append(c0 + a * uj + b * vj + 0.0001 * rng.standard_normal(3000))
        u.append(uj)
        v.append(vj)
        w.append(rng.uniform(0.5, 1.5, 3000) / 0.0001**2)
    fit = _batch.tilt_fits(
        np.concatenate(r), np.concatenate(u), np.concatenate(v), np.concatenate(w), [3000, 3000], prior
    )
    for j, (c0, a, b) in enumerate(truth):
        # The same model solved on its own: normal equations with the prior on the slopes.
        X = np.column_stack([np.ones(3000), u[j] - fit.uc[j], v[j] - fit.vc[j]])
        H = (X.T * w[j]) @ X + np.diag([0.0, prior**-2, prior**-2])
        coef = np.linalg.solve(H, (X.T * w[j]) @ r[j])
        assert np.allclose([fit.c0[j], fit.a[j], fit.b[j]], coef, rtol=1e-9, atol=1e-12)
        # The plane's value on the seam line (u = 0): the truth within 4 standard errors, which are a few um;
        # the slopes within 4 of theirs (0.1 mm noise over 55 mm: ~1e-4).
        at_line = fit.c0[j] - fit.a[j] * fit.uc[j]
        assert abs(at_line - (c0 + b * fit.vc[j])) < 4.0 * fit.se0[j] and 1e-6 < fit.se0[j] < 2e-5
        assert abs(fit.a[j] - a) < 5e-4 and abs(fit.b[j] - b) < 5e-4


def test_voxel_order_groups_each_voxel_and_its_table_says_where() -> None:
    rng = np.random.default_rng(4)
    P = rng.uniform([-0.2, 0.1, 0.0], [0.1, 0.3, 0.05], (30000, 3))
    cam = rng.integers(0, 3, len(P)).astype(np.int16)
    ordered, table = voxel_order(Cloud(P, "R", cam), 0.01)
    assert sorted(map(tuple, ordered.points)) == sorted(map(tuple, P))  # the same points, reordered
    assert np.all(np.diff(table.keys) > 0) and table.starts[0] == 0 and table.starts[-1] == len(P)
    ijk = np.floor(ordered.points / 0.01).astype(np.int64)
    for v in rng.choice(len(table), 50, replace=False):
        run = ijk[table.starts[v] : table.starts[v + 1]]
        assert len(run) > 0 and np.all(run == run[0])  # one voxel per run ...
    assert len({tuple(x) for x in ijk}) == len(table)  # ... and one run per voxel
    assert np.allclose(table.lo, P.min(axis=0)) and np.allclose(table.hi, P.max(axis=0))
    camera_of = {tuple(p): c for p, c in zip(P, cam, strict=True)}
    assert all(camera_of[tuple(p)] == c for p, c in zip(ordered.points[:500], ordered.camera[:500], strict=True))


def test_in_box_gives_every_point_of_a_box_from_the_voxels_it_touches() -> None:
    rng = np.random.default_rng(6)
    P = rng.uniform([-0.2, 0.1, 0.0], [0.1, 0.3, 0.05], (30000, 3))
    ordered, table = voxel_order(Cloud(P, "R"), 0.01)
    Q = np.asarray(ordered.points)
    for lo, hi in [
        ([-0.05, 0.15, 0.01], [0.02, 0.2, 0.03]),
        ([-0.3, 0.0, -0.1], [0.3, 0.4, 0.2]),  # around everything
        ([0.0, 0.2, 0.02], [0.0, 0.2, 0.02]),  # a point-sized box
        ([0.2, 0.5, 0.1], [0.3, 0.6, 0.2]),  # beside the cloud
    ]:
        at = in_box(table, np.array(lo), np.array(hi))
        inside = np.flatnonzero(np.all((np.array(lo) <= Q) & (np.array(hi) >= Q), axis=1))
        assert len(np.unique(at)) == len(at) and set(inside) <= set(at.tolist())
        near = Q[at]  # and nothing farther than a voxel from the box
        assert np.all(near >= np.array(lo) - 0.01) and np.all(near <= np.array(hi) + 0.01)
    assert len(in_box(table, np.array([-0.3, 0.0, -0.1]), np.array([0.3, 0.4, 0.2]))) == len(P)


def test_robust_offset_recovers_a_plane_despite_outliers_and_weighs_cameras_by_their_noise() -> None:
    """The scalar fit that places a face from an adjacent face's edge (cell.seams._edge)."""
    rng = np.random.default_rng(5)
    n = 2000
    cam = rng.integers(0, 2, n)  # camera 1 is five times noisier than camera 0
    r = 0.0012 + np.where(cam == 0, 0.0004, 0.002) * rng.standard_normal(n)
    out = rng.random(n) < 0.1  # 10 % of another surface 6 mm behind
    r[out] = 0.0012 - 0.006 + 0.0004 * rng.standard_normal(int(out.sum()))
    fit = _robust.robust_offset(r, cam, _robust.histogram_mode(r, 0.002))
    # Weighted by camera: within 3 standard errors of the quiet camera's mean (0.4 mm / sqrt(900); measured 1.6 um).
    assert abs(fit.offset - 0.0012) < 3.0 * 0.0004 / np.sqrt(900)
    assert 0.0006 < fit.scale < 0.0012  # the inliers' scale, both cameras pooled (measured 0.80 mm)
    # Noise-free: exact, no scatter.
    exact = _robust.robust_offset(np.full(100, 0.003), np.zeros(100, np.intp), 0.0)
    assert exact.offset == 0.003 and exact.scale == 0.0
