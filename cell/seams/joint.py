"""How each seam of a welding map is made, from the geometry alone: which part abuts, which receives, which faces
(T, corner or lap fillets at any dihedral in range), and the faces' planes, bisector and angle for the torch and the
locators. All in the map's own frame, metres and radians."""

from __future__ import annotations

import math
from dataclasses import replace
from typing import NamedTuple

import numpy as np

from cell.errors import MapError
from cell.geometry import FloatArray
from cell.types import Box, Joint, MapSeam, Part, WeldMap

_ANTIPARALLEL_COS = float(np.cos(np.radians(5.0)))  # end face vs receiving face: within 5 deg of opposite
MIN_DIHEDRAL_DEG = 30.0  # the weld faces' angle: sharper than this is no fillet
MAX_DIHEDRAL_DEG = 150.0  # flatter than this is a butt, not a fillet
_COPLANAR_M = 0.003  # [m] how far two faces may lie apart and still be flush (a corner joint)


def _planes(part: Part) -> tuple[tuple[str, ...], FloatArray, FloatArray]:
    """The part's face names, outward normals (F, 3) and offsets (F,)."""
    names = part.face_names()
    planes = [part.face_plane(f) for f in names]
    return names, np.array([n for n, _ in planes]), np.array([d for _, d in planes])


def _candidates(seam: MapSeam, parts: tuple[Part, ...], tol: float, max_gap: float) -> list[tuple[float, Joint]]:
    """Every (score, joint) that explains ``seam``; the score (smaller is better) is the gap plus plane
    residuals."""
    pts = np.stack([seam.p_start, seam.p_end])
    # Both parts of a joint hold the seam within the gap (plus tolerance): only those are worth a look.
    parts = tuple(p for p in parts if np.all(p.contains(pts, margin=max_gap + tol)))
    planes = {p.name: _planes(p) for p in parts}
    cos_lo, cos_hi = math.cos(math.radians(180.0 - MIN_DIHEDRAL_DEG)), math.cos(math.radians(180.0 - MAX_DIHEDRAL_DEG))
    found: list[tuple[float, Joint]] = []
    for b in parts:
        names_b, N_b, D_b = planes[b.name]
        res_B = np.abs(pts @ N_b.T - D_b)  # (2, F) each seam end off each face plane
        for k_b in np.flatnonzero(np.all(res_B <= tol, axis=0)):
            if not np.all(b.contains(pts, margin=tol)):
                continue
            n_b, res_b = N_b[k_b], res_B[:, k_b]
            for a in parts:
                if a.name == b.name:
                    continue
                names_a, N_a, D_a = planes[a.name]
                res_A = np.abs(pts @ N_a.T - D_a)
                for k_e in np.flatnonzero(N_a @ n_b <= -_ANTIPARALLEL_COS):
                    n_e, d_e = N_a[k_e], D_a[k_e]
                    gap = pts @ n_e - d_e  # how far the seam lies in front of A's end face
                    if np.any(gap < -tol) or np.any(gap > max_gap + tol):
                        continue
                    # The seam, pushed back onto A's end face, must lie on that face (on one of its edges).
                    q = pts - np.outer(gap, n_e)
                    if not np.all(a.contains(q, margin=tol)):
                        continue
                    c = N_a @ n_b  # cos of the angle between the normals: 180 deg - the dihedral
                    ok = np.all(res_A <= tol, axis=0) & (c >= cos_lo) & (c <= cos_hi)
                    for k_a in np.flatnonzero(ok):
                        score = float(np.mean(np.abs(gap)) + res_A[:, k_a].sum() + res_b.sum())
                        joint = Joint(seam.id, a.name, b.name, names_a[k_a], names_b[k_b], names_a[k_e])
                        found.append((score, joint))
    return found


def _nearest_faces(seam: MapSeam, parts: tuple[Part, ...], n: int = 2) -> str:
    """The ``n`` faces nearest the seam (the larger of its ends' distances to each face's polygon), for a message."""
    pts = np.stack([seam.p_start, seam.p_end])
    near = []
    for p in parts:
        body = p.body.to_polyhedron() if isinstance(p.body, Box) else p.body
        near += [(float(body.face_distance(f, pts).max()), f"{p.name}:{f}") for f in p.face_names()]
    near.sort()
    return ", ".join(f"{f} ({d * 1000:.1f} mm)" for d, f in near[:n]) or "none"


def find_joints(weldmap: WeldMap, tol_m: float = 0.003, max_gap_m: float = 0.006) -> dict[str, Joint]:
    """The :class:`Joint` of every seam of ``weldmap``, keyed by seam id, found from the parts' faces alone.

    tol_m : how far [m] a seam end may lie off a face plane or outside the body.
    max_gap_m : the largest gap [m] between the abutting part's end face and the receiving face.
    Raises :class:`MapError` naming the seam when a seam does not sit on two parts this way.
    """
    joints: dict[str, Joint] = {}
    for seam in weldmap.seams:
        if seam.length <= tol_m:
            raise MapError(f"seam {seam.id!r} is {seam.length * 1000:.2f} mm long; a seam must be longer than tol_m")
        found = _candidates(seam, weldmap.parts, tol_m, max_gap_m)
        if not found:
            raise MapError(
                f"seam {seam.id!r} does not sit on two parts: no part face holds it with another part's end "
                f"face across a gap of at most {max_gap_m * 1000:.1f} mm and a face at {MIN_DIHEDRAL_DEG:.0f} to "
                f"{MAX_DIHEDRAL_DEG:.0f} deg (tolerance {tol_m * 1000:.1f} mm); nearest faces: "
                f"{_nearest_faces(seam, weldmap.parts)}"
            )
        joints[seam.id] = min(found, key=lambda sj: sj[0])[1]
    return joints


def weld_faces(weldmap: WeldMap, joint: Joint) -> tuple[FloatArray, float, FloatArray, float]:
    """The two weld faces' planes in the map's frame: ``(n_a, d_a, n_b, d_b)``.

    n_a, d_a : outward unit normal (3,) and offset [m] of the abutting part's ``face_abutting`` (n_a . p =
    d_a).
    n_b, d_b : the same for the receiving part's ``face_receiving``.
    """
    n_a, d_a = weldmap.part(joint.abutting).face_plane(joint.face_abutting)
    n_b, d_b = weldmap.part(joint.receiving).face_plane(joint.face_receiving)
    return n_a, d_a, n_b, d_b


def fillet_bisector(weldmap: WeldMap, joint: Joint) -> FloatArray:
    """Unit direction (3,) out of the fillet corner, in the map's frame: the normalised sum of the two outward
    normals."""
    n_a, _, n_b, _ = weld_faces(weldmap, joint)
    s = n_a + n_b
    norm = float(np.linalg.norm(s))
    if norm < 1e-9:
        raise MapError(f"seam {joint.seam_id!r}: the weld faces are parallel, there is no fillet corner")
    return np.asarray(s / norm)


def dihedral(weldmap: WeldMap, joint: Joint) -> float:
    """The angle [rad] between the two weld faces, inside the fillet (pi/2 for a box T; about 0.61 and 2.53 on
    either side of a brace at 35 degrees): pi minus the angle between their outward normals."""
    n_a, _, n_b, _ = weld_faces(weldmap, joint)
    return math.pi - math.acos(max(-1.0, min(1.0, float(n_a @ n_b))))


class WeldGeometry(NamedTuple):
    """The two weld faces of a joint in the map's frame: planes (n . p = d, outward unit normals), the unit
    direction out of the fillet corner, and the dihedral [rad] between the faces."""

    n_a: FloatArray
    d_a: float
    n_b: FloatArray
    d_b: float
    bisector: FloatArray
    dihedral: float


def weld_geometry(weldmap: WeldMap, joint: Joint) -> WeldGeometry:
    """:func:`weld_faces`, :func:`fillet_bisector` and :func:`dihedral` of one joint at once."""
    n_a, d_a, n_b, d_b = weld_faces(weldmap, joint)
    return WeldGeometry(n_a, d_a, n_b, d_b, fillet_bisector(weldmap, joint), dihedral(weldmap, joint))


def joint_kind(weldmap: WeldMap, joint: Joint) -> str:
    """``T``, ``corner`` or ``lap`` for one seam's joint, for any bodies (parts and faces in the same frame).

    lap: the abutting part rests on the receiving face with a thin side (its extent along the end face's normal is
    smaller than along its weld face's normal); corner: a face of the abutting part opposite its weld face (within
    5 deg; a hollow tube has its outer wall and its inner one) is flush with a face of the receiving part (the outside
    of an L); T otherwise.
    """
    a, b = weldmap.part(joint.abutting), weldmap.part(joint.receiving)
    n_end, _ = a.face_plane(joint.end_face)
    n_a, _ = a.face_plane(joint.face_abutting)
    h_end, h_a = a.vertices() @ n_end, a.vertices() @ n_a
    if np.ptp(h_end) < np.ptp(h_a):
        return "lap"
    within = math.cos(math.radians(5.0))
    _, N_a, D_a = _planes(a)
    _, N_b, D_b = _planes(b)
    for n_o, d_o in zip(N_a[N_a @ n_a < -within], D_a[N_a @ n_a < -within], strict=True):
        if bool(np.any((N_b @ n_o > within) & (np.abs(D_b - d_o) <= _COPLANAR_M))):
            return "corner"
    return "T"


def joint_notes(weldmap: WeldMap) -> dict[str, str]:
    """Each seam's joint as ``cell map info`` shows it (:func:`cell.weldmap.describe`): type, dihedral [deg],
    abutting > receiving part, e.g. ``T 90 deg  POST_L > TOP_RAIL``; a seam no two faces hold is left out."""
    text = {}
    for s in weldmap.seams:
        try:
            joint = find_joints(replace(weldmap, seams=(s,)))[s.id]
        except MapError:
            continue
        deg = math.degrees(dihedral(weldmap, joint))
        text[s.id] = f"{joint_kind(weldmap, joint)} {deg:.0f} deg  {joint.abutting} > {joint.receiving}"
    return text
