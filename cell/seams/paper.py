"""The paper's seam locator (section 3.6): masks around the map seam, boundary points, extremes and frequencies, every
threshold from the cloud's own point spacing (docs/locate.md, "The two baselines"). Everything in R, metres."""

from __future__ import annotations

import numpy as np

from cell.config.seams import PaperOptions
from cell.geometry import FloatArray
from cell.seams._features import cloud_features
from cell.seams._support import mesh_part, not_supported
from cell.seams.sigma import paper_end_sigmas, paper_sigma
from cell.types import EndSource, MapSeam, Reason, SeamEstimate, SeamScene, SeamStatus

AXIS_TOLERANCE_DEG = 10.0  # a seam within this of x, y or z counts as "along" it
MIN_MASK_POINTS = 8  # fewer cloud points than this in the outer mask: nothing to measure
MIN_BOUNDARY_POINTS = 3  # fewer boundary points than this in the inner mask: nothing to measure
MIN_FACE_POINTS = 3  # points sharing a coordinate needed to call them a face
FACE_EXTENT_SPACINGS = 0.75  # ... how far they spread in both other axes (a face, not an edge or a column)
FACE_NORMAL_COS = float(np.cos(np.radians(30.0)))  # ... and how close to the axis their normals are
_NOT_AXIS = "the paper's method handles seams along x, y or z only"


def _not_found(seam: MapSeam, reason: str, code: Reason = Reason.NO_SUPPORT) -> SeamEstimate:
    return SeamEstimate(seam.id, SeamStatus.NOT_FOUND, reason, code=code)


def second_most_frequent(values: FloatArray, bin_m: float) -> float:
    """The paper's rule: centre of the second most frequent ``bin_m`` bin of ``values`` (the most frequent if
    only one bin is filled)."""
    k, counts = np.unique(np.floor(values / bin_m).astype(np.int64), return_counts=True)
    order = np.argsort(-counts, kind="stable")
    pick = order[1] if len(order) > 1 else order[0]
    return float((k[pick] + 0.5) * bin_m)


def axis_faces(
    p: FloatArray, normals: FloatArray, axis: int, bin_m: float, min_extent: float, at: FloatArray
) -> list[tuple[float, int]]:
    """Faces perpendicular to ``axis`` among points p (n, 3) with normals (n, 3): (coordinate [m], number of
    points), densest first; the coordinate is read at the point ``at`` (3,) (a plane fit, for faces a little
    off the axis).

    A face is a set of at least :data:`MIN_FACE_POINTS` points whose normals lie within 30 deg of ``axis``,
    whose ``axis`` coordinates agree within ``bin_m`` (the densest window of that width, so no bin edge splits
    a face), and that spread at least ``min_extent`` in both other axes. Normal and spread tell a face from
    the other things that repeat a coordinate in a voxel-averaged cloud: the voxels of faces parallel to
    ``axis`` (they share the voxel-centre value) and the mixed voxels along an edge.
    """
    p = p[np.abs(np.nan_to_num(normals[:, axis])) >= FACE_NORMAL_COS]
    v = p[:, axis]
    order = np.argsort(v, kind="stable")
    vs = v[order]
    lo = np.searchsorted(vs, vs - bin_m / 2.0, side="left")
    hi = np.searchsorted(vs, vs + bin_m / 2.0, side="right")
    density = hi - lo
    others = [t for t in range(3) if t != axis]
    seen: list[float] = []
    faces: list[tuple[float, int]] = []
    for i in np.argsort(-density, kind="stable"):
        if density[i] < MIN_FACE_POINTS:
            break
        if any(abs(vs[i] - u) < bin_m for u in seen):
            continue
        seen.append(float(vs[i]))
        members = p[order[lo[i] : hi[i]]]
        if np.all(np.ptp(members[:, others], axis=0) >= min_extent):
            faces.append((_plane_at(members, axis, at), int(density[i])))
    return faces


def _plane_at(members: FloatArray, axis: int, at: FloatArray) -> float:
    """The ``axis`` coordinate of the plane through ``members`` (n, 3), as a function of the other two
    coordinates, at the point ``at`` (3,); the median when the fit is ill-posed."""
    others = [t for t in range(3) if t != axis]
    A = np.column_stack([np.ones(len(members)), members[:, others] - at[others]])
    if len(members) < 4 or np.linalg.cond(A) > 1e6:
        return float(np.median(members[:, axis]))
    coef, *_ = np.linalg.lstsq(A, members[:, axis], rcond=None)
    return float(coef[0])


def _nearest(faces: list[tuple[float, int]], target: float, centre: float, half_width: float) -> float | None:
    """The face value nearest ``target`` among those within ``half_width`` of ``centre`` (the inner mask)."""
    inside = [f[0] for f in faces if abs(f[0] - centre) <= half_width]
    return min(inside, key=lambda v: abs(v - target)) if inside else None


class PaperLocator:
    """The paper's local search (section 3.6) on the voxel-downsampled cloud ``scene.cloud`` (frame R).

    For a seam along the robot's y axis (along x: swap the roles of x and y):

    1. outer mask around the map seam's start point, ``outer_mask_m`` = (across, along) half-widths, all z
       (l_z);
    2. boundary points of the masked cloud (angle-gap criterion on the local tangent plane);
    3. inner mask ``inner_mask_m`` = (across, along) half-widths on the boundary points;
    4. start X = the min or max X of those points, whichever is nearer the map start's X; start Y = the second
       most frequent Y (``frequency_bin_m`` bins); start Z = the map start's Z;
    5. end = start + the map's seam vector (the seam length is the map's).

    A vertical seam is handled as the horizontal seam it is near (step 4c): its receiving face's normal (from
    the joint) is across the junction's horizontal seams, so that axis is "across" and the other horizontal
    axis is "along". Without a joint, the nearest horizontal seam of the map decides.

    Which mask number is along which axis (eq. 5-6 say "3 cm x 5 cm x l_z" and do not say): the smaller across
    the seam, the larger along it, both as half-widths around the start. Across, the mask must hold the
    receiving face wherever the as-built part put it (several mm of deviation plus the map alignment error)
    and little else; along, it must hold the abutting part's side face at the seam start (the along value is
    read there) but, for parts 40-80 mm wide, not the side face at the seam's end. The other way round the
    along window would be narrower than the errors it has to absorb.

    Robustness choices (``strict=False``, the default; ``strict=True`` runs step 4 exactly as written):

    - Boundary points are extracted from the outer mask's points, as step 2 says; the mask's own cut is
      "boundary" too, and the paper's second, smaller mask removes it (inside it the flags are the whole
      cloud's: tests/test_seams_paper.py).
    - Step 4 reads each value on the face it belongs to. In a voxel-averaged cloud a voxel that holds one flat
      face keeps the face's coordinate exactly, while boundary (edge) voxels average two faces and are off by
      up to half a voxel, and the voxels of a face parallel to an axis share their voxel-centre coordinate:
      that is the paper's "most frequent value [that] usually comes from noise". So both values are taken from
      faces (points that share the coordinate and spread over an area, see :func:`axis_faces`; found on the
      outer mask's points, kept when they lie within the inner mask): across, the face nearest the paper's
      min/max value; along, the face nearest the map start (instead of "the second most frequent").
    - When the abutting part's face at the start is not seen (a side no camera looks at), the along value is
      read on its opposite face (at the seam's other end) less the part's width from the map, in the spirit of
      step 5. When no face is seen at all the paper's value is kept and the confidence is lowered.
    """

    name = "paper"
    reads_voxel_cloud = True

    def __init__(self, spec: PaperOptions | None = None, *, strict: bool = False) -> None:
        self.spec = spec if spec is not None else PaperOptions()
        self.strict = strict

    def locate(self, scene: SeamScene, seam: MapSeam, rng: np.random.Generator) -> SeamEstimate:
        """Find ``seam`` (the aligned map's seam, in R) in ``scene.cloud``; ``rng`` is unused
        (deterministic)."""
        del rng
        if (part := mesh_part(scene, seam)) is not None:
            return not_supported(seam, self.name, part, "the paper's method is axis-aligned by construction (boxes)")
        axes = self.axes(scene, seam)
        if isinstance(axes, str):
            return _not_found(seam, axes, Reason.NOT_SUPPORTED)
        c, a = axes
        pts = np.asarray(scene.cloud.points)
        s0 = np.asarray(seam.p_start)
        (oc, oa), (ic, ia) = self.spec.outer_mask_m, self.spec.inner_mask_m
        # Step 1: the larger mask (all z: l_z = Z_max - Z_min of the masked points).
        outer = (np.abs(pts[:, c] - s0[c]) <= oc) & (np.abs(pts[:, a] - s0[a]) <= oa)
        n_outer = int(outer.sum())
        if n_outer < MIN_MASK_POINTS:
            return _not_found(
                seam,
                f"only {n_outer} cloud points in the outer mask around the seam start (need {MIN_MASK_POINTS})",
            )
        # Step 2: the masked cloud's features (boundary points); step 3: those within the smaller mask.
        po = pts[outer]
        feats = cloud_features(po)
        inner = (np.abs(po[:, c] - s0[c]) <= ic) & (np.abs(po[:, a] - s0[a]) <= ia)
        pb = po[inner & feats.boundary]
        if len(pb) < MIN_BOUNDARY_POINTS:
            return _not_found(
                seam,
                f"only {len(pb)} boundary points in the inner mask around the seam start (need {MIN_BOUNDARY_POINTS})",
            )
        # Step 4: the start point, as written ...
        bin_m = self.spec.frequency_bin_m
        lo, hi = float(pb[:, c].min()), float(pb[:, c].max())
        across = lo if abs(lo - s0[c]) <= abs(hi - s0[c]) else hi
        along = second_most_frequent(pb[:, a], bin_m)
        confidence = 0.5
        if not self.strict:  # ... then read on the faces (see the class docstring).
            ext = FACE_EXTENT_SPACINGS * feats.spacing
            face_c = _nearest(axis_faces(po, feats.normals, c, bin_m, ext, s0), across, float(s0[c]), ic)
            face_a = _nearest(axis_faces(po, feats.normals, a, bin_m, ext, s0), float(s0[a]), float(s0[a]), ia)
            confidence = 1.0
            if face_a is None:  # the start face is not seen: read the abutting part's opposite face
                face_a = self._along_from_far_face(scene, seam, pts, (c, a), ext)
                confidence -= 0.1
            confidence -= 0.25 * ((face_c is None) + (face_a is None))
            across = across if face_c is None else face_c
            along = along if face_a is None else face_a
        start = s0.copy()
        start[c], start[a] = across, along
        # Step 5: the end from the map's seam vector.
        end = start + (np.asarray(seam.p_end) - s0)
        return SeamEstimate(
            seam.id,
            SeamStatus.FOUND,
            "",
            start,
            end,
            confidence,
            sigma_m=paper_sigma(confidence),
            end_sigma_m=paper_end_sigmas(confidence, seam.length),
            end_source=(EndSource.FACE_END, EndSource.DRAWN),
        )

    def _along_from_far_face(
        self,
        scene: SeamScene,
        seam: MapSeam,
        pts: FloatArray,
        axes: tuple[int, int],
        min_extent: float,
    ) -> float | None:
        """The along value of the start read on the abutting part's other face across ``a`` (the face at the
        seam's far end for a horizontal seam), minus the part's width there from the map; None when that is
        not seen."""
        joint = scene.joints.get(seam.id)
        if joint is None:
            return None
        c, a = axes
        s0 = np.asarray(seam.p_start)
        box = scene.weldmap.part(joint.abutting).box
        # The a-values, at the start point, of the abutting part's two faces most nearly perpendicular to a.
        k = int(np.argmax(np.abs(box.X_AB[a, :3])))
        values = []
        for sign in "+-":
            n, d = box.face_plane(f"{sign}{'xyz'[k]}")
            values.append((d - n @ s0 + n[a] * s0[a]) / n[a])
        near, far = sorted(values, key=lambda v: abs(v - s0[a]))
        (oc, oa), ia = self.spec.outer_mask_m, self.spec.inner_mask_m[1]
        mask = (np.abs(pts[:, c] - s0[c]) <= oc) & (np.abs(pts[:, a] - far) <= oa)
        at = s0.copy()
        at[a] = far
        pm = pts[mask]
        faces = axis_faces(pm, cloud_features(pm).normals, a, self.spec.frequency_bin_m, min_extent, at)
        found = _nearest(faces, far, far, ia)
        return None if found is None else found + (near - far)

    def axes(self, scene: SeamScene, seam: MapSeam) -> tuple[int, int] | str:
        """(across, along) axis indices in R for ``seam``, or the reason the method cannot handle it."""
        u = np.asarray(seam.direction)
        k = int(np.argmax(np.abs(u)))
        if abs(u[k]) < np.cos(np.radians(AXIS_TOLERANCE_DEG)):
            return _NOT_AXIS
        if k < 2:
            return 1 - k, k
        joint = scene.joints.get(seam.id)
        if joint is not None:
            n_b, _ = scene.weldmap.part(joint.receiving).face_plane(joint.face_receiving)
            if np.hypot(n_b[0], n_b[1]) > 0.5:
                c = int(np.argmax(np.abs(n_b[:2])))
                return c, 1 - c
        near = _nearest_horizontal_axis(scene, seam)
        if near is None:
            return "a vertical seam needs its joint or a horizontal seam nearby to choose its axes"
        return 1 - near, near


def _nearest_horizontal_axis(scene: SeamScene, seam: MapSeam) -> int | None:
    """Axis (0: x, 1: y) of the map's horizontal seam nearest to ``seam``'s midpoint, if any."""
    mid = 0.5 * (np.asarray(seam.p_start) + np.asarray(seam.p_end))
    best, best_d = None, np.inf
    for other in scene.weldmap.seams:
        v = np.asarray(other.direction)
        if other.id == seam.id or abs(v[2]) > np.sin(np.radians(AXIS_TOLERANCE_DEG)):
            continue
        d = point_segment_distance(mid, np.asarray(other.p_start), np.asarray(other.p_end))
        if d < best_d:
            best, best_d = int(np.argmax(np.abs(v[:2]))), d
    return best


def point_segment_distance(p: FloatArray, a: FloatArray, b: FloatArray) -> float:
    """Distance [m] of the point p (3,) from the segment a-b."""
    d = b - a
    t = float(np.clip((p - a) @ d / max(float(d @ d), 1e-18), 0.0, 1.0))
    return float(np.linalg.norm(p - (a + t * d)))
