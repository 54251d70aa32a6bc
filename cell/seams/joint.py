"""How each seam of a welding map is made, from the geometry alone: which part abuts, which receives, which
faces.

A seam of a T (or corner) joint lies on a face of the receiving part B, where that face meets the plane of one
of the side faces of the abutting part A, whose end face looks at B across a small gap. :func:`find_joints`
recovers that :class:`~cell.seams.base.Joint` for every seam without reading the seam id; :func:`weld_faces`
and :func:`fillet_bisector` give the two faces' planes and the direction out of the fillet corner (for the
torch and the locators). All geometry is in the map's own frame (whatever ``weldmap.frame`` is), metres.
"""

from __future__ import annotations

import numpy as np

from cell.errors import MapError
from cell.geometry import FloatArray
from cell.types import BOX_FACES, Joint, MapSeam, Part, WeldMap

_ANTIPARALLEL_COS = float(np.cos(np.radians(5.0)))  # end face vs receiving face: within 5 deg of opposite


def _face_axis(face: str) -> int:
    return "xyz".index(face[1])


def _on_plane(part: Part, face: str, pts: FloatArray, tol: float) -> bool:
    n, d = part.face_plane(face)
    return bool(np.all(np.abs(pts @ n - d) <= tol))


def _candidates(seam: MapSeam, parts: tuple[Part, ...], tol: float, max_gap: float) -> list[tuple[float, Joint]]:
    """Every (score, joint) that explains ``seam``; the score (smaller is better) is the gap plus plane
    residuals."""
    pts = np.stack([seam.p_start, seam.p_end])
    # Both parts of a joint hold the seam within the gap (plus tolerance): only those are worth a look.
    parts = tuple(p for p in parts if np.all(p.contains(pts, margin=max_gap + tol)))
    found: list[tuple[float, Joint]] = []
    for b in parts:
        for face_b in BOX_FACES:
            n_b, d_b = b.face_plane(face_b)
            res_b = np.abs(pts @ n_b - d_b)
            if np.any(res_b > tol) or not np.all(b.contains(pts, margin=tol)):
                continue
            for a in parts:
                if a.name == b.name:
                    continue
                for end_face in BOX_FACES:
                    n_e, d_e = a.face_plane(end_face)
                    if float(n_e @ n_b) > -_ANTIPARALLEL_COS:
                        continue
                    gap = pts @ n_e - d_e  # how far the seam lies in front of A's end face
                    if np.any(gap < -tol) or np.any(gap > max_gap + tol):
                        continue
                    # The seam, pushed back onto A's end face, must lie on that face (on one of its edges).
                    q = pts - np.outer(gap, n_e)
                    if not np.all(a.contains(q, margin=tol)):
                        continue
                    for face_a in BOX_FACES:
                        if _face_axis(face_a) == _face_axis(end_face):
                            continue
                        n_a, d_a = a.face_plane(face_a)
                        res_a = np.abs(pts @ n_a - d_a)
                        if np.any(res_a > tol):
                            continue
                        score = float(np.mean(np.abs(gap)) + res_a.sum() + res_b.sum())
                        found.append((score, Joint(seam.id, a.name, b.name, face_a, face_b, end_face)))
    return found


def find_joints(weldmap: WeldMap, tol_m: float = 0.003, max_gap_m: float = 0.006) -> dict[str, Joint]:
    """The :class:`Joint` of every seam of ``weldmap``, keyed by seam id, found from the part boxes alone.

    tol_m : how far [m] a seam end may lie off a face plane or outside a face rectangle.
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
                f"face across a gap of at most {max_gap_m * 1000:.1f} mm (tolerance {tol_m * 1000:.1f} mm)"
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
