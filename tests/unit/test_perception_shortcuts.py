"""The shortcuts that make perception cheaper give the answers of the plain computations they replace."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
from scipy.spatial import cKDTree

from cell.config.perception import HealthOptions
from cell.perception import downsample
from cell.perception.camera_health import _among, agreement
from cell.types import Cloud


def test_open3d_core_loads_without_its_visualization() -> None:
    code = (
        "import sys\nfrom cell.perception import _open3d\n_open3d.estimate_normals([[0, 0, 0], [1, 0, 0], [0, 1, 0]],"
        " 2.0, 3)\nprint(sorted(m for m in sys.modules if m.split('.')[0] in ('dash', 'plotly')"
        " or m.startswith('open3d.visualization')))"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "[]"


def _brute_agreement(clouds: dict[str, Cloud], o: HealthOptions) -> dict[tuple[str, str], float]:
    grids = {n: np.asarray(downsample(c, o.agree_voxel_m).points) for n, c in clouds.items()}
    return {
        (a, b): float(np.mean(np.isfinite(cKDTree(grids[b]).query(grids[a], distance_upper_bound=o.agree_tol_m)[0])))
        for a in grids
        for b in grids
        if a != b
    }


def test_agreement_shortcut_gives_the_searched_shares() -> None:
    rng = np.random.default_rng(3)
    plane = np.column_stack([rng.uniform(0, 0.4, 40000), rng.uniform(0, 0.3, 40000), rng.normal(0, 0.002, 40000)])
    other = plane[:30000] + np.array([0.004, 0.0, 0.003])  # overlapping, a few mm off, and a part the first never saw
    far = np.column_stack([rng.uniform(0.5, 0.7, 5000), rng.uniform(0, 0.3, 5000), np.zeros(5000)])
    names = ("a", "b")
    clouds = {
        "a": Cloud(plane, "R", np.zeros(len(plane), np.int16), names),
        "b": Cloud(np.concatenate([other, far]), "R", np.ones(len(other) + len(far), np.int16), names),
    }
    for o in (HealthOptions(), HealthOptions(agree_tol_m=0.006)):  # the second: tolerance under a voxel's diagonal
        fast, brute = agreement(clouds, o), _brute_agreement(clouds, o)
        assert fast.keys() == brute.keys()
        for key, share in brute.items():
            assert fast[key] == share
    assert 0.2 < agreement(clouds)[("b", "a")] < 0.95  # a real mix of agreeing and disagreeing points


def test_voxel_membership_by_binary_search_is_isins_answer() -> None:
    """The camera agreement's voxel membership (one sorted array searched per pair) answers as ``np.isin`` does,
    shared voxels, repeats and an empty camera included."""
    rng = np.random.default_rng(3)
    a = rng.integers(0, 1 << 40, 5000)
    b = np.concatenate([a[::3], rng.integers(0, 1 << 40, 4000), a[:10]])
    for x, y in ((a, b), (b, a), (a, b[:0]), (a[:0], b), (np.repeat(a[:50], 3), a[25:75])):
        got = _among(x, np.unique(y))
        assert got.dtype == bool and np.array_equal(got, np.isin(x, y))
    assert _among(a, np.unique(b)).sum() == np.isin(a, b).sum() > 1000
