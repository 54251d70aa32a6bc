"""Generate ``maps/brace.dxf``: fence1 drawn as MESH bodies plus a mitred diagonal flat-bar brace between the posts
(a body that is not a box, inside a rotated block). Conventions of ``tools/make_maps.py``.

Run from the repository root::

    .venv/bin/python tools/make_brace.py            # writes maps/brace.dxf
    .venv/bin/python tools/make_brace.py --out DIR  # somewhere else
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

import ezdxf
from ezdxf.document import Drawing
from ezdxf.math import Matrix44
from ezdxf.render import MeshTransformer
from make_maps import (
    FENCE1_JUNCTIONS,
    FENCE1_PARTS,
    PART_LAYER_COLOR,
    SeamSpec,
    _add_body,
    _add_seam,
    _rot_z,
    all_seams,
    build_map,
    one_map_main,
    write_stable,
)

BRACE_DEG = 35.0  # the brace's axis to the rails (M's x) [deg]
BRACE_WIDTH = 40.0  # across its axis, in the table's plane [mm]
BRACE_Z = (61.0, 80.0)  # a flat bar 1 mm over the bottom rail, flush with the posts' tops [mm]
BRACE_Y0 = 60.0  # y of its centre line at its left end [mm]
BRACE_GAP = 1.0  # between each mitred end and a post's inner face [mm]


def brace_outline() -> list[tuple[float, float]]:
    """The brace's corners in the table's plane (x, y) [mm], counter-clockwise from above: a parallelogram whose
    ends are cut square to the rails (mitred), so that they lie flat on the posts' inner faces across the gap."""
    (_, (x_l, _, _)), ((x_r, _, _), _) = FENCE1_PARTS["POST_L"], FENCE1_PARTS["POST_R"]
    x0, x1 = x_l + BRACE_GAP, x_r - BRACE_GAP
    t, h = math.tan(math.radians(BRACE_DEG)), BRACE_WIDTH / 2.0 / math.cos(math.radians(BRACE_DEG))
    y1 = BRACE_Y0 + (x1 - x0) * t
    return [(x0, BRACE_Y0 - h), (x1, y1 - h), (x1, y1 + h), (x0, BRACE_Y0 + h)]


def brace_mesh(M: Matrix44 | None = None) -> MeshTransformer:
    """The brace as a closed MESH (8 vertices, 6 quads, outward normals) [mm], moved by ``M`` if given."""
    mesh = MeshTransformer()
    mesh.vertices = [ezdxf.math.Vec3(x, y, z) for z in BRACE_Z for x, y in brace_outline()]
    mesh.faces = [(3, 2, 1, 0), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
    if M is not None:
        mesh.transform(M)
    return mesh


def brace_seams() -> list[SeamSpec]:
    """The brace's four fillets: where its two long sides meet each post's inner face (vertical, z over the
    brace's thickness), ids ``BRACE>POST_L:lower`` ... (lower/upper: the side of smaller/larger y)."""
    (_, (x_l, _, _)), ((x_r, _, _), _) = FENCE1_PARTS["POST_L"], FENCE1_PARTS["POST_R"]
    (x0, y_lo), _, _, (_, y_hi) = brace_outline()
    t = math.tan(math.radians(BRACE_DEG))
    seams: list[SeamSpec] = []
    for post, x in (("POST_L", x_l), ("POST_R", x_r)):
        for side, y0 in (("lower", y_lo), ("upper", y_hi)):
            y = y0 + (x - x0) * t  # the side's plane at the post's face
            seams.append((f"BRACE>{post}:{side}", (x, y, BRACE_Z[0]), (x, y, BRACE_Z[1])))
    return seams


def build_brace_map() -> Drawing:
    """fence1's posts and rails as MESH bodies with their 16 seams, plus the brace as a MESH on layer 0 inside
    block ``BRACE`` (drawn along its own axis, turned by the INSERT's ``BRACE_DEG`` rotation) and its 4 seams."""
    doc = build_map(FENCE1_PARTS, all_seams(FENCE1_PARTS, FENCE1_JUNCTIONS), solid="mesh")
    doc.layers.add("BRACE", color=PART_LAYER_COLOR)
    (x0, y0), *_ = brace_outline()
    block = doc.blocks.new("BRACE")
    _add_body(block, brace_mesh(Matrix44.translate(-x0, -y0, 0.0) @ _rot_z(-BRACE_DEG)), "0", "mesh")
    doc.modelspace().add_blockref("BRACE", (x0, y0, 0.0), dxfattribs={"layer": "BRACE", "rotation": BRACE_DEG})
    for seam_id, p0, p1 in brace_seams():
        _add_seam(doc.modelspace(), seam_id, p0, p1, "WELD_SEAMS", "explicit", None)
    return doc


def write_brace_map(path: str | Path) -> Path:
    """Write the brace map (:func:`build_brace_map`) to ``path``, byte-stable; returns the path."""
    return write_stable(build_brace_map, path)


def main(argv: Sequence[str] | None = None) -> int:
    return one_map_main(
        argv,
        __doc__,
        "brace.dxf",
        write_brace_map,
        lambda: f"{len(FENCE1_PARTS) + 1} parts (one a mesh), {16 + len(brace_seams())} seams",
    )


if __name__ == "__main__":
    raise SystemExit(main())
