"""Our map-guided seam locator: fit the two weld faces near the map's seam, intersect them, find the ends.

Method (general: no assumption that a seam runs along x, y or z):

1. From the aligned map: the weld faces, A's ``face_abutting`` (n_a, d_a) and B's ``face_receiving`` (n_b,
   d_b), the seam line where they meet with its direction t, and A's side faces across t (where the seam
   ends).
2. Points of ``scene.dense`` in a tube around the map seam (a KD-tree built once per scene).
3. Face A's support: points near A's plane, away from B's face by a corner band (gap, shadow and corner noise
   live there), inside A's extent along t less an edge band (flying pixels on convex edges), above the table.
   Face B's support: points near B's plane inside B's face less an edge band, outside the footprint of A grown
   by the band. Each face's offset is fitted along the map's normal by iteratively reweighted least squares
   (Tukey biweight), each camera weighted by its own measured noise; the normal is refined by a small tilt
   only when the data demand it (a Wald test on the tilt). ``passes`` passes: the first from the map with wide
   gates, the others with gates and bands from the measured noise and the ends found.
4. The seam line is the intersection of the fitted planes. Each end is where the line meets A's side face
   across it, fitted from that face's points when it is seen, the table when A rests on it there, or else the
   extent of face A's support along t (its empirical CDF extrapolated, then refined by a blurred-edge
   likelihood: robust to blur and strays).
5. Confidence from the support of each face against the expected count, the standard errors of the fitted
   offsets and ends, and the residual scale. A face without enough support gives NOT_FOUND naming that face.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from cell.errors import MapError
from cell.geometry import FloatArray
from cell.seams import _fit
from cell.seams.base import Joint, SeamScene
from cell.types import Box, MapSeam, SeamEstimate, SeamStatus

BoolArray = npt.NDArray[np.bool_]
_Z = np.array([0.0, 0.0, 1.0])


@dataclass(frozen=True)
class OursOptions:
    """Options of :class:`OursLocator` (defaults suit RealSense D4xx-class clouds at 1-2 m); lengths [m]."""

    tube_radius_m: float = 0.035  # points within this distance of the map seam are looked at
    extend_m: float = 0.02  # ... and this far past the map's ends
    corner_band_m: float = (
        0.005  # least band excluded next to the other weld face (gap, shadow, corner noise)
    )
    edge_band_m: float = 0.004  # band excluded along convex edges (flying pixels, side faces)
    map_tolerance_m: float = 0.006  # how far the as-built faces and ends may lie from the aligned map
    sensor_sigma_m: float = 0.003  # depth noise assumed before it is measured
    gate_sigmas: float = 3.5  # half-width of the gate around a plane, in measured noise scales
    passes: int = 2  # fits: the first from the map with wide gates, the others with measured noise and ends
    min_face_points: int = 30  # fewer supporting points on a weld face: NOT_FOUND
    min_end_points: int = 40  # fewer points on a side face of A: take the end from the extent instead
    refine_normals: bool = True  # tilt a face's normal when the data demand it
    tilt_sigmas: float = 4.0  # ... significance of the tilt (Wald statistic, in standard errors)
    max_tilt_deg: float = 3.0  # ... and at most this much
    max_points: int = 30000  # random subsample of the tube above this
    target_se_m: float = 0.0002  # standard error of the seam's position that still earns full confidence


@dataclass
class _Face:
    """A plane being fitted: unit normal n (3,), offset d [m], noise scale [m], offset standard error [m]."""

    n: FloatArray
    d: float
    scale: float
    se: float = float("inf")
    count: int = 0
    tilted: bool = False


@dataclass
class _End:
    """One end of the seam: a plane across the line (A's side face or the table), or the extent of face A."""

    n: FloatArray
    d: float
    on_table: bool
    s: float = 0.0  # parameter along the line [m]
    se: float = float("inf")
    scale: float = 0.003  # noise of the side face's points [m]
    source: str = "map"


class OursLocator:
    """Map-guided plane-fit seam locator (see the module docstring). Deterministic for a given ``rng``."""

    name: str = "ours"

    def __init__(self, options: OursOptions | None = None) -> None:
        self.options = options if options is not None else OursOptions()

    def locate(self, scene: SeamScene, seam: MapSeam, rng: np.random.Generator) -> SeamEstimate:
        """Find ``seam`` (frame R) in ``scene.dense`` (see the module docstring); MapError for a bad joint."""
        o = self.options
        joint = _joint_of(scene, seam)
        box_a = scene.weldmap.part(joint.abutting).box
        box_b = scene.weldmap.part(joint.receiving).box
        n_a, d_a = box_a.face_plane(joint.face_abutting)
        n_b, d_b = box_b.face_plane(joint.face_receiving)
        mid = 0.5 * (seam.p_start + seam.p_end)
        try:
            p0, t = _fit.plane_intersection(n_a, d_a, n_b, d_b, mid)
        except ValueError:
            raise MapError(
                f"seam {seam.id}: faces {joint.abutting} {joint.face_abutting} and {joint.receiving} "
                f"{joint.face_receiving} are parallel; a joint needs two faces that meet in a line"
            ) from None
        if t @ seam.direction < 0.0:
            t = -t
        if _against_table(n_a, n_b, seam, scene.table_z, o.map_tolerance_m):
            return SeamEstimate(seam.id, SeamStatus.NOT_VISIBLE, reason="the seam lies against the table")

        idx = _fit.tube_indices(scene, seam.p_start, seam.p_end, o.tube_radius_m, o.extend_m)
        if len(idx) > o.max_points:
            idx = np.sort(rng.choice(idx, o.max_points, replace=False))
        P = scene.dense.points[idx]
        cam = scene.dense.camera[idx].astype(np.intp)
        above = P[:, 2] >= scene.table_z + o.corner_band_m
        geo = _Geometry.of(box_a, box_b, joint, t, o.edge_band_m)
        s_map = sorted((float(t @ (seam.p_start - p0)), float(t @ (seam.p_end - p0))))
        face_a = _Face(n_a, d_a, o.sensor_sigma_m)
        face_b = _Face(n_b, d_b, o.sensor_sigma_m)
        ends = geo.end_planes(t, scene.table_z, o.map_tolerance_m)
        ends[0].s, ends[1].s = s_map
        names = (f"{joint.abutting} {joint.face_abutting}", f"{joint.receiving} {joint.face_receiving}")

        for it in range(o.passes):
            first = it == 0
            p0, t = _fit.plane_intersection(face_a.n, face_a.d, face_b.n, face_b.d, mid)
            if t @ seam.direction < 0.0:
                t = -t
            r_a = P @ face_a.n - face_a.d
            r_b = P @ face_b.n - face_b.d
            s = (P - p0) @ t
            slack = o.map_tolerance_m if first else 0.0
            band_a = max(o.corner_band_m, 3.0 * face_a.scale) + slack
            band_b = max(o.corner_band_m, 3.0 * face_b.scale) + slack
            e0, e1 = ends[0].s, ends[1].s
            eb = o.edge_band_m + (slack if first else min(max(ends[0].se, ends[1].se), o.map_tolerance_m))
            in_a = (r_b >= band_b) & (s >= e0 + eb) & (s <= e1 - eb) & above
            in_b = (
                geo.in_face_b(P)
                & ~((r_a < band_a) & (r_a > -geo.depth_a - band_a) & (s > e0 - band_a) & (s < e1 + band_a))
                & above
            )
            for face, r, region, name, other in (
                (face_a, r_a, in_a, names[0], face_b),
                (face_b, r_b, in_b, names[1], face_a),
            ):
                gate = (o.map_tolerance_m + 3.0 * o.sensor_sigma_m) if first else o.gate_sigmas * face.scale
                sel = region & (np.abs(r) < gate)
                face.count = int(np.count_nonzero(sel))
                if face.count < o.min_face_points:
                    return _not_found(
                        seam.id,
                        f"face {name} has {face.count} points near the seam "
                        f"(needs {o.min_face_points}): not seen or not there",
                    )
                self._fit_face(face, other, r[sel], P[sel], cam[sel], p0, t, first, refine=it == o.passes - 1)
            p0, t = _fit.plane_intersection(face_a.n, face_a.d, face_b.n, face_b.d, mid)
            if t @ seam.direction < 0.0:
                t = -t
            # p0 lies on both fitted planes: its distance from a map plane is how far that face moved.
            for drift, name in (
                (abs(float(n_a @ p0) - d_a), names[0]),
                (abs(float(n_b @ p0) - d_b), names[1]),
            ):
                if drift > 2.0 * o.map_tolerance_m:
                    return _not_found(
                        seam.id,
                        f"face {name} fitted {drift * 1000:.1f} mm from the map "
                        f"(allowed {2000 * o.map_tolerance_m:.1f} mm): wrong surface or part moved",
                    )
            self._find_ends(ends, P, cam, face_a, face_b, p0, t, geo, above, first, s_map)

        length = ends[1].s - ends[0].s
        if not 0.3 * (s_map[1] - s_map[0]) < length < 2.0 * (s_map[1] - s_map[0]) + 2.0 * o.extend_m:
            return _not_found(
                seam.id,
                f"seam length {length * 1000:.1f} mm found, the map says "
                f"{(s_map[1] - s_map[0]) * 1000:.1f} mm",
            )
        conf = self._confidence(scene, face_a, face_b, ends, p0, t, geo, s_map)
        return SeamEstimate(
            id=seam.id,
            status=SeamStatus.FOUND,
            reason=f"ends from {ends[0].source} / {ends[1].source}",
            p_start=p0 + ends[0].s * t,
            p_end=p0 + ends[1].s * t,
            confidence=conf,
        )

    # -- steps ------------------------------------------------------------------------------------------

    def _fit_face(
        self,
        face: _Face,
        other: _Face,
        r: FloatArray,
        P: FloatArray,
        cam: npt.NDArray[np.intp],
        p0: FloatArray,
        t: FloatArray,
        first: bool,
        refine: bool,
    ) -> None:
        """Fit the offset (and, when asked and significant, a small tilt) of ``face``; update it in place."""
        o = self.options
        start = _fit.histogram_mode(r, max(0.002, o.sensor_sigma_m)) if first else 0.0
        ones = np.ones((len(r), 1))
        fit = _fit.robust_plane_fit(r, ones, cam, start)
        face.d += fit.offset
        face.scale, face.se = max(fit.scale, 1e-4), fit.se
        face.count = fit.n_inliers
        if not (refine and o.refine_normals and fit.n_inliers >= 3 * o.min_face_points):
            return
        e_u = other.n - (other.n @ face.n) * face.n
        e_u /= np.linalg.norm(e_u)
        q = P - p0
        X = np.column_stack([ones[:, 0], q @ e_u, q @ t])
        tilt = _fit.robust_plane_fit(r - fit.offset, X, cam, 0.0)
        ab = tilt.coef[1:]
        try:
            wald = float(ab @ np.linalg.solve(tilt.cov[1:, 1:], ab))
        except np.linalg.LinAlgError:
            return
        if wald < o.tilt_sigmas**2 or np.degrees(np.arctan(np.hypot(*ab))) > o.max_tilt_deg:
            return
        m = face.n - ab[0] * e_u - ab[1] * t
        norm = float(np.linalg.norm(m))
        face.d = (face.d + tilt.coef[0] - ab[0] * float(e_u @ p0) - ab[1] * float(t @ p0)) / norm
        face.n = m / norm
        face.se, face.tilted = tilt.se, True

    def _find_ends(
        self,
        ends: list[_End],
        P: FloatArray,
        cam: npt.NDArray[np.intp],
        face_a: _Face,
        face_b: _Face,
        p0: FloatArray,
        t: FloatArray,
        geo: _Geometry,
        above: BoolArray,
        first: bool,
        s_map: list[float],
    ) -> None:
        """Update both ends: the table where A rests on it, A's side face where it is seen, else the extent
        of face A's support along the seam."""
        o = self.options
        r_a = P @ face_a.n - face_a.d
        r_b = P @ face_b.n - face_b.d
        s = (P - p0) @ t
        band_b = max(o.corner_band_m, 3.0 * face_b.scale)
        side = (r_a < -o.edge_band_m) & (r_a > -(geo.depth_a - o.edge_band_m)) & (r_b >= band_b) & above
        known = [False, False]
        for k, end in enumerate(ends):
            if end.on_table:
                end.s, end.se, end.source = _fit.line_plane_parameter(p0, t, end.n, end.d), 2e-4, "table"
                known[k] = True
            elif geo.has_sides:
                known[k] = self._fit_side(end, P, cam, side, p0, t, first)
        if all(known):
            return
        # Face A's support along t; a known end's neighbourhood is cut away (A's side face shows up there),
        # which only shifts the CDF by a constant and leaves the other end's extrapolation unbiased.
        near_a = (np.abs(r_a) < 2.5 * face_a.scale) & (r_b >= band_b) & (r_b <= o.tube_radius_m) & above
        cut = o.edge_band_m + 3.0 * face_a.scale
        if known[0]:
            near_a &= s > ends[0].s + cut
        if known[1]:
            near_a &= s < ends[1].s - cut
        extent = _fit.cdf_extent(s[near_a]) if np.count_nonzero(near_a) >= o.min_face_points else None
        for k, end in enumerate(ends):
            if known[k]:
                continue
            if extent is not None:
                # Refine the CDF's extrapolation by the edge's own sharpness (blurred-step likelihood).
                sign = 1.0 if k == 1 else -1.0
                edge, se = _fit.edge_ml(sign * s[near_a], sign * extent[k])
                if np.isfinite(se):
                    # The curvature understates the scatter of a blurred edge: no better than 3 spacings.
                    density = np.count_nonzero(near_a) / max(extent[1] - extent[0], 1e-3)  # [1/m]
                    end.s, end.se, end.source = sign * edge, max(se, 3.0 / density), "extent"
                else:
                    end.s, end.se, end.source = extent[k], extent[2], "extent"
            else:
                end.s, end.se, end.source = s_map[k], o.map_tolerance_m, "map"

    def _fit_side(
        self,
        end: _End,
        P: FloatArray,
        cam: npt.NDArray[np.intp],
        side: BoolArray,
        p0: FloatArray,
        t: FloatArray,
        first: bool,
    ) -> bool:
        """Fit the offset of A's side face at ``end`` from the points on it; False when too few are seen."""
        o = self.options
        r_l = P @ end.n - end.d
        gate = (o.map_tolerance_m + 3.0 * o.sensor_sigma_m) if first else o.gate_sigmas * end.scale
        sel = side & (np.abs(r_l) < gate)
        count = int(np.count_nonzero(sel))
        if count < o.min_end_points:
            return False
        start = _fit.histogram_mode(r_l[sel], max(0.002, o.sensor_sigma_m)) if first else 0.0
        fit = _fit.robust_plane_fit(r_l[sel], np.ones((count, 1)), cam[sel], start)
        if fit.n_inliers < o.min_end_points:
            return False
        end.d += fit.offset
        end.scale = max(fit.scale, 1e-4)
        end.s = _fit.line_plane_parameter(p0, t, end.n, end.d)
        end.se = fit.se / max(abs(float(end.n @ t)), 1e-3)
        end.source = "side face"
        return True

    def _confidence(
        self,
        scene: SeamScene,
        face_a: _Face,
        face_b: _Face,
        ends: list[_End],
        p0: FloatArray,
        t: FloatArray,
        geo: _Geometry,
        s_map: list[float],
    ) -> float:
        """Confidence in [0, 1]: support vs the expected count, offset and end standard errors, noise."""
        o = self.options
        spacing = _fit.dense_spacing(scene)
        band_a = max(o.corner_band_m, 3.0 * face_a.scale)
        band_b = max(o.corner_band_m, 3.0 * face_b.scale)
        length = max(ends[1].s - ends[0].s - 2.0 * o.edge_band_m, 1e-3)
        area_a = length * max(o.tube_radius_m - band_b, 1e-3)
        area_b = geo.face_b_area(p0, t, face_a, face_b, ends, band_a, o.tube_radius_m, s_map, o.extend_m)
        support = 1.0
        if np.isfinite(spacing) and spacing > 0.0:
            expect_a, expect_b = area_a / spacing**2, max(area_b, 1e-6) / spacing**2
            support = min(1.0, face_a.count / expect_a, face_b.count / expect_b)
        sin_ab = float(np.linalg.norm(np.cross(face_a.n, face_b.n)))
        se_lat = float(np.hypot(face_a.se, face_b.se)) / max(sin_ab, 0.1)
        se_end = max(ends[0].se, ends[1].se)
        noise = min(1.0, 2.0 * o.sensor_sigma_m / max(face_a.scale, face_b.scale))
        conf = (
            np.sqrt(support)
            / (1.0 + (se_lat / o.target_se_m) ** 2)
            / (1.0 + (se_end / (4.0 * o.target_se_m)) ** 2)
            * np.sqrt(noise)
        )
        return float(np.clip(conf, 0.0, 1.0))


@dataclass(frozen=True)
class _Geometry:
    """What the map says about the joint's boxes, for region tests (frame R)."""

    box_a: Box
    box_b: Box
    depth_a: float  # A's thickness below its weld face [m]
    side_axis: int  # A's box axis across the seam's ends (-1: none: the seam is not across A's faces)
    b_axes: tuple[int, int]  # B's in-plane box axes of the receiving face
    edge_band: float

    @staticmethod
    def of(box_a: Box, box_b: Box, joint: Joint, t: FloatArray, edge_band: float) -> _Geometry:
        k_a = "xyz".index(joint.face_abutting[1])
        R_A = box_a.X_AB[:3, :3]
        cand = [k for k in range(3) if k != k_a]
        k_t = max(cand, key=lambda k: abs(float(R_A[:, k] @ t)))
        side_axis = k_t if abs(float(R_A[:, k_t] @ t)) > np.cos(np.radians(30.0)) else -1
        k_b = "xyz".index(joint.face_receiving[1])
        b_axes = tuple(k for k in range(3) if k != k_b)
        return _Geometry(box_a, box_b, float(box_a.size[k_a]), side_axis, (b_axes[0], b_axes[1]), edge_band)

    @property
    def has_sides(self) -> bool:
        return self.side_axis >= 0

    def end_planes(self, t: FloatArray, table_z: float, tol: float) -> list[_End]:
        """Planes of A's side faces at the start and the end of the seam (direction t; outward normals); the
        table instead of a side face that rests on it."""
        R_A = self.box_a.X_AB[:3, :3]
        k = max(self.side_axis, 0)
        h = 0.5 * float(self.box_a.size[k])
        c = self.box_a.center
        axis = R_A[:, k] if float(R_A[:, k] @ t) >= 0.0 else -R_A[:, k]
        out = []
        for sign in (-1.0, 1.0):
            n = sign * axis
            d = float(n @ c) + h
            on_table = self.has_sides and float(n @ _Z) < -0.9 and abs(d + table_z) < tol
            out.append(_End(-_Z, -table_z, True) if on_table else _End(n, d, False))
        return out

    def in_face_b(self, P: FloatArray) -> BoolArray:
        """Points whose projection lies inside B's receiving face shrunk by the edge band."""
        q = (P - self.box_b.center) @ self.box_b.X_AB[:3, :3]
        ok = np.ones(len(P), bool)
        for j in self.b_axes:
            ok &= np.abs(q[:, j]) <= 0.5 * float(self.box_b.size[j]) - self.edge_band
        return ok

    def face_b_area(
        self,
        p0: FloatArray,
        t: FloatArray,
        face_a: _Face,
        face_b: _Face,
        ends: list[_End],
        band_a: float,
        radius: float,
        s_map: list[float],
        extend: float,
    ) -> float:
        """Area [m^2] of face B's support region inside the tube (counted on a 2 mm grid on B's plane)."""
        e_v = face_a.n - (face_a.n @ face_b.n) * face_b.n
        e_v /= np.linalg.norm(e_v)
        step = 0.002
        sv = np.arange(s_map[0] - extend, s_map[1] + extend, step)
        vv = np.arange(-radius, radius, step)
        S, V = np.meshgrid(sv, vv)
        G = p0 + np.outer(S.ravel(), t) + np.outer(V.ravel(), e_v)
        r_a = G @ face_a.n - face_a.d
        s = S.ravel()
        e0, e1 = ends[0].s, ends[1].s
        keep = self.in_face_b(G) & ~(
            (r_a < band_a) & (r_a > -self.depth_a - band_a) & (s > e0 - band_a) & (s < e1 + band_a)
        )
        return float(np.count_nonzero(keep)) * step * step


def _joint_of(scene: SeamScene, seam: MapSeam) -> Joint:
    joint = scene.joints.get(seam.id)
    if joint is None:
        raise MapError(
            f"seam {seam.id} has no joint (abutting/receiving parts and faces); joints known for: "
            f"{', '.join(sorted(scene.joints)) or 'none'}"
        )
    return joint


def _against_table(n_a: FloatArray, n_b: FloatArray, seam: MapSeam, table_z: float, tol: float) -> bool:
    """A seam on a downward face, at the table's height: no camera can see it."""
    low = max(float(seam.p_start[2]), float(seam.p_end[2])) < table_z + tol
    return low and min(float(n_a @ _Z), float(n_b @ _Z)) < -0.7


def _not_found(seam_id: str, reason: str) -> SeamEstimate:
    return SeamEstimate(seam_id, SeamStatus.NOT_FOUND, reason=reason)
