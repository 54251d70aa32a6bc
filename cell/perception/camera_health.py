"""Is a camera's data fit to splice? Checks before the splice that turn a broken camera into a reason: one image on its
own (dead, stuck, garbage), and the cameras' clouds against each other (a camera knocked out of calibration, judged
on its footprint and only where the other camera could have seen it; with two cameras none can be blamed)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from scipy.spatial import cKDTree

from cell.config.perception import HealthOptions
from cell.geometry import FloatArray, invert, transform_points
from cell.perception.preprocess import downsample
from cell.types import Cloud, DepthImage

FOOTPRINT_TOLS = 4.0  # a camera's footprint: the voxels of this many agreement tolerances its points occupy


@dataclass(frozen=True)
class ImageHealth:
    """Statistics of one depth image and the verdict: ``reason`` is empty for a usable image."""

    camera: str
    valid_fraction: float
    constant_fraction: float  # share of valid pixels reading the most frequent value
    rough_fraction: float  # share of valid neighbour pairs with an implausible depth step
    reason: str = ""

    @property
    def ok(self) -> bool:
        return not self.reason


def image_health(image: DepthImage, options: HealthOptions | None = None) -> ImageHealth:
    """Judge one depth image from its own pixels (see the module docstring)."""
    o = options if options is not None else HealthOptions()
    z = np.asarray(image.depth, dtype=np.float64)
    valid = np.isfinite(z) & (z > 0)
    n_valid = int(valid.sum())
    valid_fraction = n_valid / max(z.size, 1)
    if valid_fraction < o.min_valid_fraction:
        return ImageHealth(
            image.camera,
            valid_fraction,
            0.0,
            0.0,
            f"no usable image: {n_valid} valid pixels of {z.size} (needs {o.min_valid_fraction:.0%}): "
            "dead, unplugged or blinded",
        )
    values, counts = np.unique(z[valid].astype(np.float32), return_counts=True)
    k = int(np.argmax(counts))
    constant_fraction = float(counts[k]) / n_valid
    rough = 0
    pairs = 0
    for a, b in ((z[:, :-1], z[:, 1:]), (z[:-1, :], z[1:, :])):
        ok = (a > 0) & (b > 0) & np.isfinite(a) & np.isfinite(b)
        step = np.abs(a - b)
        limit = np.maximum(o.rough_jump_m, 0.05 * np.minimum(a, b))
        rough += int(np.count_nonzero(ok & (step > limit)))
        pairs += int(np.count_nonzero(ok))
    rough_fraction = rough / max(pairs, 1)
    reason = ""
    if constant_fraction > o.max_constant_fraction:
        reason = (
            f"implausible image: {constant_fraction:.0%} of the valid pixels read exactly {float(values[k]):.4f} m "
            "(a stuck or frozen sensor)"
        )
    elif rough_fraction > o.max_rough_fraction:
        reason = (
            f"implausible image: {rough_fraction:.0%} of neighbouring pixels differ by more than "
            f"{o.rough_jump_m * 1000:.0f} mm (a real scene: a few per cent at edges): random depths or interference"
        )
    return ImageHealth(image.camera, valid_fraction, constant_fraction, rough_fraction, reason)


def _voxel_keys(points: np.ndarray, voxel_m: float) -> np.ndarray:
    """(n,) one int64 per point naming its voxel of edge ``voxel_m`` (grid anchored at the origin, +-5 km)."""
    ijk = np.floor(points / voxel_m).astype(np.int64) + (1 << 20)
    return np.asarray((ijk[:, 0] << 42) | (ijk[:, 1] << 21) | ijk[:, 2])


def _among(keys: np.ndarray, sorted_unique: np.ndarray) -> npt.NDArray[np.bool_]:
    """(n,) which of ``keys`` are in ``sorted_unique`` (sorted, no repeats): ``np.isin``'s answer, by binary search
    in the one sorted array instead of sorting both for every pair."""
    if not len(sorted_unique):
        return np.zeros(len(keys), dtype=bool)
    pos = np.minimum(np.searchsorted(sorted_unique, keys), len(sorted_unique) - 1)
    return np.asarray(sorted_unique[pos] == keys)


def seen_by(p_R: FloatArray, image: DepthImage, X_WR: FloatArray, tol_m: float) -> npt.NDArray[np.bool_]:
    """(n,) which points p_R (n, 3) [m, frame R] the camera of ``image`` could have seen: in front of it, inside its
    image, where it has a depth, and not behind the surface it saw there by more than ``tol_m`` (a point behind
    another surface, or on a face it sees edge-on, is hidden from it: it can neither confirm nor deny it)."""
    p_C = transform_points(invert(image.X_WC) @ X_WR, p_R)
    k = image.intrinsics
    z = p_C[:, 2]
    ahead = z > 1e-6
    u = np.full(len(z), -1, dtype=np.intp)
    v = np.full(len(z), -1, dtype=np.intp)
    u[ahead] = np.floor(k.fx * p_C[ahead, 0] / z[ahead] + k.cx + 0.5).astype(np.intp)
    v[ahead] = np.floor(k.fy * p_C[ahead, 1] / z[ahead] + k.cy + 0.5).astype(np.intp)
    inside = ahead & (u >= 0) & (u < k.width) & (v >= 0) & (v < k.height)
    seen = np.zeros(len(z), dtype=bool)
    d = np.asarray(image.depth[v[inside], u[inside]], dtype=np.float64)
    seen[inside] = np.isfinite(d) & (d > 0.0) & (z[inside] <= d + tol_m)
    return seen


def agreement(clouds: Mapping[str, Cloud], options: HealthOptions | None = None) -> dict[tuple[str, str], float]:
    """(a, b) -> share of camera a's points (on a grid of ``agree_voxel_m``) with a point of camera b within
    ``agree_tol_m``; for every ordered pair of non-empty clouds (frame R, calibrated extrinsics).

    Both grids share one anchoring, so when the tolerance covers a voxel's diagonal, a's grid point whose voxel
    b also occupies agrees without a search (the two centroids lie in one voxel); only the others are searched.
    """
    return _shares(clouds, options)[0]


def _shares(
    clouds: Mapping[str, Cloud],
    options: HealthOptions | None = None,
    views: tuple[Mapping[str, DepthImage], FloatArray] | None = None,
) -> tuple[dict[tuple[str, str], float], dict[tuple[str, str], float]]:
    """:func:`agreement`, and (a, b) -> the same share over only a's grid points inside b's footprint (the
    voxels of ``FOOTPRINT_TOLS`` x ``agree_tol_m`` that b's points occupy; NaN when none is). With ``views``
    (the depth images by camera and X_WR), both shares count only a's points b could have seen (:func:`seen_by`;
    NaN when b could see none of them)."""
    o = options if options is not None else HealthOptions()
    names = [n for n, c in clouds.items() if len(c) > 0]

    def grid(name: str) -> tuple[FloatArray, cKDTree]:
        p = np.asarray(downsample(clouds[name], o.agree_voxel_m).points)
        return p, cKDTree(p, balanced_tree=False, compact_nodes=False)

    with ThreadPoolExecutor(max_workers=2) as pool:  # two cameras at a time: sorts and tree builds drop the GIL
        done = dict(zip(names, pool.map(grid, names), strict=True))
    grids = {n: p for n, (p, _) in done.items()}
    trees = {n: tree for n, (_, tree) in done.items()}
    shortcut = o.agree_voxel_m * math.sqrt(3.0) * (1.0 + 1e-6) <= o.agree_tol_m
    keys = {n: _voxel_keys(p, o.agree_voxel_m) for n, p in grids.items()} if shortcut else {}
    coarse = {n: _voxel_keys(p, FOOTPRINT_TOLS * o.agree_tol_m) for n, p in grids.items()}
    occupied = {n: np.unique(k) for n, k in keys.items()}  # each camera's voxels, sorted once for every pair
    footprint = {n: np.unique(k) for n, k in coarse.items()}
    out: dict[tuple[str, str], float] = {}
    within: dict[tuple[str, str], float] = {}
    for a, pa in grids.items():
        for b, tree in trees.items():
            if a == b:
                continue
            near = _among(keys[a], occupied[b]) if shortcut else np.zeros(len(pa), dtype=bool)
            agrees = near.copy()
            dist, _ = tree.query(pa[~near], distance_upper_bound=o.agree_tol_m, workers=-1)
            agrees[~near] = np.isfinite(dist)
            judged = np.ones(len(pa), dtype=bool)
            if views is not None and b in views[0]:
                judged = seen_by(pa, views[0][b], views[1], o.agree_tol_m)
            agrees &= judged
            n_judged = np.count_nonzero(judged)
            out[(a, b)] = float(np.count_nonzero(agrees) / n_judged) if n_judged else float("nan")
            inside = _among(coarse[a], footprint[b]) & judged
            n_in = np.count_nonzero(inside)
            within[(a, b)] = float(np.count_nonzero(agrees & inside) / n_in) if n_in else float("nan")
    return out, within


def _least(x: float, y: float) -> float:
    """The smaller share; 0 when either is NaN (nothing to judge by is no agreement)."""
    return 0.0 if math.isnan(x) or math.isnan(y) else min(x, y)


def disagreeing_cameras(
    clouds: Mapping[str, Cloud],
    options: HealthOptions | None = None,
    views: tuple[Mapping[str, DepthImage], FloatArray] | None = None,
) -> dict[str, str]:
    """Cameras whose cloud agrees with no other camera while at least two others agree with each other:
    name -> reason. Empty when all agree, or when there is no agreeing majority to judge by. With ``views`` (the
    depth images and X_WR) a camera is judged by another only on what that one could have seen: a face one camera
    sees and another sees edge-on (or hidden) is no disagreement."""
    o = options if options is not None else HealthOptions()
    share, within = _shares(clouds, o, views)
    names = sorted({a for a, _ in share})

    def both(a: str, b: str) -> float:  # both ways: a shifted cloud can still cover the other's tops
        return _least(share[(a, b)], share[(b, a)])

    def agree(a: str, b: str) -> bool:
        """Both ways, each camera's points where the other has any (a camera that sees a part of what the other
        sees is judged there), and one of them lies on the other's surfaces as a whole."""
        inside = _least(within[(a, b)], within[(b, a)])  # no common footprint (NaN) never agrees
        whole = max(np.nan_to_num(share[(a, b)], nan=0.0), np.nan_to_num(share[(b, a)], nan=0.0))
        return inside >= o.min_agreement and whole >= o.min_agreement

    out = {}
    for c in names:
        others = [n for n in names if n != c]
        if any(agree(c, n) for n in others):
            continue
        if not any(agree(a, b) for i, a in enumerate(others) for b in others[i + 1 :]):
            continue  # no pair of the others agrees either: no majority to tell who is wrong
        best = max(others, key=lambda n: both(c, n))
        worst = both(c, best)
        out[c] = (
            f"disagrees with the other cameras: at best {worst:.0%} of its points and {best}'s (where each could see "
            f"the other's) lie within "
            f"{o.agree_tol_m * 1000:.0f} mm of each other (needs {o.min_agreement:.0%}), while the others agree: "
            "knocked out of calibration?"
        )
    return out
