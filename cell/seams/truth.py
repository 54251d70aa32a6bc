"""Ground truth of the seams of the part as it was really built (simulation only; exact, no noise): two boxes by
their edge carried across the gap, any other pair by their as-built weld faces (docs/bodies.md section 3)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from cell.errors import MapError
from cell.geometry import FloatArray, invert, transform_points
from cell.seams._truth_faces import general_seam_W, resolve_face
from cell.types import Box, Joint, Part, WeldMap


def _axis_sign(face: str) -> tuple[int, float]:
    return "xyz".index(face[1]), (1.0 if face[0] == "+" else -1.0)


def abutting_edge(box: Box, face_abutting: str, end_face: str) -> tuple[FloatArray, FloatArray, int]:
    """The edge shared by two adjacent faces of ``box``.

    Returns the edge's two end points (3,) in the box's parent frame [m] (the one at -half-size along the free
    axis first) and the index of the free axis in the box frame.
    """
    i_a, s_a = _axis_sign(face_abutting)
    i_e, s_e = _axis_sign(end_face)
    if i_a == i_e:
        raise ValueError(f"faces {face_abutting} and {end_face} are not adjacent: they share no edge")
    k = 3 - i_a - i_e
    half = box.size / 2.0
    lo = np.zeros(3)
    lo[i_a], lo[i_e], lo[k] = s_a * half[i_a], s_e * half[i_e], -half[k]
    hi = lo.copy()
    hi[k] = half[k]
    p = transform_points(box.X_AB, np.stack([lo, hi]))
    return p[0], p[1], k


def _as_built(parts: Sequence[Part], name: str) -> Part:
    for p in parts:
        if p.name == name:
            return p
    raise MapError(f"the as-built parts have no part {name!r}; they have: {', '.join(p.name for p in parts)}")


def true_seam_W(design: WeldMap, joint: Joint, parts_as_built_W: Sequence[Part]) -> tuple[FloatArray, FloatArray]:
    """One true seam, (p_start_W, p_end_W) (3,) each [m], in the same order as the map seam."""
    seam = design.seam(joint.seam_id)
    part_a, part_b = _as_built(parts_as_built_W, joint.abutting), _as_built(parts_as_built_W, joint.receiving)
    design_a = design.part(joint.abutting)
    if not (part_a.is_box and part_b.is_box and design_a.is_box):
        return general_seam_W(seam, joint, design_a, part_a, part_b)
    a_design, a, b = design_a.box, part_a.box, part_b.box
    p_lo, p_hi, k = abutting_edge(a, joint.face_abutting, joint.end_face)
    # Which end is the start: read the map seam's direction along the edge axis in A's own (design) frame.
    ends_B = transform_points(invert(a_design.X_AB), np.stack([seam.p_start, seam.p_end]))
    start, end = (p_lo, p_hi) if ends_B[0, k] <= ends_B[1, k] else (p_hi, p_lo)
    n_e, _ = a.face_plane(joint.end_face)
    n_b, d_b = b.face_plane(joint.face_receiving)
    denom = float(n_b @ n_e)
    if abs(denom) < 1e-6:
        raise MapError(f"seam {joint.seam_id!r}: the abutting part's end face is perpendicular to the receiving face")

    def onto_b(p: FloatArray) -> FloatArray:
        return np.asarray(p + ((d_b - n_b @ p) / denom) * n_e)

    return onto_b(start), onto_b(end)


def weld_face_plane(part: Part, face: str, near: FloatArray) -> tuple[FloatArray, float]:
    """The outward normal (3,) and offset [m] of the as-built face that stands for the drawn ``face`` near the point
    ``near`` (3,): the face itself, or on a bowed part the segment nearest to it (docs/bodies.md section 7)."""
    name, _ = resolve_face(part, face, near)
    return part.face_plane(name)


def true_seams(
    design: WeldMap, joints: Mapping[str, Joint], parts_as_built: Sequence[Part], X_WR: FloatArray
) -> dict[str, tuple[FloatArray, FloatArray]]:
    """The true seams of the as-built part, in the robot frame R.

    design : the designed map (any frame; only its parts' own frames are used, to order start and end).
    joints : seam id -> :class:`Joint` (from :func:`cell.seams.joint.find_joints` on ``design``).
    parts_as_built : the same parts (same names, same kind of body) as built, in the world W.
    X_WR : (4, 4) pose of the robot base in the world.
    Returns seam id -> (p_start_R, p_end_R), (3,) each [m], for every seam of ``design``.
    """
    X_RW = invert(np.asarray(X_WR, dtype=float))
    out: dict[str, tuple[FloatArray, FloatArray]] = {}
    for seam in design.seams:
        if seam.id not in joints:
            raise MapError(f"no joint for seam {seam.id!r}; run find_joints on the same map")
        p0, p1 = true_seam_W(design, joints[seam.id], parts_as_built)
        out[seam.id] = (transform_points(X_RW, p0), transform_points(X_RW, p1))
    return out
