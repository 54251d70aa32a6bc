"""Generate the plate weldment map ``maps/bracket.dxf``: plates, not tubes, drawn as MESH bodies.

Run from the repository root::

    .venv/bin/python tools/make_weldments.py            # writes maps/bracket.dxf
    .venv/bin/python tools/make_weldments.py --out DIR  # somewhere else

The bracket (millimetres, map frame M with z = 0 on the table top, conventions of ``tools/make_maps.py``):

- ``BASE``: a 400 x 250 x 12 plate lying on the table, with a 60 x 60 square hole (a body of genus one: its top
  and bottom are drawn as four quads around the hole, as mesh exporters write them);
- ``UPRIGHT``: a 12 mm plate standing on the base (200 x 168), welded along its +x side;
- ``GUSSET``: a right-triangular 12 mm plate (legs 100 mm) between the base and the upright's -x face, welded on
  both sides to both (a prism of five faces: no box);
- ``LAP``: an 8 mm plate lying on the base, lap-welded along its four edges.

Every seam is a red 3D LINE on layer ``WELD_SEAMS`` carrying its id as XDATA (``WELDCELL``). The output is
byte-stable (ezdxf's fixed metadata, sorted classes).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import ezdxf
from ezdxf.math import Vec3 as DxfVec3
from ezdxf.render import MeshTransformer
from make_maps import (
    APPID,
    PART_LAYER_COLOR,
    SEAM_LAYER_COLOR,
    SeamSpec,
    _add_seam,
    box_mesh,
    one_map_main,
    write_stable,
)

BASE = (0.0, 0.0, 0.0, 400.0, 250.0, 12.0)  # x0, y0, z0, x1, y1, z1 [mm]
HOLE = (20.0, 95.0, 80.0, 155.0)  # x0, y0, x1, y1 of the base's square hole [mm]
UPRIGHT = ((200.0, 25.0, 12.0), (212.0, 225.0, 180.0))
GUSSET_Y = (119.0, 131.0)  # the gusset's two faces [mm]
GUSSET_XZ = ((200.0, 12.0), (100.0, 12.0), (200.0, 112.0))  # back-bottom corner, toe, apex [mm]
LAP = ((280.0, 40.0, 12.0), (380.0, 210.0, 20.0))
SEAM_LAYER = "WELD_SEAMS"


def plate_with_hole_mesh() -> MeshTransformer:
    """The base plate with its hole, closed, outward normals: outer and hole outlines at the bottom (z0) and the
    top (z1); the top and bottom each four quads around the hole; four outer and four hole walls."""
    x0, y0, z0, x1, y1, z1 = BASE
    hx0, hy0, hx1, hy1 = HOLE
    outer = [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]
    inner = [(hx0, hy0), (hx1, hy0), (hx1, hy1), (hx0, hy1)]
    mesh = MeshTransformer()
    mesh.vertices = [DxfVec3(x, y, z) for z in (z0, z1) for x, y in outer + inner]
    faces: list[Sequence[int]] = []
    for i in range(4):
        j = (i + 1) % 4
        o0, o1, i0, i1 = i, j, 4 + i, 4 + j
        faces += [
            (o0 + 8, o1 + 8, i1 + 8, i0 + 8),  # top, around the hole
            (o0, i0, i1, o1),  # bottom
            (o0, o1, o1 + 8, o0 + 8),  # outer wall
            (i0, i0 + 8, i1 + 8, i1),  # hole wall, facing into the hole
        ]
    mesh.faces = faces
    return mesh


def gusset_mesh() -> MeshTransformer:
    """The gusset: the triangle GUSSET_XZ (in x, z) extruded across GUSSET_Y, closed, outward normals."""
    (bx, bz), (tx, tz), (ax, az) = GUSSET_XZ
    mesh = MeshTransformer()
    mesh.vertices = [DxfVec3(x, y, z) for y in GUSSET_Y for x, z in ((bx, bz), (tx, tz), (ax, az))]
    # 0 1 2 at y0, 3 4 5 at y1 (back-bottom, toe, apex); faces: y0, y1, bottom, hypotenuse, back.
    mesh.faces = [(0, 2, 1), (3, 4, 5), (1, 4, 3, 0), (2, 5, 4, 1), (0, 3, 5, 2)]
    return mesh


def bracket_seams() -> list[SeamSpec]:
    """The bracket's ten fillets, ids ``A>B:where``; each runs the whole length of the edge it welds."""
    (ux0, uy0, uz0), (ux1, uy1, _) = UPRIGHT
    (bx, bz), (tx, _), (_, az) = GUSSET_XZ
    (lx0, ly0, lz0), (lx1, ly1, _) = LAP
    seams: list[SeamSpec] = [("UPRIGHT>BASE:+x", (ux1, uy0, uz0), (ux1, uy1, uz0))]
    for side, y in zip(("-y", "+y"), GUSSET_Y, strict=True):
        seams.append((f"GUSSET>BASE:{side}", (bx, y, bz), (tx, y, bz)))
        seams.append((f"GUSSET>UPRIGHT:{side}", (ux0, y, bz), (ux0, y, az)))
    seams += [
        ("LAP>BASE:-x", (lx0, ly0, lz0), (lx0, ly1, lz0)),
        ("LAP>BASE:+x", (lx1, ly0, lz0), (lx1, ly1, lz0)),
        ("LAP>BASE:-y", (lx0, ly0, lz0), (lx1, ly0, lz0)),
        ("LAP>BASE:+y", (lx0, ly1, lz0), (lx1, ly1, lz0)),
    ]
    return seams


def build_bracket_map() -> ezdxf.document.Drawing:
    """The bracket drawing: four MESH bodies on layers named after the parts, the seams on WELD_SEAMS."""
    doc = ezdxf.new("R2018", units=4)
    doc.appids.add(APPID)
    msp = doc.modelspace()
    doc.layers.add(SEAM_LAYER, color=SEAM_LAYER_COLOR)
    bodies = {
        "BASE": plate_with_hole_mesh(),
        "UPRIGHT": box_mesh(*UPRIGHT),
        "GUSSET": gusset_mesh(),
        "LAP": box_mesh(*LAP),
    }
    for name, mesh in bodies.items():
        doc.layers.add(name, color=PART_LAYER_COLOR)
        mesh.render_mesh(msp, dxfattribs={"layer": name, "color": 256})
    for seam_id, p0, p1 in bracket_seams():
        _add_seam(msp, seam_id, p0, p1, SEAM_LAYER, "explicit", None)
    return doc


def write_bracket_map(path: str | Path) -> Path:
    """Write the bracket map (:func:`build_bracket_map`) to ``path``, byte-stable; returns the path."""
    return write_stable(build_bracket_map, path)


def main(argv: Sequence[str] | None = None) -> int:
    return one_map_main(
        argv, __doc__, "bracket.dxf", write_bracket_map, lambda: f"4 parts (two meshes), {len(bracket_seams())} seams"
    )


if __name__ == "__main__":
    raise SystemExit(main())
