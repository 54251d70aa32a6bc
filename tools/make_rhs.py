"""Generate the rhs map ``maps/rhs.dxf``: fence1's drawing built from real rectangular hollow sections (RHS).

Run from the repository root::

    .venv/bin/python tools/make_rhs.py            # writes maps/rhs.dxf
    .venv/bin/python tools/make_rhs.py --out DIR  # somewhere else

Each of fence1's four boxes (``FENCE1_PARTS`` in ``tools/make_maps.py``, millimetres, map frame M with z = 0 on the
table top) becomes a hollow tube along its longest edge with the box's outer size: wall 4 mm (``TOP_RAIL``) or
3 mm (the others), outer corner radius 2 x wall and inner radius 1 x wall about the same centres, each quarter round
drawn as 4 flat facets; both ends open. One closed MESH body per tube: the outer and inner shells (20 quads each,
the inner facing the hollow) joined at each end by a ring of 20 quads.

The seams are fence1's where they lie on the flat parts of both tubes' faces, shortened by the corner radii: a
seam along an abutting tube's side runs between the ends of that side's flat (and of the receiving face's flat);
fence1's four underside seams (the abutting tubes' bottoms, at z = 0) meet the receiving tubes in their rounded
lower corners, on no flat face, and are left out: 12 seams. Every seam is a red 3D LINE on layer ``WELD_SEAMS``
carrying its id as XDATA (``WELDCELL``). The output is byte-stable (ezdxf's fixed metadata, sorted classes).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

import ezdxf
from ezdxf.math import Vec3 as DxfVec3
from ezdxf.render import MeshTransformer
from make_maps import (
    APPID,
    FENCE1_JUNCTIONS,
    FENCE1_PARTS,
    PART_LAYER_COLOR,
    SEAM_LAYER_COLOR,
    SeamSpec,
    _add_seam,
    all_seams,
    one_map_main,
    write_stable,
)

WALL_MM = {"TOP_RAIL": 4.0, "POST_L": 3.0, "POST_R": 3.0, "BOTTOM_RAIL": 3.0}
FACETS = 4  # flat facets per quarter round
SEAM_LAYER = "WELD_SEAMS"


def _long_axis(lo: Sequence[float], hi: Sequence[float]) -> int:
    return max(range(3), key=lambda i: hi[i] - lo[i])


def outline(half_a: float, half_b: float, inset: float, radius: float) -> list[tuple[float, float]]:
    """A rounded rectangle about its centre, counter-clockwise: the corner centres ``inset`` in from the sides, each
    corner's quarter round of ``radius`` as FACETS + 1 points (the flats join consecutive rounds)."""
    pts: list[tuple[float, float]] = []
    for q, (sa, sb) in enumerate(((1, 1), (-1, 1), (-1, -1), (1, -1))):
        ca, cb = sa * (half_a - inset), sb * (half_b - inset)
        for k in range(FACETS + 1):
            ang = math.radians(90.0 * q + 90.0 * k / FACETS)
            pts.append((ca + radius * math.cos(ang), cb + radius * math.sin(ang)))
    return pts


def tube_mesh(lo: Sequence[float], hi: Sequence[float], wall: float) -> MeshTransformer:
    """The open-ended RHS tube filling the box lo..hi [mm] along its longest axis: a closed MESH (80 vertices, 80
    quads, outward normals)."""
    k = _long_axis(lo, hi)
    i, j = (k + 1) % 3, (k + 2) % 3  # (i, j, k) right-handed: counter-clockwise in (a, b) seen from +k
    c = [(lo[n] + hi[n]) / 2.0 for n in range(3)]
    ha, hb = (hi[i] - lo[i]) / 2.0, (hi[j] - lo[j]) / 2.0
    outer, inner = outline(ha, hb, 2.0 * wall, 2.0 * wall), outline(ha, hb, 2.0 * wall, wall)
    m = len(outer)

    def point(a: float, b: float, s: float) -> DxfVec3:
        p = [0.0, 0.0, 0.0]
        p[i], p[j], p[k] = c[i] + a, c[j] + b, s
        return DxfVec3(p)

    mesh = MeshTransformer()
    mesh.vertices = [point(a, b, s) for ring in (outer, inner) for s in (lo[k], hi[k]) for a, b in ring]
    o0, o1, i0, i1 = 0, m, 2 * m, 3 * m
    faces: list[Sequence[int]] = []
    for p in range(m):
        q = (p + 1) % m
        faces += [
            (o0 + p, o0 + q, o1 + q, o1 + p),  # outer shell
            (i0 + p, i1 + p, i1 + q, i0 + q),  # inner shell, facing the hollow
            (o1 + p, o1 + q, i1 + q, i1 + p),  # end ring at the high end
            (o0 + q, o0 + p, i0 + p, i0 + q),  # end ring at the low end
        ]
    mesh.faces = faces
    return mesh


def rhs_seams() -> list[SeamSpec]:
    """fence1's seams that lie on the flats of both tubes, each clipped to both flats (see the module docstring)."""
    out: list[SeamSpec] = []
    for seam_id, p0, p1 in all_seams(FENCE1_PARTS, FENCE1_JUNCTIONS):
        a_name, rest = seam_id.split(">")
        b_name, face = rest.split(":")
        (a_lo, a_hi), (b_lo, b_hi) = FENCE1_PARTS[a_name], FENCE1_PARTS[b_name]
        ra, rb = 2.0 * WALL_MM[a_name], 2.0 * WALL_MM[b_name]
        j = "xyz".index(face[1])
        m = next(n for n in range(3) if p0[n] != p1[n])
        if not b_lo[j] + rb <= p0[j] <= b_hi[j] - rb:
            continue  # the receiving face is rounded there
        lo = max(a_lo[m] + ra, b_lo[m] + rb)
        hi = min(a_hi[m] - ra, b_hi[m] - rb)
        q0, q1 = list(p0), list(p1)
        q0[m], q1[m] = lo, hi
        out.append((seam_id, (q0[0], q0[1], q0[2]), (q1[0], q1[1], q1[2])))
    return out


def build_rhs_map() -> ezdxf.document.Drawing:
    """The rhs drawing: four MESH tubes on layers named after the parts, the seams on WELD_SEAMS."""
    doc = ezdxf.new("R2018", units=4)
    doc.appids.add(APPID)
    msp = doc.modelspace()
    doc.layers.add(SEAM_LAYER, color=SEAM_LAYER_COLOR)
    for name, (lo, hi) in FENCE1_PARTS.items():
        doc.layers.add(name, color=PART_LAYER_COLOR)
        tube_mesh(lo, hi, WALL_MM[name]).render_mesh(msp, dxfattribs={"layer": name, "color": 256})
    for seam_id, p0, p1 in rhs_seams():
        _add_seam(msp, seam_id, p0, p1, SEAM_LAYER, "explicit", None)
    return doc


def write_rhs_map(path: str | Path) -> Path:
    """Write the rhs map (:func:`build_rhs_map`) to ``path``, byte-stable; returns the path."""
    return write_stable(build_rhs_map, path)


def main(argv: Sequence[str] | None = None) -> int:
    return one_map_main(
        argv,
        __doc__,
        "rhs.dxf",
        write_rhs_map,
        lambda: f"{len(FENCE1_PARTS)} RHS tubes (MESH), {len(rhs_seams())} seams",
    )


if __name__ == "__main__":
    raise SystemExit(main())
