"""The joint of a curved seam, from the surfaces it lies on: a round part's side (its :class:`~cell.types.Cylinder`)
or a flat face of a part, two parts within the joint finder's gap all along the seam. The round part that ends at
the seam abuts the other (a tube standing on a plate: ``cylinder_on_plane``; a branch on a run pipe:
``cylinder_on_cylinder``); a plate a tube passes through abuts the tube (``plane_on_cylinder``). Numpy only
(docs/maps.md section 4a)."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from cell.geometry import FloatArray
from cell.types import CurvedJoint, CurvedSeam, Part, Surface

GAP_M = 0.006  # [m] the joint finder's largest gap: a seam point this close to a surface lies on it
STEP_M = 0.005  # [m] the seam is tested at points this far apart (and at least 24 of them)


def _on_cylinder(part: Part, p: FloatArray) -> bool:
    c = part.cylinder
    if c is None:
        return False
    tol = GAP_M + c.sagitta_m
    return bool(np.all(np.abs(c.distance_to_axis(p) - c.radius) <= tol))


def holding_face(part: Part, p: FloatArray) -> str | None:
    """The face of ``part`` whose plane holds every point (the nearest, within the gap), or None."""
    best, err = None, GAP_M
    for face in part.face_names():
        n, d = part.face_plane(face)
        e = float(np.abs(p @ n - d).max())
        if e <= err:
            best, err = face, e
    return best


def surface_normals(part: Part, surface: Surface, face: str | None, p: FloatArray) -> FloatArray:
    """(n, 3) outward unit normals at the points p (n, 3) of the part's surface: its cylinder's side, or its flat
    face ``face``."""
    if surface is Surface.CYLINDER:
        c = part.cylinder
        assert c is not None
        d = p - c.p_base
        r = d - np.outer(d @ c.axis, c.axis)
        return np.asarray(r / np.linalg.norm(r, axis=1, keepdims=True))
    assert face is not None
    n, _ = part.face_plane(face)
    return np.tile(n, (len(p), 1))


def _ends_at(part: Part, p: FloatArray) -> bool:
    """Whether a round part ends at the seam: its body reaches no further along its axis than the seam on one side."""
    c = part.cylinder
    assert c is not None
    h, s = c.along(part.vertices()), c.along(p)
    return bool(h.min() >= s.min() - GAP_M or h.max() <= s.max() + GAP_M)


def curved_joint(seam: CurvedSeam, parts: Sequence[Part]) -> tuple[CurvedJoint | None, str]:
    """The joint of one curved seam among ``parts`` (the map's, same frame as the seam), or None and why."""
    n = max(24, math.ceil(seam.length / STEP_M))
    p = seam.sample(seam.length / n)
    held: list[tuple[Part, Surface, str | None]] = []
    for part in parts:
        if not bool(np.all(part.contains(p, GAP_M))):
            continue
        if _on_cylinder(part, p):
            held.append((part, Surface.CYLINDER, None))
        elif (face := holding_face(part, p)) is not None:
            held.append((part, Surface.PLANE, face))
    if len(held) != 2:
        names = ", ".join(h[0].name for h in held) or "none"
        return None, f"lies on the surfaces of {len(held)} parts ({names}); a curved seam joins two parts"
    (a, sa, fa), (b, sb, fb) = held
    if sa is Surface.CYLINDER and sb is Surface.CYLINDER:
        if _ends_at(b, p) and not _ends_at(a, p):
            (a, sa, fa), (b, sb, fb) = (b, sb, fb), (a, sa, fa)
    elif Surface.CYLINDER in (sa, sb):
        if sb is Surface.CYLINDER:
            (a, sa, fa), (b, sb, fb) = (b, sb, fb), (a, sa, fa)
        if not _ends_at(a, p):  # the round part goes on through: the flat part abuts it
            (a, sa, fa), (b, sb, fb) = (b, sb, fb), (a, sa, fa)
    cos = np.einsum("ij,ij->i", surface_normals(a, sa, fa, p), surface_normals(b, sb, fb, p))
    dihedral = math.pi - np.arccos(np.clip(cos, -1.0, 1.0))
    lo, hi = float(dihedral.min()), float(dihedral.max())
    kind = "T" if math.radians(30.0) <= lo and hi <= math.radians(150.0) else "corner"
    return CurvedJoint(a.name, b.name, sa, sb, kind, lo, hi), ""
