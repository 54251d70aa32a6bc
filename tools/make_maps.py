"""Generate the welding maps in ``maps/`` (fence1, fence2, ladder, tee, tee_flat) and variants of them for tests.

Run from the repository root::

    .venv/bin/python tools/make_maps.py            # writes maps/fence1.dxf, ..., tee.dxf, tee_flat.dxf
    .venv/bin/python tools/make_maps.py --out DIR  # somewhere else

Conventions of every map: drawing units mm (``$INSUNITS`` = 4), map frame M with its origin at the fence corner and
z = 0 on the table top (the tee's frame is its CAD's: see :data:`TEE_PARTS`). Parts are axis-aligned box tubes
drawn as AutoCAD-style 3DSOLIDs (ACIS data written with ``ezdxf.acis``) on a layer named after the part (colour 7).
Seams are red 3D LINEs (colour 1 set explicitly) on layer ``WELD_SEAMS`` (colour 1), each carrying its id as XDATA
(appid ``WELDCELL``, group 1000), e.g. ``POST_L>TOP_RAIL:+z``: abutting part, receiving part, and the abutting
part's box face the seam runs along.

The output is byte-stable for a given ezdxf version: ezdxf's fixed-metadata option pins the header dates,
GUIDs and marker, solids get GUIDs derived from their handles, the ACIS creation date is a fixed one, and
the CLASS entries are sorted.

``maps/brace.dxf`` (fence1 with a mitred flat-bar brace, a body that is not a box) is written by
``tools/make_brace.py``, ``maps/bracket.dxf`` (plates) by ``tools/make_weldments.py``.
"""

from __future__ import annotations

import argparse
import math
import re
import uuid
from collections import OrderedDict
from collections.abc import Callable, Iterable, Mapping, Sequence
from pathlib import Path
from typing import Literal

import ezdxf
from ezdxf.acis import api as acis
from ezdxf.acis import entities as acis_entities
from ezdxf.document import Drawing
from ezdxf.layouts import BlockLayout, Layout
from ezdxf.math import Matrix44
from ezdxf.render import MeshBuilder, MeshTransformer

Vec3 = tuple[float, float, float]
BoxSpec = tuple[Vec3, Vec3]  # (min corner, max corner) [drawing units]
SeamSpec = tuple[str, Vec3, Vec3]  # (id, start, end) [drawing units]
Junction = tuple[str, str]  # (abutting part, receiving part)

REPO_ROOT = Path(__file__).resolve().parent.parent
APPID = "WELDCELL"
FACES = ("+x", "-x", "+y", "-y", "+z", "-z")
PART_LAYER_COLOR = 7  # white/black
SEAM_LAYER_COLOR = 1  # red
TRUE_RED = 0xFF0000
_FIXED_ACIS_DATE = b"Sat Jan  1 00:00:00 2000"  # same length as datetime.ctime()
_CTIME = re.compile(rb"[A-Z][a-z]{2} [A-Z][a-z]{2} [ \d]\d \d\d:\d\d:\d\d \d{4}")
_CTIME_STR = re.compile(_CTIME.pattern.decode())

SolidKind = Literal["3dsolid", "mesh", "polyface"]
SeamColor = Literal["explicit", "bylayer", "truecolor"]

# --- The designs [mm] --------------------------------------------------------------------------------

FENCE1_PARTS: dict[str, BoxSpec] = {
    "TOP_RAIL": ((0.0, 700.0, 0.0), (1400.0, 800.0, 100.0)),
    "POST_L": ((200.0, 0.0, 0.0), (280.0, 699.0, 80.0)),  # ends 1 mm before TOP_RAIL's -y face
    "POST_R": ((1120.0, 0.0, 0.0), (1200.0, 699.0, 80.0)),
    "BOTTOM_RAIL": ((281.0, 250.0, 0.0), (1119.0, 310.0, 60.0)),  # 1 mm gap to each post
}
FENCE1_JUNCTIONS: tuple[Junction, ...] = (
    ("POST_L", "TOP_RAIL"),
    ("POST_R", "TOP_RAIL"),
    ("BOTTOM_RAIL", "POST_L"),
    ("BOTTOM_RAIL", "POST_R"),
)

FENCE2_PARTS: dict[str, BoxSpec] = {
    "RAIL_A": ((0.0, 0.0, 0.0), (1600.0, 80.0, 80.0)),
    "RAIL_B": ((0.0, 620.0, 0.0), (1600.0, 720.0, 100.0)),
    "POST_1": ((300.0, 81.0, 0.0), (360.0, 619.0, 60.0)),
    "POST_2": ((1240.0, 81.0, 0.0), (1300.0, 619.0, 60.0)),
}
FENCE2_JUNCTIONS: tuple[Junction, ...] = (
    ("POST_1", "RAIL_A"),
    ("POST_1", "RAIL_B"),
    ("POST_2", "RAIL_A"),
    ("POST_2", "RAIL_B"),
)


# The tee of the real scans (../shared/real-scans/README.md): two 2 in (50.8 mm) square tubes, the CAD frame's
# origin at the centre of the horizontal tube's cross-section under the vertical tube's axis, x along the
# horizontal tube, z up (so the table is at z = -25.4 mm). Its welds are the two fillets where the vertical
# tube's walls at x = +-25.4 mm meet the horizontal tube's top face; the walls at y = +-25.4 mm are flush with
# the horizontal tube's sides (no fillet there), so those two lines are not seams.
TEE_PARTS: dict[str, BoxSpec] = {
    "H_TUBE": ((-76.2, -25.4, -25.4), (184.15, 25.4, 25.4)),  # 260.35 mm long, lying on the table
    "V_TUBE": ((-25.4, -25.4, 25.4), (25.4, 25.4, 241.3)),  # 215.9 mm long, standing on H_TUBE's top face
}
TEE_JUNCTIONS: tuple[Junction, ...] = (("V_TUBE", "H_TUBE"),)
TEE_SEAM_FACES = ("+x", "-x")  # the abutting faces whose seams are fillets

# The T of the cropped real scan (../shared/real-scans/README.md, "A scan cropped above the table"): two 2 in square
# tubes lying flat, a 304.8 mm tube butting into the middle of the side of a 97.6 mm cross tube (the README gives
# no offset along it: drawn centred). Frame: z = 0 on the table, x along the long tube, y = 0 on its axis. Its welds
# are the two vertical fillets where the long tube's side walls (y = +-25.4 mm) meet the cross tube's -x face; the
# top edge is flush (both tubes 50.8 mm tall) and the bottom lies on the table, so those two lines are not seams.
TEE_FLAT_PARTS: dict[str, BoxSpec] = {
    "LONG_TUBE": ((0.0, -25.4, 0.0), (304.8, 25.4, 50.8)),
    "CROSS_TUBE": ((304.8, -48.8, 0.0), (355.6, 48.8, 50.8)),
}
TEE_FLAT_JUNCTIONS: tuple[Junction, ...] = (("LONG_TUBE", "CROSS_TUBE"),)
TEE_FLAT_SEAM_FACES = ("+y", "-y")


def ladder_design(
    n_rungs: int = 26,
    length: float = 2000.0,  # rail length [mm]
    rail: float = 80.0,  # rail section, square [mm]
    rung: float = 40.0,  # rung section, square [mm]
    span: float = 620.0,  # y of the far rail's near face [mm]
    gap: float = 1.0,  # between a rung end and a rail [mm]
    pitch: float = 76.0,  # rung centre spacing [mm]
) -> tuple[dict[str, BoxSpec], tuple[Junction, ...]]:
    """A ladder for scaling studies: two rails along x, ``n_rungs`` rungs between them, evenly spaced.

    With the defaults: rails 2000 x 80 x 80 mm at y[0, 80] and y[620, 700]; rungs 40 x 538 x 40 mm at
    y[81, 619] (1 mm gap at each end), centres x = 50, 126, ..., 1950; 2 * n_rungs junctions.
    """
    first = length / 2.0 - pitch * (n_rungs - 1) / 2.0
    if first - rung / 2.0 < 0.0:
        raise ValueError(f"{n_rungs} rungs at pitch {pitch} mm do not fit on a {length} mm rail")
    parts: dict[str, BoxSpec] = {
        "RAIL_A": ((0.0, 0.0, 0.0), (length, rail, rail)),
        "RAIL_B": ((0.0, span, 0.0), (length, span + rail, rail)),
    }
    junctions: list[Junction] = []
    for i in range(n_rungs):
        c = first + i * pitch
        name = f"RUNG_{i + 1:02d}"
        parts[name] = ((c - rung / 2.0, rail + gap, 0.0), (c + rung / 2.0, span - gap, rung))
        junctions += [(name, "RAIL_A"), (name, "RAIL_B")]
    return parts, tuple(junctions)


# --- Seams --------------------------------------------------------------------------------


def _overlap(a0: float, a1: float, b0: float, b1: float) -> tuple[float, float]:
    return max(a0, b0), min(a1, b1)


def junction_seams(parts: Mapping[str, BoxSpec], abutting: str, receiving: str) -> list[SeamSpec]:
    """The 4 seams where the end of box ``abutting`` meets a face of box ``receiving`` (both axis-aligned).

    The boxes must be separated (by a gap, possibly 0) along exactly one axis k. Each seam is the intersection
    of the receiving face (the one facing the abutting part) with the plane of one of the abutting part's 4
    side faces around its end, clipped to the abutting cross-section (and to the receiving face). Seams come
    in the order +x -x +y -y +z -z of the abutting face they run along; start is the lower coordinate.
    """
    (a_lo, a_hi), (r_lo, r_hi) = parts[abutting], parts[receiving]
    separated = [k for k in range(3) if a_hi[k] <= r_lo[k] or r_hi[k] <= a_lo[k]]
    if len(separated) != 1:
        raise ValueError(f"{abutting} and {receiving} must be apart along exactly one axis, got {separated}")
    k = separated[0]
    plane = r_lo[k] if a_hi[k] <= r_lo[k] else r_hi[k]  # the receiving face's coordinate along k
    seams: list[SeamSpec] = []
    for face in FACES:
        j = "xyz".index(face[1])
        if j == k:
            continue
        m = 3 - j - k  # the axis the seam runs along
        at = a_hi[j] if face[0] == "+" else a_lo[j]
        if not r_lo[j] <= at <= r_hi[j]:
            raise ValueError(f"{abutting} face {face} at {at} lies outside {receiving}'s face")
        lo, hi = _overlap(a_lo[m], a_hi[m], r_lo[m], r_hi[m])
        if hi <= lo:
            raise ValueError(f"{abutting} and {receiving} do not overlap along axis {'xyz'[m]}")
        p0, p1 = [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]
        p0[k] = p1[k] = plane
        p0[j] = p1[j] = at
        p0[m], p1[m] = lo, hi
        seams.append((f"{abutting}>{receiving}:{face}", (p0[0], p0[1], p0[2]), (p1[0], p1[1], p1[2])))
    return seams


def all_seams(parts: Mapping[str, BoxSpec], junctions: Iterable[Junction]) -> list[SeamSpec]:
    """Seams of every junction, in junction order."""
    return [s for a, r in junctions for s in junction_seams(parts, a, r)]


# --- Writing --------------------------------------------------------------------------------


def box_mesh(lo: Sequence[float], hi: Sequence[float], M: Matrix44 | None = None) -> MeshTransformer:
    """A closed box mesh (8 vertices, 6 quads, outward normals) from its corners, moved by ``M`` if given."""
    mesh = MeshTransformer()
    v = [(x, y, z) for z in (lo[2], hi[2]) for y in (lo[1], hi[1]) for x in (lo[0], hi[0])]
    mesh.vertices = [ezdxf.math.Vec3(p) for p in v]
    # Index bits: 1 -> x hi, 2 -> y hi, 4 -> z hi. Quads counter-clockwise seen from outside.
    mesh.faces = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    if M is not None:
        mesh.transform(M)
    return mesh


def _exact_body(mesh: MeshBuilder) -> acis.Body:
    """``acis.body_from_mesh`` with full-precision coordinates.

    body_from_mesh centres the mesh and stores its centre as the body's ACIS transform, which ezdxf writes
    with 6 significant digits (``f"{value:g}"``): 27.5590551 in becomes 27.5591. Move the geometry back
    instead (points, plane origins and line origins; each once) and drop the transform.
    """
    body = acis.body_from_mesh(mesh)
    if body.transform.is_none:
        return body
    c = body.transform.matrix.transform((0.0, 0.0, 0.0))
    done: set[int] = set()

    def shift(obj: object, attr: str) -> None:
        if not getattr(obj, "is_none", True) and id(obj) not in done:
            done.add(id(obj))
            setattr(obj, attr, getattr(obj, attr) + c)

    lump = body.lump
    while not lump.is_none:
        face = lump.shell.face
        while not face.is_none:
            shift(face.surface, "origin")
            first = coedge = face.loop.coedge
            while not coedge.is_none:
                edge = coedge.edge
                shift(edge.curve, "origin")
                shift(edge.start_vertex.point, "location")
                shift(edge.end_vertex.point, "location")
                coedge = coedge.next_coedge
                if coedge is first:
                    break
            face = face.next_face
        lump = lump.next_lump
    body.transform = acis_entities.NONE_REF
    return body


def _add_body(layout: Layout | BlockLayout, mesh: MeshBuilder, layer: str, solid: SolidKind) -> None:
    attribs = {"layer": layer, "color": 256}
    if solid == "3dsolid":
        entity = layout.add_3dsolid(dxfattribs=attribs)
        acis.export_dxf(entity, [_exact_body(mesh)])
        # Reproducible output: a fixed ACIS creation date, a GUID derived from the handle (not random).
        if entity.has_binary_data:  # SAB (DXF R2013+)
            entity.sab = _CTIME.sub(_FIXED_ACIS_DATE, entity.sab, count=1)
        else:  # SAT text (DXF R2000-R2010)
            fixed = _FIXED_ACIS_DATE.decode()
            entity.sat = [_CTIME_STR.sub(fixed, line, count=1) for line in entity.sat]
        uid = uuid.uuid5(uuid.NAMESPACE_OID, f"{APPID}/{entity.dxf.handle}")
        entity.dxf.uid = "{" + str(uid).upper() + "}"
    elif solid == "mesh":
        mesh.render_mesh(layout, dxfattribs=attribs)
    elif solid == "polyface":
        mesh.render_polyface(layout, dxfattribs=attribs)
    else:
        raise ValueError(f"solid must be '3dsolid', 'mesh' or 'polyface', got {solid!r}")


def _add_seam(
    layout: Layout | BlockLayout,
    seam_id: str,
    p0: Vec3,
    p1: Vec3,
    layer: str,
    color: SeamColor,
    M: Matrix44 | None,
) -> None:
    if M is not None:
        p0, p1 = M.transform(p0).xyz, M.transform(p1).xyz
    if color == "explicit":
        attribs: dict[str, object] = {"layer": layer, "color": 1}
    elif color == "bylayer":
        attribs = {"layer": layer, "color": 256}
    elif color == "truecolor":
        attribs = {"layer": layer, "color": 7, "true_color": TRUE_RED}  # true colour overrides the index
    else:
        raise ValueError(f"seam_color must be 'explicit', 'bylayer' or 'truecolor', got {color!r}")
    line = layout.add_line(p0, p1, dxfattribs=attribs)
    line.set_xdata(APPID, [(1000, seam_id)])


def _rot_z(deg: float) -> Matrix44:
    return Matrix44.z_rotate(math.radians(deg))


def build_map(
    parts: Mapping[str, BoxSpec],
    seams: Sequence[SeamSpec],
    *,
    units: int | None = 4,
    solid: SolidKind = "3dsolid",
    seam_color: SeamColor = "explicit",
    seam_layer: str = "WELD_SEAMS",
    in_blocks: bool = False,
    block_rotation_deg: float = 0.0,
    dxfversion: str = "R2018",
) -> Drawing:
    """A welding-map drawing (see :func:`write_map`)."""
    doc = ezdxf.new(dxfversion, units=units if units is not None else 0)
    if units is None:
        del doc.header["$INSUNITS"]
    doc.appids.add(APPID)
    msp = doc.modelspace()
    for name in parts:
        doc.layers.add(name, color=PART_LAYER_COLOR)
    doc.layers.add(seam_layer, color=SEAM_LAYER_COLOR)
    if not in_blocks:
        for name, (lo, hi) in parts.items():
            _add_body(msp, box_mesh(lo, hi), name, solid)
        for seam_id, p0, p1 in seams:
            _add_seam(msp, seam_id, p0, p1, seam_layer, seam_color, None)
        return doc
    # Each part in its own block (body on layer "0", so the part takes the block's name), drawn relative to
    # its min corner and turned by -rotation; the INSERT puts it back with +rotation. The seams sit in block
    # SEAMS, nested in block ASSEMBLY, with a translation at each level.
    for name, (lo, hi) in parts.items():
        block = doc.blocks.new(name)
        M = Matrix44.translate(-lo[0], -lo[1], -lo[2]) @ _rot_z(-block_rotation_deg)
        _add_body(block, box_mesh(lo, hi, M), "0", solid)
        msp.add_blockref(name, lo, dxfattribs={"layer": name, "rotation": block_rotation_deg})
    t_outer, t_inner = (50.0, -30.0, 5.0), (120.0, 40.0, 0.0)  # [drawing units]
    seams_block = doc.blocks.new("SEAMS")
    shift = [-(a + b) for a, b in zip(t_outer, t_inner, strict=True)]
    M = Matrix44.translate(*shift) @ _rot_z(-block_rotation_deg)
    for seam_id, p0, p1 in seams:
        _add_seam(seams_block, seam_id, p0, p1, seam_layer, seam_color, M)
    assembly = doc.blocks.new("ASSEMBLY")
    assembly.add_blockref("SEAMS", t_inner, dxfattribs={"rotation": block_rotation_deg})
    msp.add_blockref("ASSEMBLY", t_outer)
    return doc


def write_map(
    path: str | Path,
    parts: Mapping[str, BoxSpec],
    seams: Sequence[SeamSpec],
    *,
    units: int | None = 4,
    solid: SolidKind = "3dsolid",
    seam_color: SeamColor = "explicit",
    seam_layer: str = "WELD_SEAMS",
    in_blocks: bool = False,
    block_rotation_deg: float = 0.0,
    dxfversion: str = "R2018",
) -> Path:
    """Write a welding map to ``path``; returns the path.

    parts : name -> (min corner, max corner) of an axis-aligned box [drawing units]; one layer per part.
    seams : (id, start, end) [drawing units]; red LINEs with the id as WELDCELL XDATA.
    units : ``$INSUNITS`` code (1 in, 4 mm, 5 cm, 6 m, 0 unitless); None leaves the variable out.
    solid : how parts are drawn: ACIS ``"3dsolid"``, ``"mesh"`` or ``"polyface"``.
    seam_color : ``"explicit"`` colour 1, ``"bylayer"`` (red layer), ``"truecolor"`` RGB red over ACI 7.
    in_blocks : parts and seams inside block references (seams nested two deep), each INSERT turned by
        ``block_rotation_deg`` about z, so that the drawn geometry equals the design.
    """

    def build() -> Drawing:
        return build_map(
            parts,
            seams,
            units=units,
            solid=solid,
            seam_color=seam_color,
            seam_layer=seam_layer,
            in_blocks=in_blocks,
            block_rotation_deg=block_rotation_deg,
            dxfversion=dxfversion,
        )

    return write_stable(build, path)


def write_stable(build: Callable[[], Drawing], path: str | Path) -> Path:
    """Build a drawing with ezdxf's fixed metadata (dates, GUIDs, marker) and save it byte-stable (:func:`_save_stable`)
    to ``path``; returns the path. Every map of ``maps/`` is written through here."""
    path = Path(path)
    fixed = ezdxf.options.write_fixed_meta_data_for_testing
    ezdxf.options.write_fixed_meta_data_for_testing = True
    try:
        _save_stable(build(), path)
    finally:
        ezdxf.options.write_fixed_meta_data_for_testing = fixed
    return path


def _save_stable(doc: Drawing, path: Path) -> None:
    # ezdxf adds the CLASS entries of the entity types in use from a set, in an order that depends on the
    # hash seed: add them now and sort them so that the file is the same on every run (order is free).
    doc.classes.add_required_classes(doc.dxfversion)
    doc.classes.classes = OrderedDict(sorted(doc.classes.classes.items()))
    doc.saveas(path)


def designs() -> dict[str, tuple[dict[str, BoxSpec], tuple[Junction, ...]]]:
    """The maps this tool writes: name -> (parts, junctions)."""
    return {
        "fence1": (FENCE1_PARTS, FENCE1_JUNCTIONS),
        "fence2": (FENCE2_PARTS, FENCE2_JUNCTIONS),
        "ladder": ladder_design(),
        "tee": (TEE_PARTS, TEE_JUNCTIONS),
        "tee_flat": (TEE_FLAT_PARTS, TEE_FLAT_JUNCTIONS),
    }


def design_seams(name: str, parts: Mapping[str, BoxSpec], junctions: Iterable[Junction]) -> list[SeamSpec]:
    """The seams of design ``name``: every junction's, but for the two tees only their fillets (TEE_SEAM_FACES,
    TEE_FLAT_SEAM_FACES)."""
    seams = all_seams(parts, junctions)
    faces = {"tee": TEE_SEAM_FACES, "tee_flat": TEE_FLAT_SEAM_FACES}.get(name)
    if faces is not None:
        seams = [s for s in seams if s[0].rsplit(":", 1)[1] in faces]
    return seams


def one_map_main(
    argv: Sequence[str] | None,
    doc: str | None,
    filename: str,
    write: Callable[[Path], Path],
    summary: Callable[[], str],
) -> int:
    """The command line of a tool that writes one map: ``--out DIR`` (default ``maps/``), then ``write(DIR /
    filename)`` and one line, the path and ``summary()``. ``doc``: the tool's module docstring (its first line is
    the help text)."""
    parser = argparse.ArgumentParser(description=doc.splitlines()[0] if doc else None)
    parser.add_argument("--out", type=Path, default=REPO_ROOT / "maps", help="output folder (default: maps/)")
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    path = write(args.out / filename)
    print(f"{path}: {summary()}")
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--out", type=Path, default=REPO_ROOT / "maps", help="output folder (default: maps/)")
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    for name, (parts, junctions) in designs().items():
        seams = design_seams(name, parts, junctions)
        path = write_map(args.out / f"{name}.dxf", parts, seams)
        print(f"{path}: {len(parts)} parts, {len(junctions)} junctions, {len(seams)} seams")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
