"""What the aligned map says about a joint, for our locator (frame R, metres): its boxes and the regions they
bound, the seam line where two planes meet, the side faces (or the table) at the seam's ends."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from cell.errors import MapError
from cell.geometry import FloatArray
from cell.seams import _edge
from cell.seams._lines import plane_intersection
from cell.seams.ours._planes import End
from cell.seams.ours._points import Points
from cell.types import Box, Joint, MapSeam, SeamScene

BoolArray = npt.NDArray[np.bool_]
_Z = np.array([0.0, 0.0, 1.0])


@dataclass(frozen=True)
class JointGeometry:
    """What the map says about the joint's boxes, for region tests (frame R)."""

    box_a: Box
    box_b: Box
    depth_a: float  # A's thickness below its weld face [m]
    length_a: float  # A's length away from B (along its end face's normal) [m]
    side_axis: int  # A's box axis across the seam's ends (-1: none: the seam is not across A's faces)
    k_b: int  # B's box axis normal to the receiving face
    edge_band: float

    @staticmethod
    def of(box_a: Box, box_b: Box, joint: Joint, t: FloatArray, edge_band: float) -> JointGeometry:
        """The geometry of ``joint`` between A's ``box_a`` and B's ``box_b``, its seam along t (3,)."""
        k_a = "xyz".index(joint.face_abutting[1])
        k_e = "xyz".index(joint.end_face[1])
        R_A = box_a.X_AB[:3, :3]
        cand = [k for k in range(3) if k != k_a]
        k_t = max(cand, key=lambda k: abs(float(R_A[:, k] @ t)))
        side_axis = k_t if abs(float(R_A[:, k_t] @ t)) > np.cos(np.radians(30.0)) else -1
        k_b = "xyz".index(joint.face_receiving[1])
        return JointGeometry(box_a, box_b, float(box_a.size[k_a]), float(box_a.size[k_e]), side_axis, k_b, edge_band)

    @property
    def has_sides(self) -> bool:
        """Whether the seam runs across A's side faces (so that they end it)."""
        return self.side_axis >= 0

    def end_planes(self, t: FloatArray, s_map: list[float], table_z: float, tol: float) -> tuple[End, End]:
        """Planes of A's side faces at the start and the end of the seam (direction t; outward normals), the
        table instead of a side face that rests on it; the ends where the map puts them (``s_map`` along t [m])."""
        R_A = self.box_a.X_AB[:3, :3]
        k = max(self.side_axis, 0)
        h = 0.5 * float(self.box_a.size[k])
        c = self.box_a.center
        axis = R_A[:, k] if float(R_A[:, k] @ t) >= 0.0 else -R_A[:, k]
        out = []
        for sign, s in zip((-1.0, 1.0), s_map, strict=True):
            n = sign * axis
            d = float(n @ c) + h
            on_table = self.has_sides and _edge.on_table(n, d, table_z, tol)
            out.append(End(-_Z, -table_z, True, s) if on_table else End(n, d, False, s))
        return out[0], out[1]

    def in_face_b(self, pts: Points, slack: float) -> BoolArray:
        """Points whose projection lies inside B's receiving face shrunk by the edge band (and ``slack``)."""
        ok = np.ones(len(pts.cam), bool)
        R_B, c_B = self.box_b.X_AB[:3, :3], self.box_b.center
        for j in range(3):
            if j != self.k_b:
                axis = R_B[:, j]
                half = 0.5 * float(self.box_b.size[j]) - self.edge_band - slack
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
