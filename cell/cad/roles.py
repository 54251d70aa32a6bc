"""Which bodies of a CAD are welded and which are not: fasteners (bolts, nuts, washers: small bodies that pass
through a hole of another body, and the small bodies that touch them) and bodies named like fixtures."""

from __future__ import annotations

import enum
import re
from collections.abc import Sequence

import numpy as np
from scipy.spatial import ConvexHull, QhullError

from cell.cad.model import Body
from cell.geometry import FloatArray
from cell.types import Polyhedron
from cell.weldmap import LayerRoles, body_role

SMALL_VOLUME = 0.05  # a fastener holds at most this fraction of the largest body's volume
SMALL_EXTENT = 0.25  # and is at most this fraction of the assembly's size across
HOLE_DEPTH_M = 0.001  # a point this far inside another body's convex hull, and outside its material, is in a hole
_FASTENER_NAME = re.compile(
    r"(BOLT|SCREW|NUT|WASHER|RIVET|STUD|DOWEL|(^|[^A-Z])PIN([^A-Z]|$)|ISO[ _-]?(4014|4017|4032|4762|7089|7090)|"
    r"DIN[ _-]?(125|912|931|933|934)|(^|[^A-Z0-9])M\d{1,2}([X_ -]|$))",
    re.IGNORECASE,
)


class Role(enum.StrEnum):
    PART = "part"  # welded: seams proposed where it touches another part
    FASTENER = "fastener"  # bolted, never welded: a fixture of the map
    FIXTURE = "fixture"  # on a fixture layer (FIXTURE*, CLAMP*, JIG*, STOP*): a fixture of the map


def polyhedron(body: Body) -> Polyhedron:
    """The body's tessellation as a :class:`~cell.types.Polyhedron` (for inside tests), slivers dropped."""
    V, T = body.vertices, body.triangles
    area = np.linalg.norm(np.cross(V[T[:, 1]] - V[T[:, 0]], V[T[:, 2]] - V[T[:, 0]]), axis=1)
    return Polyhedron(V, tuple(tuple(int(i) for i in t) for t in T[area > 1e-14]))


def _in_a_hole(small: Body, big: Body, big_poly: Polyhedron) -> bool:
    """Whether part of ``small`` lies inside ``big``'s convex hull but outside its material (through a hole)."""
    try:
        hull = ConvexHull(big.vertices)
    except QhullError:
        return False
    V, T = small.vertices, small.triangles
    p = np.concatenate([V, V[T].mean(axis=1)])
    inside = np.all(p @ hull.equations[:, :3].T + hull.equations[:, 3] <= -HOLE_DEPTH_M, axis=1)
    if not inside.any():
        return False
    return bool(np.any(~big_poly.contains(p[inside])))


def _touch(a: Body, b: Body, gap_m: float) -> bool:
    lo_a, hi_a = a.vertices.min(axis=0), a.vertices.max(axis=0)
    lo_b, hi_b = b.vertices.min(axis=0), b.vertices.max(axis=0)
    return bool(np.all(lo_a <= hi_b + gap_m) and np.all(lo_b <= hi_a + gap_m))


def roles(bodies: Sequence[Body], polys: Sequence[Polyhedron], gap_m: float) -> list[Role]:
    """Each body's role: a fixture by its name or a layer it is on (the map reader's fixture layers: FIXTURE*,
    CLAMP*, JIG*, STOP*), a fastener by its name or its
    place (small and through a hole of a larger body, or small and touching a fastener), else a part."""
    out = [
        Role.FIXTURE
        if any(body_role(b.name, layer, LayerRoles()) == "fixture" for layer in (b.name, *b.layers))
        else Role.PART
        for b in bodies
    ]
    if not bodies:
        return out
    largest = max(b.volume for b in bodies)
    all_v: FloatArray = np.concatenate([b.vertices for b in bodies])
    size = float(np.ptp(all_v, axis=0).max())
    small = [b.volume <= SMALL_VOLUME * largest and float(b.extent.max()) <= SMALL_EXTENT * size for b in bodies]
    for i, b in enumerate(bodies):
        if out[i] == Role.PART and small[i]:
            through = any(
                j != i and not small[j] and _touch(b, o, gap_m) and _in_a_hole(b, o, polys[j])
                for j, o in enumerate(bodies)
            )
            if through or _FASTENER_NAME.search(b.name):
                out[i] = Role.FASTENER
    changed = True
    while changed:  # nuts and washers: small bodies on a fastener
        changed = False
        for i, b in enumerate(bodies):
            on_one = any(out[j] == Role.FASTENER and _touch(b, o, gap_m) for j, o in enumerate(bodies) if j != i)
            if out[i] == Role.PART and small[i] and on_one:
                out[i], changed = Role.FASTENER, True
    return out
