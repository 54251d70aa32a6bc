"""The baseline: Takubo et al. as the paper ran it (RANSAC planes, the weld line their intersection), three seeded runs
per seam on the 1 cm cloud by default (docs/locate.md, "The two baselines")."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from cell.config.seams import RansacOptions
from cell.config.seams import RansacThresholds as _Thresholds
from cell.errors import MapError
from cell.geometry import FloatArray
from cell.seams._index import dense_index
from cell.seams._lines import plane_intersection
from cell.seams.sigma import RANSAC_END_SIGMA_M, ransac_sigma
from cell.types import EndSource, MapSeam, Reason, SeamEstimate, SeamScene, SeamStatus


@dataclass(frozen=True)
class _Plane:
    n: FloatArray  # (3,) unit normal
    d: float  # n . p = d [m]
    inliers: np.ndarray  # indices into the region's points


class RansacLocator:
    """RANSAC plane-intersection baseline (Takubo et al.), restricted to the map's seam region."""

    name: str = "ransac"
    reads_voxel_cloud: bool = True

    def __init__(self, options: RansacOptions | None = None) -> None:
        self.options = options if options is not None else RansacOptions()

    def locate(self, scene: SeamScene, seam: MapSeam, rng: np.random.Generator) -> SeamEstimate:
        """Median of ``runs`` RANSAC runs on the points near ``seam`` (frame R); deterministic for ``rng``."""
        o = self.options
        normals = self._map_normals(scene, seam)
        P = self._region(scene, seam)
        if len(P) < 2 * o.min_inliers:
            return SeamEstimate(
                seam.id,
                SeamStatus.NOT_FOUND,
                code=Reason.NO_SUPPORT,
                reason=f"{len(P)} points near the seam, RANSAC needs {2 * o.min_inliers}",
            )
        th = o.thresholds(_spacing(P))
        results = []
        for _ in range(o.runs):
            res = self._one_run(P, seam, normals, th, rng)
            if res is not None:
                results.append(res)
        if not results:
            return SeamEstimate(
                seam.id,
                SeamStatus.NOT_FOUND,
                code=Reason.NO_SUPPORT,
                reason=f"no two planes along the map's weld faces near the seam in {o.runs} RANSAC runs "
                f"({len(P)} points, planes of at least {th.min_inliers})",
            )
        ends = np.array(results)  # (runs, 2, 3)
        med = np.median(ends, axis=0)
        spread = float(np.max(np.linalg.norm(ends - med, axis=2)))
        conf = len(results) / o.runs * float(np.exp(-spread / 0.005))
        return SeamEstimate(
            seam.id,
            SeamStatus.FOUND,
            reason=f"{len(results)}/{o.runs} runs, spread {spread * 1000:.3f} mm",
            p_start=med[0],
            p_end=med[1],
            confidence=conf,
            sigma_m=ransac_sigma(),
            end_sigma_m=(RANSAC_END_SIGMA_M, RANSAC_END_SIGMA_M),
            end_source=(EndSource.FACE_END, EndSource.FACE_END),
        )

    def _map_normals(self, scene: SeamScene, seam: MapSeam) -> tuple[FloatArray, FloatArray]:
        joint = scene.joints.get(seam.id)
        if joint is None:
            raise MapError(
                f"seam {seam.id} has no joint; joints known for: {', '.join(sorted(scene.joints)) or 'none'}"
            )
        n_a, _ = scene.weldmap.part(joint.abutting).face_plane(joint.face_abutting)
        n_b, _ = scene.weldmap.part(joint.receiving).face_plane(joint.face_receiving)
        return n_a, n_b

    def _region(self, scene: SeamScene, seam: MapSeam) -> FloatArray:
        """Points (n, 3) within region_m of the map seam segment extended by region_m."""
        o = self.options
        if o.cloud == "dense":
            dense = dense_index(scene)
            return dense.tube(seam.p_start, seam.p_end, o.region_m, o.region_m, 1.0)[0].T
        pts = scene.cloud.points
        t = seam.direction
        q = pts - (seam.p_start - o.region_m * t)
        s = q @ t
        d2 = np.einsum("ij,ij->i", q, q) - s * s
        keep = (s >= 0.0) & (s <= seam.length + 2.0 * o.region_m) & (d2 <= o.region_m**2)
        return np.asarray(pts[keep])

    def _segment(self, P: FloatArray, th: _Thresholds, rng: np.random.Generator) -> list[_Plane]:
        """Sequential RANSAC: planes in decreasing order of support, each refitted by least squares."""
        o = self.options
        remaining = np.arange(len(P))
        planes: list[_Plane] = []
        while len(planes) < o.max_planes and len(remaining) >= th.min_inliers:
            score = (
                remaining
                if len(remaining) <= o.sample_points
                else rng.choice(remaining, o.sample_points, replace=False)
            )
            tri = P[rng.choice(remaining, (o.iterations, 3))]  # (iterations, 3 points, 3)
            n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
            norm = np.linalg.norm(n, axis=1)
            good = norm > 1e-9
            if not np.any(good):
                break
            n = n[good] / norm[good, None]
            d = np.einsum("ij,ij->i", n, tri[good, 0])
            counts = (np.abs(P[score] @ n.T - d) < th.distance).sum(axis=0)
            best = int(np.argmax(counts))
            nb, db = n[best], float(d[best])
            for _ in range(2):  # least-squares refit on all remaining inliers
                inl = remaining[np.abs(P[remaining] @ nb - db) < th.distance]
                if len(inl) < 3:
                    break
                c = P[inl].mean(axis=0)
                nb = np.linalg.svd(P[inl] - c, full_matrices=False)[2][2]
                db = float(nb @ c)
            inl = remaining[np.abs(P[remaining] @ nb - db) < th.distance]
            if len(inl) < th.min_inliers:
                break
            planes.append(_Plane(nb, db, inl))
            remaining = np.setdiff1d(remaining, inl, assume_unique=True)
        return planes

    def _pick(
        self, planes: list[_Plane], normals: tuple[FloatArray, FloatArray], mid: FloatArray
    ) -> tuple[_Plane, _Plane] | None:
        """The joint's two planes: for each of the map's weld faces, the largest plane along it passing near
        the seam's middle ``mid`` (3,); None unless both are found, distinct and not parallel."""
        o = self.options
        cos_par, cos_match = np.cos(np.radians(o.parallel_deg)), np.cos(np.radians(o.match_deg))
        matched = []
        for n_face in normals:
            cands = [
                p
                for p in planes
                if abs(float(p.n @ n_face)) > cos_match and abs(float(p.n @ mid) - p.d) < o.match_offset_m
            ]
            matched.append(max(cands, key=lambda p: len(p.inliers)) if cands else None)
        a, b = matched
        if a is not None and b is not None and a is not b and abs(float(a.n @ b.n)) < cos_par:
            return a, b
        return None

    def _one_run(
        self,
        P: FloatArray,
        seam: MapSeam,
        normals: tuple[FloatArray, FloatArray],
        th: _Thresholds,
        rng: np.random.Generator,
    ) -> tuple[FloatArray, FloatArray] | None:
        """One RANSAC run: (start, end) (3,) each [m], or None when it finds no pair of joint planes."""
        o = self.options
        mid = 0.5 * (seam.p_start + seam.p_end)
        pair = self._pick(self._segment(P, th, rng), normals, mid)
        if pair is None:
            return None
        a, b = pair
        p0, t = plane_intersection(a.n, a.d, b.n, b.d, mid)
        if t @ seam.direction < 0.0:
            t = -t
        extents = []
        for plane, other in ((a, b), (b, a)):
            q = P[plane.inliers] - p0
            s = q @ t
            # Inliers near the line, but not on the other plane too (there the planes cannot tell who is who).
            near = (np.linalg.norm(q - np.outer(s, t), axis=1) < th.clip_radius) & (
                np.abs(P[plane.inliers] @ other.n - other.d) > th.clip_band
            )
            if np.count_nonzero(near) < 3:
                return None
            lo_s, hi_s = np.quantile(s[near], [o.clip_quantile, 1.0 - o.clip_quantile])
            extents.append((float(lo_s), float(hi_s)))
        lo, hi = max(extents[0][0], extents[1][0]), min(extents[0][1], extents[1][1])
        if hi <= lo:
            return None
        return p0 + lo * t, p0 + hi * t


def _spacing(P: FloatArray) -> float:
    """Point spacing [m] of the region's points (n, 3): the median distance to the 4th nearest neighbour (on a
    voxel grid one voxel, even where a face lying on a grid plane fills the voxels on both sides of it)."""
    k = min(5, len(P))
    dist, _ = cKDTree(P).query(P[:: max(1, len(P) // 500)], k=k)
    return float(np.median(dist[:, k - 1]))
