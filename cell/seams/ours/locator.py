"""Our map-guided seam locator's driver (the method: :mod:`cell.seams.ours`): each seam's steps as a coroutine
that yields its pass's plane fits, and the loop that runs the seams of a scene in lock-step, so that every fit of a
pass (and every tilt step) is one batched fit for all of them."""

from __future__ import annotations

from collections.abc import Generator, Sequence

import numpy as np

from cell.errors import MapError
from cell.geometry import FloatArray
from cell.seams._edge import at_cut
from cell.seams._truth_faces import CLIP_TOL_M, plane_extent
from cell.seams.ours._ends import end_source, find_ends, within_receiving
from cell.seams.ours._faces import away_from, face_from_edge, fit_planes, outside, tilt
from cell.seams.ours._geometry import JointGeometry, against_table, joint_of, line, within
from cell.seams.ours._planes import Face, FitRequest, Fitted, PassFit, Selection, Tilt, thin
from cell.seams.ours._points import Points, crop_box, gather
from cell.seams.ours._round import round_facet
from cell.seams.ours._shear import across_lever, end_shear, end_slopes
from cell.seams.ours._sides import side_selections
from cell.seams.ours.confidence import NO_ERRORS, SeamErrors, confidence, errors_of
from cell.seams.ours.options import OursOptions
from cell.seams.sigma import drawn_end_sigma, ours_end_sigma, ours_sigma
from cell.types import MapSeam, Reason, SeamEstimate, SeamScene, SeamStatus

PAST_B_M = 3e-4  # an end placed this far past B's drawn face's edge comes back to it [m] (an end's floor)


class OursLocator:
    """Map-guided plane-fit seam locator (the method: :mod:`cell.seams.ours`). Deterministic for a given ``rng``."""

    name: str = "ours"
    reads_voxel_cloud: bool = False  # the dense, registered cloud only

    def __init__(self, options: OursOptions | None = None) -> None:
        self.options = options if options is not None else OursOptions()

    def locate(self, scene: SeamScene, seam: MapSeam, rng: np.random.Generator) -> SeamEstimate:
        """Find ``seam`` (frame R) in ``scene.dense`` (the method: :mod:`cell.seams.ours`); MapError for a bad joint."""
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
        generator spawned from ``rng``, in the order given. Any closed planar-faced body works: a box answers from
        its axes, a polyhedron from its vertices and face polygons (:mod:`cell.seams.ours._bodies`)."""
        return self._locate_all(scene, seams, rng.spawn(len(seams)))

    def _locate_all(
        self, scene: SeamScene, seams: Sequence[MapSeam], rngs: Sequence[np.random.Generator]
    ) -> list[tuple[SeamEstimate, SeamErrors]]:
        """The lock-step loop of :meth:`locate_many_with_errors`."""
        o = self.options
        runs = [self._run(scene, seam, r) for seam, r in zip(seams, rngs, strict=True)]
        out: list[tuple[SeamEstimate, SeamErrors] | None] = [None] * len(runs)
        pending: dict[int, FitRequest] = {}

        def advance(i: int, result: PassFit | None) -> None:
            try:
                pending[i] = next(runs[i]) if result is None else runs[i].send(result)
            except StopIteration as stop:
                out[i] = stop.value

        for i in range(len(runs)):
            advance(i, None)
        while pending:
            batch = list(pending.items())
            pending.clear()
            fits: dict[int, list[Fitted | None]] = {}
            for first in (True, False):
                group = [(i, req) for i, req in batch if req.first is first]
                fits.update(zip([i for i, _ in group], fit_planes([req for _, req in group], first, o), strict=True))
            jobs = [(req.selections[s.j], fits[i][s.j], s, req.pts) for i, req in batch for s in req.tilts]
            tilted = iter(tilt(jobs, o))
            results = {i: PassFit(fits[i], {s.j: next(tilted) for s in req.tilts}) for i, req in batch}
            for i, _ in batch:
                advance(i, results[i])
        return [x for x in out if x is not None]

    def _run(
        self, scene: SeamScene, seam: MapSeam, rng: np.random.Generator
    ) -> Generator[FitRequest, PassFit, tuple[SeamEstimate, SeamErrors]]:
        """The steps of :meth:`locate_with_errors` for one seam: yields each pass's plane fits (and tilt steps)
        for :meth:`locate_many_with_errors` to do and is sent their results; returns the estimate and its standard
        errors."""
        o = self.options
        joint = joint_of(scene, seam)
        part_a = scene.weldmap.part(joint.abutting)
        part_b = scene.weldmap.part(joint.receiving)
        n_a, d_a = part_a.face_plane(joint.face_abutting)
        n_b, d_b = part_b.face_plane(joint.face_receiving)
        mid = 0.5 * (seam.p_start + seam.p_end)
        try:
            p0, t = line(n_a, d_a, n_b, d_b, mid, seam.direction)
        except ValueError:
            raise MapError(
                f"seam {seam.id}: faces {joint.abutting} {joint.face_abutting} and {joint.receiving} "
                f"{joint.face_receiving} are parallel; a joint needs two faces that meet in a line"
            ) from None
        if against_table(n_a, n_b, seam, scene.table_z, o.map_tolerance_m):
            reason = "the seam lies against the table"
            return SeamEstimate(seam.id, SeamStatus.NOT_VISIBLE, reason, code=Reason.UNDERSIDE), NO_ERRORS

        def dense(a: FloatArray, b: FloatArray) -> Points:
            """The tube about a-b (3,) from ``edge_sample_share`` of the cloud (an end found as an edge needs
            density)."""
            return gather(scene, a, b, o.tube_radius_m, 0.0, joint, rng, o, o.edge_sample_share)

        s_map = sorted((float(t @ (seam.p_start - p0)), float(t @ (seam.p_end - p0))))
        geo = JointGeometry.of(part_a, part_b, joint, p0, t, (s_map[0], s_map[1]), o.edge_band_m)
        face_a = Face(n_a, d_a, o.sensor_sigma_m, f"{joint.abutting} {joint.face_abutting}")
        face_b = Face(n_b, d_b, o.sensor_sigma_m, f"{joint.receiving} {joint.face_receiving}")
        others = tuple(p for p in scene.weldmap.parts if p.name != part_a.name)
        ends = geo.end_planes(t, s_map, scene.table_z, o.map_tolerance_m, others, p0)
        # A side face at an angle to the seam (a mitred brace's) ends face A's points that far further along it.
        end_face = part_a.face_plane(joint.end_face)
        shear0 = end_shear(ends, n_a, n_b, t, p0, end_face)
        skew = max(abs(shear0.slope(0)), abs(shear0.slope(1))) * o.tube_radius_m
        pts = gather(scene, seam.p_start, seam.p_end, o.tube_radius_m, o.extend_m + skew, joint, rng, o)
        # B a round's facet along the seam: its points beside the seam are the round's, their heights off its round.
        round_b = round_facet(part_b, joint.face_receiving, p0, t)
        flat_b = round_b.flattening(pts.P) if round_b is not None else 0.0

        for it in range(o.passes):
            first, last = it == 0, it == o.passes - 1
            p0, t = line(face_a.n, face_a.d, face_b.n, face_b.d, mid, seam.direction)
            r_a = pts.along(face_a.n) - face_a.d
            r_b = pts.along(face_b.n) - face_b.d - flat_b
            # Along the seam as A's side faces run across face A (square for a box; a mitred brace's at an angle).
            # Each end along its own side lines (a gusset's snipe at one end, its square toe at the other).
            shear = end_shear(ends, face_a.n, face_b.n, t, p0, end_face)
            s0 = shear.s(pts, p0, t, 0)
            s1 = shear.s(pts, p0, t, 1) if shear.ends else s0
            slack = o.map_tolerance_m if first else 0.0
            band_a = max(o.corner_band_m, 3.0 * face_a.scale) + slack
            band_b = max(o.corner_band_m, 3.0 * face_b.scale) + slack
            e0, e1 = ends[0].s, ends[1].s
            eb = o.edge_band_m + (slack if first else min(max(ends[0].se, ends[1].se), o.map_tolerance_m))
            # Across face A (its height over B), the bands leave a thin plate's side a window.
            lo_a, hi_a = within(band_b, geo.length_a), geo.length_a - within(eb, geo.length_a)
            eb_s = within(eb, s_map[1] - s_map[0])  # a 19 mm seam keeps a window along it too
            in_a = (r_b >= lo_a) & (r_b <= hi_a) & (s0 >= e0 + eb_s) & (s1 <= e1 - eb_s) & pts.ok
            if geo.region_a is not None:  # a polyhedron's face need not fill its extents: only points over it
                in_a &= geo.in_face_a(pts, joint.face_abutting, within(eb, geo.length_a))
            # The widest gate B's points pass below (the region test on a polyhedron is costly: only on those).
            gate_b = max(o.map_tolerance_m + 3.0 * o.sensor_sigma_m, o.gate_sigmas * face_b.scale)
            beside_a = ~((r_a < band_a) & (r_a > -geo.depth_a - band_a) & (s0 > e0 - band_a) & (s1 < e1 + band_a))
            where_b = pts.ok & beside_a & (np.abs(r_b) < gate_b)
            if round_b is None:
                in_b = geo.in_face_b(pts, slack, where_b) & beside_a & pts.ok
            else:
                in_b = where_b & round_b.over(pts.P, o.edge_band_m + slack)
            planes: list[Selection] = []
            for key, face, r, region, part, face_name, skip in (
                ("a", face_a, r_a, in_a, part_a, joint.face_abutting, joint.end_face),
                ("b", face_b, r_b, in_b, part_b, joint.face_receiving, ""),
            ):
                if face.source != "points":
                    continue  # placed from an edge in the first pass
                gate = (o.map_tolerance_m + 3.0 * o.sensor_sigma_m) if first else o.gate_sigmas * face.scale
                # Never past half the part's thickness behind the face: a thin plate's far side is not this face;
                # and as far in front (a gate cut on one side only drags a noisy face out: 0.8 mm on an 8 mm plate).
                behind = 0.5 * (geo.depth_a if key == "a" else geo.depth_b)
                # Only points whose camera looks at the face's front (a tube's inner wall, seen down its bore, is not).
                sel = np.flatnonzero(region & (np.abs(r) < min(gate, behind)) & pts.facing(face.n, face.d))
                if len(sel) >= pts.least(o.min_face_points):
                    planes.append(Selection(key, face, r, sel, thin(sel, o.max_fit_points)))
                    continue
                why = "no edge of it is seen either: not seen or not there"
                if first:
                    # Where an adjacent face of the same part may show this face's edge: away from the other part.
                    away = away_from(face_b, lo_a) if key == "a" else outside(part_a, band_a)
                    placed = face_from_edge(scene, face, part, face_name, skip, seam, joint, away, rng, o)
                    if isinstance(placed, Face):
                        face_a, face_b = (placed, face_b) if key == "a" else (face_a, placed)
                        continue
                    why = placed
                return _not_found(
                    seam.id,
                    f"face {face.name} is seen by no usable camera ({len(sel)} points near the seam in a "
                    f"{pts.share:.0%} sample, needs {pts.least(o.min_face_points)}) and {why}",
                )
            sides = side_selections(ends, pts, r_a, r_b, face_b, geo, first, slack, o, face_a.n)
            tilts = []
            if last and o.refine_normals:
                for j, x in enumerate(planes):
                    tilts.append(Tilt(j, (face_b if x.key == "a" else face_a).n, p0, t))
            request = FitRequest(planes + sides, pts, first, tilts)
            fitting = (yield request).applied(request, face_a, face_b, ends)
            # Support regions' areas, for the confidence: A's strip between its ends, B's strip beside A.
            area_a = max(e1 - e0 - 2.0 * eb, 0.0) * max(min(o.tube_radius_m, geo.length_a) - band_b - eb, 0.0)
            face_a = fitting.face_a.with_area(area_a)
            face_b = fitting.face_b.with_area((e1 - e0 + 2.0 * o.extend_m) * max(o.tube_radius_m - band_a, 0.0))
            p0, t = line(face_a.n, face_a.d, face_b.n, face_b.d, mid, seam.direction)
            # p0 lies on both fitted planes: its distance from a map plane is how far that face moved.
            for drift, name in ((abs(float(n_a @ p0) - d_a), face_a.name), (abs(float(n_b @ p0) - d_b), face_b.name)):
                if drift > 2.0 * o.map_tolerance_m:
                    return _not_found(
                        seam.id,
                        f"face {name} fitted {drift * 1000:.1f} mm from the map "
                        f"(allowed {2000 * o.map_tolerance_m:.1f} mm): wrong surface or part moved",
                    )
            ends = find_ends(
                fitting.ends,
                fitting.sides_se,
                pts,
                dense if last else None,
                face_a,
                face_b,
                p0,
                t,
                s_map,
                geo.length_a,
                o,
                end_face,
            )

        # Where B's drawn face stops along the line (the line laid in its plane, as the truth's is).
        on_b = p0 - (float(n_b @ p0) - d_b) * n_b
        ends = within_receiving(ends, plane_extent(part_b, joint.face_receiving, on_b, t, CLIP_TOL_M), PAST_B_M)
        length = ends[1].s - ends[0].s
        if not 0.3 * (s_map[1] - s_map[0]) < length < 2.0 * (s_map[1] - s_map[0]) + 2.0 * o.extend_m:
            return _not_found(
                seam.id,
                f"seam length {length * 1000:.1f} mm found, the map says {(s_map[1] - s_map[0]) * 1000:.1f} mm",
            )
        crop = crop_box(scene, o)
        for k, end in enumerate(ends):
            if end.source in ("extent", "tangent") and at_cut(
                crop, p0 + end.s * t, t if k == 1 else -t, 0.0, o.edge_band_m
            ):
                return _not_found(
                    seam.id,
                    f"the seam's {('start', 'end')[k]} is not seen: face {face_a.name}'s points run to where the "
                    "cloud stops (the workspace's boundary): the part reaches out of the workspace",
                )
        errors = errors_of(face_a, face_b, ends)
        conf = confidence(face_a, face_b, errors, pts.pitch, o)
        via = [f"face {f.name} from the {f.source} ({f.note})" for f in (face_a, face_b) if f.source != "points"]
        sources = (end_source(ends[0]), end_source(ends[1]))
        drawn = drawn_end_sigma(o.map_tolerance_m, s_map[1] - s_map[0])
        # A side face at an angle to the seam moves its end along it by the as-built gap's error times its slope.
        slopes = end_slopes(ends, face_a.n, face_b.n, t)
        sigma = ours_sigma(float(np.hypot(errors.lateral_m, errors.tilt_m)), o.sigma_floor_m)
        if round_b is not None:  # B's points lie on facets, the fit takes them off the round through their corners
            sigma = float(np.hypot(sigma, round_b.bias_m))
        end_sigmas = [
            drawn
            if e.source == "map"
            else ours_end_sigma(
                e.spread,
                k,
                bool(e.touching) and e.source == "side face",
                abs(slope),
                o.end_floor_scale,
                float(np.hypot(e.bias, across_lever(e, t) * sigma)),
            )
            for e, k, slope in zip(ends, sources, slopes, strict=True)
        ]
        estimate = SeamEstimate(
            id=seam.id,
            status=SeamStatus.FOUND,
            reason="; ".join([f"ends from {ends[0].source} / {ends[1].source}", *via]),
            p_start=p0 + ends[0].s * t,
            p_end=p0 + ends[1].s * t,
            confidence=conf,
            sigma_m=sigma,
            end_sigma_m=(end_sigmas[0], end_sigmas[1]),
            end_source=sources,
        )
        return estimate, errors


def _not_found(seam_id: str, reason: str) -> tuple[SeamEstimate, SeamErrors]:
    """NOT_FOUND: the data does not hold the seam's faces or ends (``reason`` says which and why)."""
    return SeamEstimate(seam_id, SeamStatus.NOT_FOUND, reason=reason, code=Reason.NO_SUPPORT), NO_ERRORS
