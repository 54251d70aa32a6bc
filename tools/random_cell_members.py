"""The members a generated weldment is made of, each with the fillets that join it [mm, frame M, z up].

A member stands (or lies) on the top face of a receiving part at height ``z_top`` across a drawn gap, at a centre
(x, y) and a yaw about z; its own frame has x along its length. Each builder returns the :class:`Body`, its seams
(named ``<member>><receiving>:<face>``, the member's face in its own frame) and its footprint on the receiving
face (a capsule: a segment and a radius that hold it) for placing the next member clear of it. A seam runs along
the member's edge between the weld face and the end face, carried across the gap onto the receiving face, as the
cell's truth does.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from random_cell_parts import (
    Body,
    Seam,
    foot_seams,
    hollow,
    moved,
    polygon,
    pose,
    prism,
    rectangle,
    rot_z,
    rounded_rectangle,
    vec,
)

MIN_SEAM_MM = 10.0  # a fillet shorter than this is not drawn
DIHEDRAL_RANGE_DEG = (35.0, 145.0)  # a welder's fillet (the reader's joint finder takes 30-150)


@dataclass(frozen=True)
class Member:
    """A body, its seams and its footprint: a capsule (x0, y0, x1, y1, radius) that holds it [mm]."""

    body: Body
    seams: tuple[Seam, ...]
    footprint: tuple[float, float, float, float, float]


def capsule(X: np.ndarray, a: float, b: float) -> tuple[float, float, float, float, float]:
    """The capsule holding an a x b rectangle about the origin of the pose X (4, 4): a segment along its longer
    side and the radius that takes in its corners."""
    long_x = a >= b
    half = (abs(a - b) / 2, 0.0) if long_x else (0.0, abs(a - b) / 2)
    p0, p1 = moved(X, (-half[0], -half[1], 0.0)), moved(X, (half[0], half[1], 0.0))
    return (float(p0[0]), float(p0[1]), float(p1[0]), float(p1[1]), min(a, b) / math.sqrt(2.0))


def _sides(
    a: float, b: float, X: np.ndarray, faces: tuple[str, ...], inset: float = 0.0
) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """(face, start, end) of a member's side edges at its foot, a x b about its centre, moved by X; each edge
    shortened by ``inset`` at both ends (a rounded corner's flat)."""
    ends = {
        "+x": ((a / 2, -b / 2 + inset), (a / 2, b / 2 - inset)),
        "-x": ((-a / 2, -b / 2 + inset), (-a / 2, b / 2 - inset)),
        "+y": ((-a / 2 + inset, b / 2), (a / 2 - inset, b / 2)),
        "-y": ((-a / 2 + inset, -b / 2), (a / 2 - inset, -b / 2)),
    }
    out = []
    for f in faces:
        (x0, y0), (x1, y1) = ends[f]
        out.append((f, moved(X, (x0, y0, 0.0)), moved(X, (x1, y1, 0.0))))
    return out


def standing(
    name: str,
    kind: str,
    size: tuple[float, float, float],
    xy: tuple[float, float],
    yaw: float,
    base: str,
    z_top: float,
    gap: float,
    faces: tuple[str, ...],
) -> Member:
    """A box (a plate on its edge, a post, a flat bar lying flat) of ``size`` (length, width, height) resting on
    ``base``'s top across ``gap``, its fillets on ``faces`` (of ``+x -x +y -y``)."""
    a, b, h = size
    X = pose(rot_z(yaw), (xy[0], xy[1], z_top + gap + h / 2))
    v, f = prism(rectangle(a, b), -h / 2, h / 2, X)
    body = Body(name, kind, v, f, vec(X[:3, 3]), (0.0, 0.0, yaw), size)
    seams = foot_seams(body, base, z_top, _sides(a, b, X, faces))
    joint = "lap" if kind == "flat" else "T"
    seams = [Seam(s.id, s.p0, s.p1, s.abutting, s.receiving, s.dihedral_deg, joint) for s in seams]
    return Member(body, tuple(seams), capsule(X, a, b))


def rhs(
    name: str,
    size: tuple[float, float, float],
    wall: float,
    xy: tuple[float, float],
    yaw: float,
    base: str,
    z_top: float,
    gap: float,
) -> Member:
    """A rectangular hollow section (outer a x b, corner radii 2 x wall outside and 1 x wall inside about the same
    centres, 4 facets a quarter) standing open-ended on ``base``; a fillet on each of its four flats."""
    a, b, h = size
    X = pose(rot_z(yaw), (xy[0], xy[1], z_top + gap + h / 2))
    outer, inner = rounded_rectangle(a, b, 2 * wall), rounded_rectangle(a - 2 * wall, b - 2 * wall, wall)
    v, f = hollow(outer, inner, -h / 2, h / 2, X)
    body = Body(name, "rhs", v, f, vec(X[:3, 3]), (0.0, 0.0, yaw), size, extra={"wall_mm": wall, "radius_mm": 2 * wall})
    X0 = pose(rot_z(yaw), (xy[0], xy[1], 0.0))
    seams = foot_seams(body, base, z_top, _sides(a, b, X0, ("+x", "-x", "+y", "-y"), inset=2 * wall))
    return Member(body, tuple(seams), capsule(X, a, b))


def round_tube(
    name: str, kind: str, outer_d: float, wall: float, height: float, xy: tuple[float, float], z0: float, segments: int
) -> Member:
    """A round tube or pipe (outer diameter, wall [mm]) standing open-ended at height z0, tessellated into
    ``segments`` flat facets (a face's middle at angle 0: a facet faces +x); no seam of its own."""
    r = outer_d / 2
    phase = 180.0 / segments
    ro, ri = r / math.cos(math.pi / segments), (r - wall) / math.cos(math.pi / segments)  # facets' middles on r
    X = pose(np.eye(3), (xy[0], xy[1], z0 + height / 2))
    v, f = hollow(polygon(ro, segments, phase), polygon(ri, segments, phase), -height / 2, height / 2, X)
    extra = {"outer_d_mm": outer_d, "wall_mm": wall, "segments": float(segments)}
    body = Body(name, kind, v, f, vec(X[:3, 3]), (0.0, 0.0, 0.0), (outer_d, outer_d, height), extra=extra)
    return Member(body, (), (xy[0], xy[1], xy[0], xy[1], ro))


def _in_range(deg: float) -> bool:
    return DIHEDRAL_RANGE_DEG[0] <= deg <= DIHEDRAL_RANGE_DEG[1]


def brace(
    name: str,
    host: str,
    base: str,
    F: np.ndarray,
    n: np.ndarray,
    z_top: float,
    theta: float,
    width: float,
    thick: float,
    rise: float,
    gaps: tuple[float, float],
) -> Member | None:
    """A flat bar (``width`` across, ``thick``) from ``base``'s top (height z_top) up to ``host``'s vertical face,
    at ``theta`` degrees to the base (90 - theta to the face), both ends mitred to lie flat on what they meet across
    ``gaps`` (base, face); its top corner ``rise`` above the base. F : (3,) the point of the host face at z_top
    under the brace's middle; n : (3,) the face's horizontal outward normal. None when the bar does not fit.

    Fillets: its two cheeks on the base and on the face (90 degrees), and its underside and overside on each
    (theta and 180 - theta on the base, 90 - theta and 90 + theta on the face) where a welder's torch fits
    (:data:`DIHEDRAL_RANGE_DEG`), each at least :data:`MIN_SEAM_MM` long. Each lies where the planes of its two
    weld faces meet (across a gap, a skewed face's plane meets the other beyond the edge), over the extent of the
    bar's edge at that end (the cell's truth: docs/bodies.md section 3).
    """
    g1, g2 = gaps
    st, ct = math.sin(math.radians(theta)), math.cos(math.radians(theta))
    c = rise * ct - thick + st * g2  # the underside's line: sin(theta) s + cos(theta) z = c
    p1 = ((c - ct * g1) / st, g1)  # underside at the base, overside at the base, overside and underside at the face
    p2 = ((c + thick - ct * g1) / st, g1)
    p3 = (g2, (c + thick - st * g2) / ct)
    p4 = (g2, (c - st * g2) / ct)
    if p1[0] < g2 + 5.0 or p4[1] < g1 + 5.0:
        return None
    up = np.array([0.0, 0.0, 1.0])
    R = np.column_stack([n, up, np.cross(n, up)])  # outline in (s, z), extruded across the width
    X = pose(R, F)
    v, f = prism([p1, p2, p3, p4], -width / 2, width / 2, X)
    centre = moved(X, [*np.mean([p1, p2, p3, p4], axis=0), 0.0])
    yaw = math.degrees(math.atan2(n[1], n[0]))
    length = math.hypot(p2[0] - p3[0], p2[1] - p3[1])
    slide = math.degrees(math.atan2(R[1, 2], R[0, 2]))  # along the face, parallel to the base
    extra = {"angle_to_base_deg": theta, "angle_to_face_deg": 90.0 - theta, "slide_deg": slide}
    body = Body(name, "brace", v, f, vec(centre), (0.0, -theta, yaw), (length, width, thick), extra=extra)
    w = width / 2
    cands = [  # (receiving, face of the brace, start (s, z, w), end, dihedral)
        (base, "cheek+", (p1[0], 0.0, w), (p2[0], 0.0, w), 90.0),
        (base, "cheek-", (p1[0], 0.0, -w), (p2[0], 0.0, -w), 90.0),
        (base, "under", (c / st, 0.0, -w), (c / st, 0.0, w), theta),
        (base, "over", ((c + thick) / st, 0.0, -w), ((c + thick) / st, 0.0, w), 180.0 - theta),
        (host, "cheek+", (0.0, p4[1], w), (0.0, p3[1], w), 90.0),
        (host, "cheek-", (0.0, p4[1], -w), (0.0, p3[1], -w), 90.0),
        (host, "under", (0.0, c / ct, -w), (0.0, c / ct, w), 90.0 - theta),
        (host, "over", (0.0, (c + thick) / ct, -w), (0.0, (c + thick) / ct, w), 90.0 + theta),
    ]
    seams = []
    for recv, face, a, b, deg in cands:
        p0, p1_ = vec(moved(X, a)), vec(moved(X, b))
        if _in_range(deg) and math.dist(p0, p1_) >= MIN_SEAM_MM:
            seams.append(Seam(f"{name}>{recv}:{face}", p0, p1_, name, recv, deg))
    footprint = capsule(pose(np.column_stack([n, R[:, 2], up]), moved(X, (p2[0] / 2, 0.0, 0.0))), p2[0], width)
    return Member(body, tuple(seams), footprint)


def ending_plate(
    name: str,
    size: tuple[float, float, float],
    F: np.ndarray,
    n: np.ndarray,
    base: str,
    z_top: float,
    gaps: tuple[float, float],
    host: str | None,
) -> Member:
    """A plate standing on ``base`` whose end lies flat against a vertical face of a third part across ``gaps[1]``
    (F (3,): the face's point at z_top where the plate's middle meets it; n (3,): its horizontal outward normal):
    its fillets on the base run up to that part's wall. With ``host`` named (a face wide enough), also the two
    vertical fillets of the plate's end on that face."""
    a, b, h = size
    yaw = math.degrees(math.atan2(n[1], n[0]))
    centre = F + n * (gaps[1] + a / 2)
    m = standing(name, "plate", size, (float(centre[0]), float(centre[1])), yaw, base, z_top, gaps[0], ("+y", "-y"))
    seams = list(m.seams)
    if host is not None:
        side = rot_z(yaw)[:, 1]
        for face, sign in (("+y", 1.0), ("-y", -1.0)):
            p = F + side * sign * b / 2
            p0, p1 = vec((p[0], p[1], z_top + gaps[0])), vec((p[0], p[1], z_top + gaps[0] + h))
            seams.append(Seam(f"{name}>{host}:{face}", p0, p1, name, host, 90.0))
    return Member(m.body, tuple(seams), m.footprint)
