"""Our map-guided seam locator: fit the two weld faces near the map's seam, intersect them, find the ends.

Method (general: no assumption that a seam runs along x, y or z):

1. From the aligned map: the weld faces, A's ``face_abutting`` (n_a, d_a) and B's ``face_receiving`` (n_b,
   d_b), the seam line where they meet with its direction t, and A's side faces across t (where the seam
   ends).
2. Points in a tube around the map seam, from a fixed share (``sample_share``: every k-th point of each voxel)
   of ``scene.dense`` (:class:`~cell.seams._fit.CloudIndex`, on the voxel table perception hands on: thousands
   of points per face are plenty for a sub-0.1 mm offset); points within a band of any other part of the map
   are left out, so neighbouring parts never lend a face their points. Point counts that decide whether a face
   is seen (``min_face_points``) are the dense cloud's.
3. Face A's support: points near A's plane, away from B's face by a corner band (gap, shadow and corner noise
   live there), inside A's extent along t less an edge band (flying pixels on convex edges), above the table.
   Face B's support: points near B's plane inside B's face less an edge band, outside the footprint of A grown
   by the band. A's side faces across the seam (where it ends) likewise. All of them are fitted at once
   (:func:`~cell.seams._batch.fit_offsets`): each plane's offset along the map's normal by iteratively
   reweighted least squares (Tukey biweight), each camera weighted by its own measured noise on that face.
   ``passes`` passes: the first from the map with wide gates (from each face's densest layer), the others with
   gates and bands from the measured noise and the ends found. In the last pass (``refine_normals``) the weld
   faces may tilt a little, held near the map's normal by a Gaussian prior (as-built parts are rotated by
   hundredths of a degree, not degrees): one weighted least-squares step with the fit's weights.
4. A weld face no camera sees (too oblique, occluded) is placed from the edge where an adjacent face of the
   same part ends (:mod:`cell.seams._edge`): the extent of that face's points across the edge (a blurred-step
   likelihood), searched as far from the map as a fitted face may drift, each camera's edge on its own (from
   ``edge_sample_share`` of the dense cloud: an edge needs density). A camera's edge counts only when enough
   points define it, it is not blurred beyond the likelihood's widest blur (grazing incidence), few points lie
   beyond it (flying pixels), and it is neither at the searched range's limit nor where the cloud stops (the
   sample's own cut-off, not an edge). Its standard error: the likelihood's and the sampling pitch of the face
   (``edge_pitch_factor``); the cameras' edges are combined by inverse variance, the error inflated when they
   disagree beyond it (Birge ratio). With no such edge, the seam is NOT_FOUND naming the face and why.
5. The seam line is the intersection of the fitted planes. Each end is where the line meets A's side face
   across it, fitted from that face's points when it is seen, the table when A rests on it there, or else the
   extent of face A's support along t (its empirical CDF extrapolated, then refined by the same edge
   likelihood on every dense point about it). An extent end where the cloud stops (the workspace crop:
   ``workspace_R``, or the cloud's bounds along R's axes) is not an end: the seam is NOT_FOUND.
6. Confidence from the standard errors of the fitted offsets (an edge-placed face: its edge's) and ends
   (:class:`SeamErrors`, :meth:`OursLocator.locate_with_errors`), each face's support and the residual scale.

The seams of a scene are found together (:meth:`OursLocator.locate_many`): each seam's steps are as above, but
every plane fit of a pass, and every tilt step, is one vectorised fit for all the seams (numpy costs about the
same per call whatever the size: on the 156-seam ladder, 1.38 ms for the median seam alone, 0.94 ms per seam
together; benchmarks/bench_scaling.py).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Generator, Sequence
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from cell.errors import MapError
from cell.geometry import FloatArray
from cell.seams import _batch, _edge, _fit
from cell.seams.base import Joint, SeamScene
from cell.types import Box, MapSeam, SeamEstimate, SeamStatus

BoolArray = npt.NDArray[np.bool_]
_SPHERES_KEY = "cell.seams.ours.part_spheres"
SUPPORT_FULL_MARKS = 0.4  # share of a well-seen surface's points on a face that earns full confidence
IntArray = npt.NDArray[np.intp]
_Z = np.array([0.0, 0.0, 1.0])


@dataclass(frozen=True)
class OursOptions:
    """Options of :class:`OursLocator` (defaults suit RealSense D4xx-class clouds at 1-2 m); lengths [m]."""

    tube_radius_m: float = 0.06  # points within this distance of the map seam are looked at
    extend_m: float = 0.02  # ... and this far past the map's ends
    corner_band_m: float = 0.005  # least band excluded next to the other weld face (gap, shadow, corner noise)
    edge_band_m: float = 0.004  # band excluded along convex edges (flying pixels, side faces)
    map_tolerance_m: float = 0.006  # how far the as-built faces and ends may lie from the aligned map
    sensor_sigma_m: float = 0.003  # depth noise assumed before it is measured
    gate_sigmas: float = 3.5  # half-width of the gate around a plane, in measured noise scales
    passes: int = 2  # fits: the first from the map with wide gates, the others with measured noise and ends
    min_face_points: int = 30  # fewer supporting points (dense cloud's) on a weld face: place it from an edge
    min_end_points: int = 40  # fewer points on a side face of A: take the end from the extent instead
    min_end_fill: float = 0.04  # ... or fewer than this fraction of the points its area would hold seen well
    refine_normals: bool = True  # let a face tilt off the map's normal in the last pass (as-built parts tilt)
    tilt_prior_deg: float = 0.05  # ... standard deviation of the tilt's Gaussian prior [deg]
    sample_share: float = 0.25  # share of the dense cloud looked at (layers of _fit.INDEX_SHARES: 0.25, 0.5 or 1)
    edge_sample_share: float = 1.0  # ... where an unseen face is placed from an edge (an edge needs every point)
    max_points: int = 40000  # random subsample of the tube above this
    max_fit_points: int = 1000  # a plane is fitted to an even stride of its support above this
    target_se_m: float = 0.0002  # standard error of the seam's position that still earns full confidence
    min_edge_points: int = 20  # fewer points just inside an edge: it does not place an unseen face
    max_edge_strays: float = 0.3  # more density beyond an edge (share of that inside): it places nothing
    edge_pitch_factor: float = 0.15  # an edge's sampling error, in point pitches on its face [-] (0.29: aligned grid)
    workspace_R: Box | None = None  # where the cloud was cropped (frame R); None: the cloud's bounds along R's axes

    def __post_init__(self) -> None:
        if self.passes < 1 or self.min_face_points < 3 or self.min_end_points < 3 or self.min_edge_points < 3:
            raise ValueError(
                "ours options need passes >= 1, min_face_points >= 3, min_end_points >= 3 and min_edge_points >= 3"
            )
        if self.sample_share not in _fit.INDEX_SHARES or self.edge_sample_share not in _fit.INDEX_SHARES:
            raise ValueError(f"ours options need sample_share and edge_sample_share among {_fit.INDEX_SHARES}")
        if self.tube_radius_m <= self.corner_band_m or self.tilt_prior_deg <= 0.0:
            raise ValueError("ours options need tube_radius_m > corner_band_m and tilt_prior_deg > 0")


@dataclass(frozen=True)
class SeamErrors:
    """Standard errors [m] of a seam found by :class:`OursLocator` (what its confidence is computed from).

    lateral_m : of the seam line across itself (from the two faces' offsets).
    start_m, end_m : of the ends along the line.
    face_a_m, face_b_m : of the offsets of A's and B's weld faces (an edge-placed face: its edge's).
    """

    lateral_m: float
    start_m: float
    end_m: float
    face_a_m: float
    face_b_m: float


NO_ERRORS = SeamErrors(*(5 * (float("inf"),)))  # a seam not found


@dataclass
class _Face:
    """A plane being fitted: unit normal n (3,), offset d [m], noise scale [m], offset standard error [m]."""

    n: FloatArray
    d: float
    scale: float
    name: str
    se: float = float("inf")
    count: int = 0
    source: str = "points"  # or "edge of <face>" (an adjacent face of the same part)
    area: float = 0.0  # area of its support region [m^2] (what a head-on view would fill with points)
    note: str = ""  # how well an edge placed it (for the reason)


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


@dataclass
class _Selection:
    """A plane's support for one fit: the plane (a weld face or a side face at an end), the residuals r (n,) of
    all the seam's points from it [m], the indices of its support and of the points fitted (an even stride of
    the support above ``max_fit_points``), the points it needs; after the fit: whether it was fitted, the
    offset it moved by [m], the offset's standard error [m] and the fitted points' weights."""

    plane: _Face | _End
    r: FloatArray
    sel: IntArray
    fit: IntArray
    need: int = 0
    ok: bool = False
    offset: float = 0.0
    se: float = float("inf")
    weights: FloatArray = field(default_factory=lambda: np.zeros(0))


@dataclass
class _Points:
    """The points looked at for one seam: coordinates xyz (3, n) [m], camera index (n,), usable mask (n,)."""

    xyz: FloatArray
    cam: IntArray
    ok: BoolArray  # above the table and away from every other part
    pitch: float  # point pitch of these points on a well-seen surface [m] (the sample's, thinned)
    share: float  # the share of the dense cloud's points these are
    n_cams: int  # camera indices run 0 .. n_cams - 1
    _along: dict[bytes, FloatArray] = field(default_factory=dict)

    def least(self, dense_points: int) -> int:
        """How many of these points stand for ``dense_points`` of the dense cloud (at least 3)."""
        return max(3, math.ceil(dense_points * self.share))

    def along(self, n: FloatArray) -> FloatArray:
        """P @ n (n,) [m], computed once per direction (most planes keep the map's normal)."""
        key = np.asarray(n, np.float64).tobytes()
        out = self._along.get(key)
        if out is None:
            out = self._along[key] = n @ self.xyz
        return out

    @property
    def P(self) -> FloatArray:
        """The points (n, 3) [m]."""
        return self.xyz.T


class OursLocator:
    """Map-guided plane-fit seam locator (see the module docstring). Deterministic for a given ``rng``."""

    name: str = "ours"

    def __init__(self, options: OursOptions | None = None) -> None:
        self.options = options if options is not None else OursOptions()

    def locate(self, scene: SeamScene, seam: MapSeam, rng: np.random.Generator) -> SeamEstimate:
        """Find ``seam`` (frame R) in ``scene.dense`` (see the module docstring); MapError for a bad joint."""
        return self.locate_many_with_errors(scene, [seam], rng)[0][0]

    def locate_with_errors(
        self, scene: SeamScene, seam: MapSeam, rng: np.random.Generator
    ) -> tuple[SeamEstimate, SeamErrors]:
        """:meth:`locate`, and the standard errors behind the estimate's confidence (all inf unless FOUND)."""
        return self.locate_many_with_errors(scene, [seam], rng)[0]

    def locate_many(self, scene: SeamScene, seams: Sequence[MapSeam], rng: np.random.Generator) -> list[SeamEstimate]:
        """:meth:`locate` every seam of ``seams``, together (see :meth:`locate_many_with_errors`)."""
        return [est for est, _ in self.locate_many_with_errors(scene, seams, rng)]

    def locate_many_with_errors(
        self, scene: SeamScene, seams: Sequence[MapSeam], rng: np.random.Generator
    ) -> list[tuple[SeamEstimate, SeamErrors]]:
        """:meth:`locate_with_errors` for every seam of ``seams``, in lock-step: each seam's steps run as they
        would alone, but the plane fits of a pass (and the tilt steps) are one batched fit for all the seams,
        so that numpy's cost per call is paid once per pass, not once per seam. Each seam draws from its own
        generator spawned from ``rng``, in the order given."""
        runs = [self._run(scene, seam, r) for seam, r in zip(seams, rng.spawn(len(seams)), strict=True)]
        out: list[tuple[SeamEstimate, SeamErrors] | None] = [None] * len(runs)
        pending: dict[int, _FitRequest] = {}

        def advance(i: int) -> None:
            try:
                pending[i] = next(runs[i])
            except StopIteration as stop:
                out[i] = stop.value

        for i in range(len(runs)):
            advance(i)
        while pending:
            batch = list(pending.items())
            pending.clear()
            for first in (True, False):
                self._fit_planes([req for _, req in batch if req.first is first], first)
            self._tilt([(x, face, other, req.pts, p0, t) for _, req in batch for x, face, other, p0, t in req.tilts])
            for i, _ in batch:
                advance(i)
        return [x for x in out if x is not None]

    def _run(
        self, scene: SeamScene, seam: MapSeam, rng: np.random.Generator
    ) -> Generator[_FitRequest, None, tuple[SeamEstimate, SeamErrors]]:
        """The steps of :meth:`locate_with_errors` for one seam: yields each pass's plane fits (and tilt steps)
        for :meth:`locate_many_with_errors` to do, returns the estimate and its standard errors."""
        o = self.options
        joint = _joint_of(scene, seam)
        box_a = scene.weldmap.part(joint.abutting).box
        box_b = scene.weldmap.part(joint.receiving).box
        n_a, d_a = box_a.face_plane(joint.face_abutting)
        n_b, d_b = box_b.face_plane(joint.face_receiving)
        mid = 0.5 * (seam.p_start + seam.p_end)
        try:
            p0, t = _line(n_a, d_a, n_b, d_b, mid, seam.direction)
        except ValueError:
            raise MapError(
                f"seam {seam.id}: faces {joint.abutting} {joint.face_abutting} and {joint.receiving} "
                f"{joint.face_receiving} are parallel; a joint needs two faces that meet in a line"
            ) from None
        if _against_table(n_a, n_b, seam, scene.table_z, o.map_tolerance_m):
            return SeamEstimate(seam.id, SeamStatus.NOT_VISIBLE, "the seam lies against the table"), NO_ERRORS

        pts = self._points(scene, seam.p_start, seam.p_end, o.tube_radius_m, o.extend_m, joint, rng)

        def dense(a: FloatArray, b: FloatArray) -> _Points:
            """The tube about a-b (3,) from ``edge_sample_share`` of the cloud (an end found as an edge needs
            density)."""
            return self._points(scene, a, b, o.tube_radius_m, 0.0, joint, rng, o.edge_sample_share)

        geo = _Geometry.of(box_a, box_b, joint, t, o.edge_band_m)
        s_map = sorted((float(t @ (seam.p_start - p0)), float(t @ (seam.p_end - p0))))
        face_a = _Face(n_a, d_a, o.sensor_sigma_m, f"{joint.abutting} {joint.face_abutting}")
        face_b = _Face(n_b, d_b, o.sensor_sigma_m, f"{joint.receiving} {joint.face_receiving}")
        ends = geo.end_planes(t, scene.table_z, o.map_tolerance_m)
        ends[0].s, ends[1].s = s_map

        for it in range(o.passes):
            first, last = it == 0, it == o.passes - 1
            p0, t = _line(face_a.n, face_a.d, face_b.n, face_b.d, mid, seam.direction)
            r_a = pts.along(face_a.n) - face_a.d
            r_b = pts.along(face_b.n) - face_b.d
            s = pts.along(t) - float(p0 @ t)
            slack = o.map_tolerance_m if first else 0.0
            band_a = max(o.corner_band_m, 3.0 * face_a.scale) + slack
            band_b = max(o.corner_band_m, 3.0 * face_b.scale) + slack
            e0, e1 = ends[0].s, ends[1].s
            eb = o.edge_band_m + (slack if first else min(max(ends[0].se, ends[1].se), o.map_tolerance_m))
            in_a = (r_b >= band_b) & (r_b <= geo.length_a - eb) & (s >= e0 + eb) & (s <= e1 - eb) & pts.ok
            in_b = (
                geo.in_face_b(pts, slack)
                & ~((r_a < band_a) & (r_a > -geo.depth_a - band_a) & (s > e0 - band_a) & (s < e1 + band_a))
                & pts.ok
            )
            planes: list[_Selection] = []
            for face, r, region, box, face_name, skip in (
                (face_a, r_a, in_a, box_a, joint.face_abutting, joint.end_face),
                (face_b, r_b, in_b, box_b, joint.face_receiving, ""),
            ):
                if face.source != "points":
                    continue  # placed from an edge in the first pass
                gate = (o.map_tolerance_m + 3.0 * o.sensor_sigma_m) if first else o.gate_sigmas * face.scale
                sel = np.flatnonzero(region & (np.abs(r) < gate))
                if len(sel) >= pts.least(o.min_face_points):
                    planes.append(_Selection(face, r, sel, _thin(sel, o.max_fit_points)))
                    continue
                why = "no edge of it is seen either: not seen or not there"
                if first:
                    # Where an adjacent face of the same part may show this face's edge: away from the other part.
                    away = _away_from(face_b, band_b) if face is face_a else _outside(box_a, band_a)
                    why = self._face_from_edge(scene, face, box, face_name, skip, seam, joint, away, rng)
                    if not why:
                        continue
                return _not_found(
                    seam.id,
                    f"face {face.name} is seen by no usable camera ({len(sel)} points near the seam in a "
                    f"{pts.share:.0%} sample, needs {pts.least(o.min_face_points)}) and {why}",
                )
            sides = self._side_selections(ends, pts, r_a, r_b, face_b, geo, first, slack)
            tilts = []
            if last and o.refine_normals:
                for sel_ in planes:
                    face, other = (face_a, face_b) if sel_.plane is face_a else (face_b, face_a)
                    tilts.append((sel_, face, other, p0, t))
            yield _FitRequest(planes + sides, pts, first, tilts)
            # Support regions' areas, for the confidence: A's strip between its ends, B's strip beside A.
            face_a.area = max(e1 - e0 - 2.0 * eb, 0.0) * max(min(o.tube_radius_m, geo.length_a) - band_b - eb, 0.0)
            face_b.area = (e1 - e0 + 2.0 * o.extend_m) * max(o.tube_radius_m - band_a, 0.0)
            p0, t = _line(face_a.n, face_a.d, face_b.n, face_b.d, mid, seam.direction)
            # p0 lies on both fitted planes: its distance from a map plane is how far that face moved.
            for drift, name in ((abs(float(n_a @ p0) - d_a), face_a.name), (abs(float(n_b @ p0) - d_b), face_b.name)):
                if drift > 2.0 * o.map_tolerance_m:
                    return _not_found(
                        seam.id,
                        f"face {name} fitted {drift * 1000:.1f} mm from the map "
                        f"(allowed {2000 * o.map_tolerance_m:.1f} mm): wrong surface or part moved",
                    )
            self._find_ends(ends, sides, pts, dense if last else None, face_a, face_b, p0, t, s_map)

        length = ends[1].s - ends[0].s
        if not 0.3 * (s_map[1] - s_map[0]) < length < 2.0 * (s_map[1] - s_map[0]) + 2.0 * o.extend_m:
            return _not_found(
                seam.id,
                f"seam length {length * 1000:.1f} mm found, the map says {(s_map[1] - s_map[0]) * 1000:.1f} mm",
            )
        crop = self._crop_box(scene)
        for k, end in enumerate(ends):
            if end.source == "extent" and _edge.at_cut(crop, p0 + end.s * t, t if k == 1 else -t, 0.0, o.edge_band_m):
                return _not_found(
                    seam.id,
                    f"the seam's {('start', 'end')[k]} is not seen: face {face_a.name}'s points run to where the "
                    "cloud stops (the workspace's boundary): the part reaches out of the workspace",
                )
        errors = _errors_of(face_a, face_b, ends)
        conf = self._confidence(face_a, face_b, errors, pts.pitch)
        via = [f"face {f.name} from the {f.source} ({f.note})" for f in (face_a, face_b) if f.source != "points"]
        estimate = SeamEstimate(
            id=seam.id,
            status=SeamStatus.FOUND,
            reason="; ".join([f"ends from {ends[0].source} / {ends[1].source}", *via]),
            p_start=p0 + ends[0].s * t,
            p_end=p0 + ends[1].s * t,
            confidence=conf,
        )
        return estimate, errors

    # -- steps ------------------------------------------------------------------------------------------

    def _points(
        self,
        scene: SeamScene,
        a: FloatArray,
        b: FloatArray,
        radius: float,
        extend: float,
        joint: Joint,
        rng: np.random.Generator,
        share: float | None = None,
    ) -> _Points:
        """The dense cloud's points in the tube of ``radius`` around the segment a-b (3,) extended by
        ``extend`` [m], and which of them may support a plane (above the table, away from other parts); from
        the sample of ``share`` of the dense cloud (None: ``sample_share``)."""
        o = self.options
        index = _fit.dense_index(scene)
        share = o.sample_share if share is None else share
        xyz, cam = index.tube(a, b, radius, extend, share)
        kept = 1.0
        if len(cam) > o.max_points:
            kept = o.max_points / len(cam)
            pick = np.sort(rng.choice(len(cam), o.max_points, replace=False))
            xyz, cam = xyz[:, pick], cam[pick]
        cam = np.where(cam < 0, int(cam.max(initial=0)) + 1, cam)  # mixed / unknown captures: their own group
        ok = xyz[2] >= scene.table_z + o.corner_band_m
        reach = radius + extend + 0.5 * float(np.linalg.norm(b - a)) + o.map_tolerance_m
        centres, radii = _part_spheres(scene)
        near = np.linalg.norm(centres - 0.5 * (a + b), axis=1) <= reach + radii
        for k in np.flatnonzero(near):
            part = scene.weldmap.parts[k]
            if part.name in (joint.abutting, joint.receiving):
                continue
            R, c = part.box.X_AB[:3, :3], part.box.center
            q = R.T @ xyz - (R.T @ c)[:, None]  # in the part's frame
            h = 0.5 * part.box.size + o.map_tolerance_m
            ok &= (np.abs(q[0]) > h[0]) | (np.abs(q[1]) > h[1]) | (np.abs(q[2]) > h[2])
        return _Points(xyz, cam, ok, index.pitch(share * kept), share * kept, int(cam.max(initial=0)) + 1)

    def _face_from_edge(
        self,
        scene: SeamScene,
        face: _Face,
        box: Box,
        face_name: str,
        skip: str,
        seam: MapSeam,
        joint: Joint,
        away: Callable[[FloatArray], BoolArray],
        rng: np.random.Generator,
    ) -> str:
        """Place an unseen ``face`` of ``box`` from an edge (:func:`_edge.place_from_edge`, on
        ``edge_sample_share`` of the cloud); ``away`` masks the points (n, 3) far enough from the joint's other
        part. Returns "" when placed (``face`` updated, its standard error from the edge's own data), else why
        not."""
        o = self.options

        def points(a: FloatArray, b: FloatArray, radius: float) -> tuple[FloatArray, IntArray, BoolArray]:
            pts = self._points(scene, a, b, radius, 0.0, joint, rng, o.edge_sample_share)
            return pts.P, pts.cam, pts.ok

        placed = _edge.place_from_edge(
            face.n,
            face.d,
            box,
            face_name,
            skip,
            (seam.p_start, seam.p_end),
            scene.table_z,
            away,
            points,
            self._crop_box(scene),
            o,
        )
        if isinstance(placed, str):
            return placed
        face.d += placed.b
        face.se, face.scale, face.count = placed.se, placed.scale, placed.count
        face.source = f"edge of {placed.g}"
        face.note = f"+-{1000 * placed.se:.2f} mm, {placed.cameras} camera{'s' if placed.cameras != 1 else ''}"
        return ""

    def _crop_box(self, scene: SeamScene) -> Box:
        """Where the cloud was cropped: the workspace (in R) when the options give it, else the cloud's bounds."""
        ws = self.options.workspace_R
        return ws if ws is not None else _fit.cloud_box(scene)

    def _find_ends(
        self,
        ends: list[_End],
        sides: list[_Selection],
        pts: _Points,
        dense: Callable[[FloatArray, FloatArray], _Points] | None,
        face_a: _Face,
        face_b: _Face,
        p0: FloatArray,
        t: FloatArray,
        s_map: list[float],
    ) -> None:
        """Update both ends on the fitted line p0 + s t: the table where A rests on it, A's side face where it
        was fitted, else the extent of face A's support along the seam: the quantiles of its points in ``pts``
        extrapolated, then refined as an edge in the ``dense`` points of a short tube about it (None: not
        refined, as in a pass before the last)."""
        o = self.options
        fitted = {id(x.plane): x for x in sides if x.ok}
        known = [False, False]
        for k, end in enumerate(ends):
            side = fitted.get(id(end))
            if end.on_table:
                end.s, end.se, end.source = _fit.line_plane_parameter(p0, t, end.n, end.d), 2e-4, "table"
                known[k] = True
            elif side is not None:
                end.s = _fit.line_plane_parameter(p0, t, end.n, end.d)
                end.se = side.se / max(abs(float(end.n @ t)), 1e-3)
                end.source = "side face"
                known[k] = True
        if all(known) or face_a.source != "points":
            for k, end in enumerate(ends):
                if not known[k]:
                    end.s, end.se, end.source = s_map[k], o.map_tolerance_m, "map"
            return
        # Face A's support along t; a known end's neighbourhood is cut away (A's side face shows up there),
        # which only shifts the CDF by a constant and leaves the other end's extrapolation unbiased.
        band_b = max(o.corner_band_m, 3.0 * face_b.scale)
        cut = o.edge_band_m + 3.0 * face_a.scale

        def along_a(pts: _Points) -> FloatArray:
            """The parameters along the line of the points of face A's support among ``pts``."""
            r_a = pts.along(face_a.n) - face_a.d
            r_b = pts.along(face_b.n) - face_b.d
            s = pts.along(t) - float(p0 @ t)
            near_a = (np.abs(r_a) < 2.5 * face_a.scale) & (r_b >= band_b) & (r_b <= o.tube_radius_m) & pts.ok
            if known[0]:
                near_a &= s > ends[0].s + cut
            if known[1]:
                near_a &= s < ends[1].s - cut
            return s[near_a]

        s_a = along_a(pts)
        extent = _fit.cdf_extent(s_a) if len(s_a) >= pts.least(o.min_face_points) else None
        for k, end in enumerate(ends):
            if known[k]:
                continue
            if extent is None:
                end.s, end.se, end.source = s_map[k], o.map_tolerance_m, "map"
            elif dense is None:
                end.s, end.se, end.source = extent[k], extent[2], "extent"
            else:
                # Refine the CDF's extrapolation by the edge's own sharpness (blurred-step likelihood), on every
                # point of the dense cloud within the likelihood's window about it.
                sign = 1.0 if k == 1 else -1.0
                reach = _fit.EDGE_WINDOW_M + o.edge_band_m
                s_d = along_a(dense(p0 + (extent[k] - reach) * t, p0 + (extent[k] + reach) * t))
                edge, se = _fit.edge_ml(sign * s_d, sign * extent[k])
                if np.isfinite(se):
                    # The curvature understates the scatter of a blurred edge: no better than 3 spacings.
                    inside = np.count_nonzero(np.abs(s_d - extent[k]) < _fit.EDGE_WINDOW_M)
                    density = inside / (2.0 * _fit.EDGE_WINDOW_M)  # [1/m]
                    end.s, end.se, end.source = sign * edge, max(se, 3.0 / max(density, 1.0)), "extent"
                else:
                    end.s, end.se, end.source = extent[k], extent[2], "extent"

    def _side_selections(
        self,
        ends: list[_End],
        pts: _Points,
        r_a: FloatArray,
        r_b: FloatArray,
        face_b: _Face,
        geo: _Geometry,
        first: bool,
        slack: float,
    ) -> list[_Selection]:
        """The points on A's side faces at the seam's ends (where they are seen well enough to place an end),
        to be fitted with the weld faces."""
        o = self.options
        if not geo.has_sides:
            return []
        band_b = max(o.corner_band_m, 3.0 * face_b.scale) + slack
        eb = o.edge_band_m + slack
        side = (r_a < -eb) & (r_a > -(geo.depth_a - eb)) & (r_b >= band_b) & (r_b <= geo.length_a - eb) & pts.ok
        # A side face seen at all shows a good part of the points its patch would hold seen well; a few
        # dozen flying pixels off an edge (a face seen at grazing incidence drops out) must not pass for it.
        patch = (min(geo.depth_a, o.tube_radius_m) - 2.0 * o.edge_band_m) * (
            min(geo.length_a, o.tube_radius_m) - band_b - o.edge_band_m
        )
        need = max(o.min_end_points, int(o.min_end_fill * max(patch, 0.0) / pts.pitch**2))
        out = []
        for end in ends:
            if end.on_table:
                continue
            r_l = pts.along(end.n) - end.d
            gate = (o.map_tolerance_m + 3.0 * o.sensor_sigma_m) if first else o.gate_sigmas * end.scale
            sel = np.flatnonzero(side & (np.abs(r_l) < gate))
            if len(sel) >= need:
                out.append(_Selection(end, r_l, sel, _thin(sel, o.max_fit_points), need))
        return out

    def _fit_planes(self, requests: list[_FitRequest], first: bool) -> None:
        """Fit the offsets of every plane selected by ``requests`` (of one or several seams) at once
        (:func:`_batch.fit_offsets`; the first pass from a histogram mode with its scales measured again once
        settled, the later ones from the previous fit) and update them. A side face whose fit keeps fewer
        points than it needs stays unfitted."""
        o = self.options
        selections = [x for req in requests for x in req.selections]
        if not selections:
            return
        fit = _batch.fit_offsets(
            np.concatenate([x.r[x.fit] for x in selections]),
            [len(x.fit) for x in selections],
            np.concatenate([req.pts.cam[x.fit] for req in requests for x in req.selections]),
            max(req.pts.n_cams for req in requests),
            start=None if first else np.zeros(len(selections)),
            mode_half_width=o.map_tolerance_m + 3.0 * o.sensor_sigma_m,
            mode_bin=max(0.002, o.sensor_sigma_m),
            rescale_after=3 if first else 0,
        )
        at = 0
        for j, x in enumerate(selections):
            weights = fit.weights[at : at + len(x.fit)]
            at += len(x.fit)
            if int(fit.count[j]) < min(x.need, len(x.fit)):
                continue
            x.ok, x.offset, x.weights = True, float(fit.offset[j]), weights
            x.se = float(fit.se[j]) * np.sqrt(len(x.fit) / len(x.sel))  # the stride stands for all the support
            x.plane.d += x.offset
            x.plane.scale = max(float(fit.scale[j]), 1e-4)
            if isinstance(x.plane, _Face):
                x.plane.se, x.plane.count = x.se, len(x.sel)

    def _tilt(self, jobs: list[tuple[_Selection, _Face, _Face, _Points, FloatArray, FloatArray]]) -> None:
        """Let fitted weld faces tilt a little off their normals (a Gaussian prior of ``tilt_prior_deg``): one
        weighted least-squares step of offset and tilt about each face's points' centroid (decorrelated), with
        the biweight weights of its offset fit, carried to the seam line (:func:`_batch.tilt_fits`, all faces
        at once). A job: the face's selection, the face, the other weld face, its points, p0 (3,) and t (3,)
        of the line."""
        o = self.options
        todo, r, u, v, w = [], [], [], [], []
        for x, face, other, pts, p0, t in jobs:
            keep = x.weights > 0.0
            if not x.ok or np.count_nonzero(keep) < 4:
                continue
            idx = x.fit[keep]
            e_u = other.n - (other.n @ face.n) * face.n
            e_u /= np.linalg.norm(e_u)
            q = np.take(pts.xyz, idx, axis=1) - p0[:, None]
            todo.append((x, face, e_u, p0, t))
            r.append(x.r[idx] - x.offset)  # from the plane as fitted
            u.append(e_u @ q)
            v.append(t @ q)
            w.append(x.weights[keep])
        if not todo:
            return
        fit = _batch.tilt_fits(
            np.concatenate(r),
            np.concatenate(u),
            np.concatenate(v),
            np.concatenate(w),
            [len(ri) for ri in r],
            float(np.tan(np.radians(o.tilt_prior_deg))),
        )
        for j, (x, face, e_u, p0, t) in enumerate(todo):
            # The plane r = c0 + a (u - uc) + b (v - vc) in the face's normal and offset.
            c0, a, b = float(fit.c0[j]), float(fit.a[j]), float(fit.b[j])
            m = face.n - a * e_u - b * t
            norm = float(np.linalg.norm(m))
            face.d = (
                face.d + c0 - a * (float(fit.uc[j]) + float(e_u @ p0)) - b * (float(fit.vc[j]) + float(t @ p0))
            ) / norm
            face.n = m / norm
            face.se = float(fit.se0[j]) * np.sqrt(len(x.fit) / len(x.sel))

    def _confidence(self, face_a: _Face, face_b: _Face, errors: SeamErrors, spacing: float) -> float:
        """Confidence in [0, 1] from the standard errors of the line (lateral) and of the ends, the support of
        each face (its points against what a well-seen surface of its region at the cloud's point ``spacing``
        [m] would give; 40 % of that earns full marks) and the residual noise. A face placed from an edge enters by
        its edge's standard error (see :meth:`_face_from_edge`)."""
        o = self.options
        se_lat, se_end = errors.lateral_m, max(errors.start_m, errors.end_m)
        support = 1.0
        if np.isfinite(spacing) and spacing > 0.0:
            for f in (face_a, face_b):
                if f.source == "points":
                    expect = max(f.area, 1e-6) / spacing**2
                    support = min(support, f.count / (SUPPORT_FULL_MARKS * expect))
        noise = min(1.0, 2.0 * o.sensor_sigma_m / max(face_a.scale, face_b.scale))
        conf = (
            np.sqrt(support * noise)
            / (1.0 + (se_lat / o.target_se_m) ** 2)
            / (1.0 + (se_end / (4.0 * o.target_se_m)) ** 2)
        )
        return float(np.clip(conf, 0.0, 1.0))


@dataclass(frozen=True)
class _FitRequest:
    """What one seam's pass needs fitted: its planes' selections of ``pts``, whether it is the first pass, and
    the tilt steps to take after the fit (selection, face, the other weld face, p0 (3,) and t (3,) of the
    line)."""

    selections: list[_Selection]
    pts: _Points
    first: bool
    tilts: list[tuple[_Selection, _Face, _Face, FloatArray, FloatArray]]


@dataclass(frozen=True)
class _Geometry:
    """What the map says about the joint's boxes, for region tests (frame R)."""

    box_a: Box
    box_b: Box
    depth_a: float  # A's thickness below its weld face [m]
    length_a: float  # A's length away from B (along its end face's normal) [m]
    side_axis: int  # A's box axis across the seam's ends (-1: none: the seam is not across A's faces)
    k_b: int  # B's box axis normal to the receiving face
    edge_band: float

    @staticmethod
    def of(box_a: Box, box_b: Box, joint: Joint, t: FloatArray, edge_band: float) -> _Geometry:
        k_a = "xyz".index(joint.face_abutting[1])
        k_e = "xyz".index(joint.end_face[1])
        R_A = box_a.X_AB[:3, :3]
        cand = [k for k in range(3) if k != k_a]
        k_t = max(cand, key=lambda k: abs(float(R_A[:, k] @ t)))
        side_axis = k_t if abs(float(R_A[:, k_t] @ t)) > np.cos(np.radians(30.0)) else -1
        k_b = "xyz".index(joint.face_receiving[1])
        return _Geometry(box_a, box_b, float(box_a.size[k_a]), float(box_a.size[k_e]), side_axis, k_b, edge_band)

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
            on_table = self.has_sides and _edge.on_table(n, d, table_z, tol)
            out.append(_End(-_Z, -table_z, True) if on_table else _End(n, d, False))
        return out

    def in_face_b(self, pts: _Points, slack: float) -> BoolArray:
        """Points whose projection lies inside B's receiving face shrunk by the edge band (and ``slack``)."""
        ok = np.ones(len(pts.cam), bool)
        R_B, c_B = self.box_b.X_AB[:3, :3], self.box_b.center
        for j in range(3):
            if j != self.k_b:
                axis = R_B[:, j]
                half = 0.5 * float(self.box_b.size[j]) - self.edge_band - slack
                ok &= np.abs(pts.along(axis) - float(axis @ c_B)) <= half
        return ok


def _away_from(face: _Face, band: float) -> Callable[[FloatArray], BoolArray]:
    """A mask of points (n, 3) at least ``band`` [m] in front of ``face``."""
    return lambda P: np.asarray(P @ face.n - face.d >= band)


def _outside(box: Box, band: float) -> Callable[[FloatArray], BoolArray]:
    """A mask of points (n, 3) outside ``box`` grown by ``band`` [m]."""
    return lambda P: ~box.contains(P, margin=band)


def _thin(idx: IntArray, cap: int) -> IntArray:
    """An even stride of the indices ``idx`` leaving at most about ``cap`` of them (deterministic)."""
    return idx[:: len(idx) // cap] if len(idx) > 2 * cap else idx


def _line(
    n_a: FloatArray, d_a: float, n_b: FloatArray, d_b: float, near: FloatArray, direction: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """The line where two planes meet, nearest ``near``, directed along ``direction``; ValueError if
    parallel."""
    p0, t = _fit.plane_intersection(n_a, d_a, n_b, d_b, near)
    return p0, (t if float(t @ direction) >= 0.0 else -t)


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


def _part_spheres(scene: SeamScene) -> tuple[FloatArray, FloatArray]:
    """Centres (P, 3) and radii (P,) of the spheres around the map's parts [m], cached per scene."""
    out = scene.cache.get(_SPHERES_KEY)
    if out is None:
        parts = scene.weldmap.parts
        centres = np.array([p.box.center for p in parts]).reshape(-1, 3)
        radii = np.array([0.5 * float(np.linalg.norm(p.box.size)) for p in parts])
        out = scene.cache[_SPHERES_KEY] = (centres, radii)
    return out


def _errors_of(face_a: _Face, face_b: _Face, ends: list[_End]) -> SeamErrors:
    """The seam's standard errors from its faces' offsets and its ends (the line moves by the faces' offsets
    over the sine of the angle between them)."""
    sin_ab = float(np.linalg.norm(np.cross(face_a.n, face_b.n)))
    lateral = float(np.hypot(face_a.se, face_b.se)) / max(sin_ab, 0.1)
    return SeamErrors(lateral, ends[0].se, ends[1].se, face_a.se, face_b.se)


def _not_found(seam_id: str, reason: str) -> tuple[SeamEstimate, SeamErrors]:
    return SeamEstimate(seam_id, SeamStatus.NOT_FOUND, reason=reason), NO_ERRORS
