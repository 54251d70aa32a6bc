"""What the aligned map says about a joint, for our locator (frame R, metres): its boxes and the regions they
bound, the seam line where two planes meet, the side faces (or the table) at the seam's ends."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from cell.errors import MapError
from cell.geometry import FloatArray
from cell.seams import _edge
from cell.seams._lines import extent_behind, plane_intersection
from cell.seams.ours._bodies import TOUCH_M, Region, coplanar_boundary, fills_rectangle, side_planes, touch_gap
from cell.seams.ours._planes import End
from cell.seams.ours._points import Points
from cell.types import Joint, MapSeam, Part, SeamScene

BoolArray = npt.NDArray[np.bool_]
_Z = np.array([0.0, 0.0, 1.0])
_SIDE_REACH_M = 0.02  # a side face of a body ends the seam only this near the map's end [m]
_INSET_MIN_M = 1e-4  # a map's end nearer its side face than this lies on it [m]
THIN_SHARE = 0.25  # a band cut off a face is at most this share of the face's extent (thin plates keep a window)


def within(band: float, extent: float) -> float:
    """``band`` [m], cut off a face whose extent across it is ``extent`` [m], no wider than :data:`THIN_SHARE` of
    it: an 8 mm lap plate's side keeps a window between its corner and its edge bands. Faces 44 mm and taller
    keep every band the locator uses (at most 11 mm) as it is."""
    return min(band, THIN_SHARE * extent)


@dataclass(frozen=True)
class JointGeometry:
    """What the map says about the joint's bodies, for region tests (frame R): a box's from its axes, any other
    body's from its vertices and face polygons (:mod:`cell.seams.ours._bodies`)."""

    part_a: Part
    part_b: Part
    depth_a: float  # A's thickness below its weld face [m]
    length_a: float  # A's length away from B (along its end face's normal) [m]
    depth_b: float  # B's thickness behind its receiving face [m]
    planes: tuple[tuple[FloatArray, float], tuple[FloatArray, float]]  # (n, d) across the line at its two ends
    has_sides: bool  # whether ``planes`` are A's side faces (else the seam crosses none: its ends are found)
    face_b: str  # B's receiving face
    edge_band: float
    region_a: FloatArray | None = None  # A's weld face's boundary edges (k, 2, 3) when its extents do not bound it
    region_b: FloatArray | None = None  # a polyhedron B's receiving face's boundary edges (k, 2, 3) (coplanar too)
    # From the seam line to A's edge on its end face, in face A across the seam [m] (a polyhedron's: the drawn gap
    # seen across face A): where a side face's inset is measured (a skewed side face meets the line past that edge).
    to_end_edge: FloatArray | None = None
    w: FloatArray | None = None  # a polyhedron A's unit direction in face A across the seam, away from B
    # The region tests of this seam's points, computed once per point over the passes: "a" or "b" -> (points, test).
    _regions: dict[str, tuple[Points, Region]] = field(default_factory=dict, compare=False, repr=False)

    @staticmethod
    def of(
        part_a: Part,
        part_b: Part,
        joint: Joint,
        p0: FloatArray,
        t: FloatArray,
        s_map: tuple[float, float],
        o_band: float,
    ) -> JointGeometry:
        """The geometry of ``joint`` between parts A and B, its seam on the line p0 + s t (3,), the map's ends at
        ``s_map`` along it; ``o_band`` the edge band [m]."""
        n_a, d_a = part_a.face_plane(joint.face_abutting)
        n_e, d_e = part_a.face_plane(joint.end_face)
        # Built once per seam, not in every pass's region test.
        region_b = None if part_b.is_box else coplanar_boundary(part_b, joint.face_receiving)
        if not part_a.is_box:
            sides = side_planes(part_a, (joint.face_abutting, joint.end_face), p0, t, s_map, _SIDE_REACH_M)
            w = np.cross(n_a, t)
            w = w / max(float(np.linalg.norm(w)), 1e-12)
            if float(w @ part_b.face_plane(joint.face_receiving)[0]) < 0.0:
                w = -w
            h0 = (d_e - float(n_e @ p0)) / float(n_e @ w) if abs(float(n_e @ w)) > 0.3 else 0.0
            across = ((-t, float(-t @ p0) - s_map[0]), (t, float(t @ p0) + s_map[1]))  # never fitted
            return JointGeometry(
                part_a,
                part_b,
                extent_behind(part_a, n_a, d_a),
                extent_behind(part_a, n_e, d_e),
                extent_behind(part_b, *part_b.face_plane(joint.face_receiving)),
                across if sides is None else sides,
                sides is not None,
                joint.face_receiving,
                o_band,
                None
                if fills_rectangle(part_a, joint.face_abutting, t)
                else coplanar_boundary(part_a, joint.face_abutting),
                region_b,
                max(h0, 0.0) * w,
                w,
            )
        box_a = part_a.box
        k_a = "xyz".index(joint.face_abutting[1])
        k_e = "xyz".index(joint.end_face[1])
        R_A = box_a.X_AB[:3, :3]
        cand = [k for k in range(3) if k != k_a]
        k_t = max(cand, key=lambda k: abs(float(R_A[:, k] @ t)))
        has_sides = abs(float(R_A[:, k_t] @ t)) > np.cos(np.radians(30.0))
        k = k_t if has_sides else 0
        h = 0.5 * float(box_a.size[k])
        axis = R_A[:, k] if float(R_A[:, k] @ t) >= 0.0 else -R_A[:, k]
        c = box_a.center
        planes = ((-axis, float(-axis @ c) + h), (axis, float(axis @ c) + h))
        return JointGeometry(
            part_a,
            part_b,
            float(box_a.size[k_a]),
            float(box_a.size[k_e]),
            extent_behind(part_b, *part_b.face_plane(joint.face_receiving)),
            planes,
            has_sides,
            joint.face_receiving,
            o_band,
            region_b=region_b,
        )

    def end_planes(
        self,
        t: FloatArray,
        s_map: list[float],
        table_z: float,
        tol: float,
        others: tuple[Part, ...] = (),
        p0: FloatArray | None = None,
    ) -> tuple[End, End]:
        """Planes of A's side faces at the start and the end of the seam (direction t; outward normals), the
        table instead of a side face that rests on it; the ends where the map puts them (``s_map`` along t [m]).
        A seam that crosses no side faces keeps planes it never fits (its ends come from the extent of face A's
        points). A side face that lies on a face of one of ``others`` (the map's other parts: a gusset's back on an
        upright, its foot on a base plate, a brace drawn 1 mm over a rail) where the map's end is (on the line
        p0 + s t), within :data:`~cell.seams.ours._bodies.TOUCH_M`, is hidden: its End is that other face's plane
        (``touching``: the other part's thickness behind it; ``gap``: the drawn gap the end lies short of it)."""
        out = []
        for (n, d), s in zip(self.planes, s_map, strict=True):
            at = None if p0 is None or not self.has_sides else p0 + s * t
            if self.has_sides and _edge.on_table(n, d, table_z, tol):
                out.append(End(-_Z, -table_z, True, s, inset=self._inset(-_Z, -table_z, at)))
                continue
            # Only a part whose bounding sphere reaches the end can hold it (most of the map's parts lie far off).
            near = () if at is None else [p for p in others if np.linalg.norm(at - p.center) <= p.radius + TOUCH_M]
            found = [(g, p) for p in near if at is not None and (g := touch_gap(p, n, d, at)) is not None]
            if not found:
                out.append(End(n, d, False, s, inset=self._inset(n, d, at), span=self._span(n, d, at)))
                continue
            gap, other = min(found, key=lambda x: abs(x[0]))
            out.append(End(n, d + gap, False, s, touching=extent_behind(other, -n, -d - gap), gap=gap, against=other))
        return out[0], out[1]

    def _span(self, n: FloatArray, d: float, at: FloatArray | None) -> tuple[float, float] | None:
        """The heights [m] over the map's line (through ``at`` (3,)) across face A of A's vertices on its side face
        n . p = d: how far across A that face runs (None for a box, or fewer than two vertices on it)."""
        if at is None or self.w is None or self.part_a.is_box:
            return None
        v = self.part_a.vertices()
        h = (v[np.abs(v @ n - d) < _INSET_MIN_M] - at) @ self.w
        return (float(h.min()), float(h.max())) if len(h) >= 2 else None

    def _inset(self, n: FloatArray, d: float, at: FloatArray | None) -> float:
        """How far [m] the map's end ``at`` (3,) lies short of the plane n . p = d: a tube's flat ends into its
        corner radius (or the receiving tube's) before its side face (docs/bodies.md section 8). 0 for a box, and
        for a body whose end lies on the side face (within :data:`_INSET_MIN_M`)."""
        if at is None or self.part_a.is_box:
            return 0.0
        if self.to_end_edge is not None:
            at = at + self.to_end_edge
        inset = d - float(n @ at)
        return inset if inset > _INSET_MIN_M else 0.0

    def _region(self, key: str, pts: Points, edges: FloatArray, n: FloatArray) -> Region:
        """The region test of face ``key`` ("a" or "b": its boundary ``edges``, normal n) for ``pts``, kept."""
        kept = self._regions.get(key)
        if kept is None or kept[0] is not pts:
            kept = self._regions[key] = (pts, Region(pts.P, edges, n))
        return kept[1]

    def in_face_a(self, pts: Points, face_a: str, inset: float) -> BoolArray:
        """Points whose projection lies inside A's weld face (with its coplanar faces) shrunk by ``inset`` [m] when
        its extents do not bound it (a gusset's triangle); all points when they do (a box, a rectangle)."""
        if self.region_a is None:
            return np.ones(len(pts.cam), bool)
        return self._region("a", pts, self.region_a, self.part_a.face_plane(face_a)[0]).over(inset)

    def in_face_b(self, pts: Points, slack: float, where: BoolArray | None = None) -> BoolArray:
        """Points whose projection lies inside B's receiving face shrunk by the edge band (and ``slack``); a
        polyhedron's region is tested only on the points ``where`` says (the others: False), a box's on all."""
        if not self.part_b.is_box:
            edges = self.region_b if self.region_b is not None else coplanar_boundary(self.part_b, self.face_b)
            region = self._region("b", pts, edges, self.part_b.face_plane(self.face_b)[0])
            return region.over(self.edge_band + slack, where)
        box_b = self.part_b.box
        k_b = "xyz".index(self.face_b[1])
        ok = np.ones(len(pts.cam), bool)
        R_B, c_B = box_b.X_AB[:3, :3], box_b.center
        for j in range(3):
            if j != k_b:
                axis = R_B[:, j]
                half = 0.5 * float(box_b.size[j]) - self.edge_band - slack
                ok &= np.abs(pts.along(axis) - float(axis @ c_B)) <= half
        return ok


def line(
    n_a: FloatArray, d_a: float, n_b: FloatArray, d_b: float, near: FloatArray, direction: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """The line where two planes meet, nearest ``near``, directed along ``direction``; ValueError if
    parallel."""
    p0, t = plane_intersection(n_a, d_a, n_b, d_b, near)
    return p0, (t if float(t @ direction) >= 0.0 else -t)


def joint_of(scene: SeamScene, seam: MapSeam) -> Joint:
    """The joint of ``seam`` in ``scene``; MapError naming the seams that have one when it has none."""
    joint = scene.joints.get(seam.id)
    if joint is None:
        raise MapError(
            f"seam {seam.id} has no joint (abutting/receiving parts and faces); joints known for: "
            f"{', '.join(sorted(scene.joints)) or 'none'}"
        )
    return joint


def against_table(n_a: FloatArray, n_b: FloatArray, seam: MapSeam, table_z: float, tol: float) -> bool:
    """A seam on a downward face, at the table's height: no camera can see it."""
    low = max(float(seam.p_start[2]), float(seam.p_end[2])) < table_z + tol
    return low and min(float(n_a @ _Z), float(n_b @ _Z)) < -0.7
