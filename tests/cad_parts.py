"""The public welding benchmark part's situation, made here: a plate, a web standing on it (a T), a tube standing on
it, and a bolt with its washer and nut through a hole of the plate; written as a STEP assembly with OpenCascade
(names, millimetres) and as one STL of several bodies with trimesh. Millimetres, the plate's corner at the origin.

The true fillets (what a welder would weld) are :data:`TRUE_LINES` and :data:`TRUE_CIRCLES`."""

from __future__ import annotations

import math
from pathlib import Path

PLATE = ((0.0, 0.0, 0.0), (400.0, 300.0, 12.0))
WEB = ((144.0, 50.0, 12.0), (156.0, 250.0, 112.0))  # 12 mm thick, standing along y
TUBE = ((300.0, 200.0, 12.0), 30.0, 25.0, 150.0)  # centre of its foot, outer and inner radius, height
BOLT = ((330.0, 60.0), 6.0, 6.5, 10.0)  # axis (x, y), shank radius, hole radius, head radius
WASHER_MM = 2.0  # thick, under the bolt's head
NUT_MM = 10.0  # across flats 19 mm... here a hexagon of circumradius 11 under the plate

TRUE_LINES = {  # the web's two long fillets [mm]
    "WEB>PLATE:-x": ((144.0, 50.0, 12.0), (144.0, 250.0, 12.0)),
    "WEB>PLATE:+x": ((156.0, 50.0, 12.0), (156.0, 250.0, 12.0)),
}
TRUE_CIRCLES = {"TUBE>PLATE": ((300.0, 200.0, 12.0), 30.0)}  # the tube's outer foot: centre, radius [mm]


def _ocp_bodies() -> list[tuple[str, object]]:
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut, BRepAlgoAPI_Fuse
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakePolygon
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox, BRepPrimAPI_MakeCylinder, BRepPrimAPI_MakePrism
    from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt, gp_Vec

    def box(lo: tuple[float, ...], hi: tuple[float, ...]) -> object:
        return BRepPrimAPI_MakeBox(gp_Pnt(*lo), gp_Pnt(*hi)).Shape()

    def cyl(x: float, y: float, z: float, r: float, h: float) -> object:
        return BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(x, y, z), gp_Dir(0, 0, 1)), r, h).Shape()

    (bx, by), r_shank, r_hole, r_head = BOLT
    plate = BRepAlgoAPI_Cut(box(*PLATE), cyl(bx, by, -1.0, r_hole, 14.0)).Shape()
    (tx, ty, tz), r_out, r_in, h = TUBE
    tube = BRepAlgoAPI_Cut(cyl(tx, ty, tz, r_out, h), cyl(tx, ty, tz - 1.0, r_in, h + 2.0)).Shape()
    top = 12.0 + WASHER_MM
    bolt = BRepAlgoAPI_Fuse(cyl(bx, by, top, r_head, 8.0), cyl(bx, by, -NUT_MM - 4.0, r_shank, top + NUT_MM + 4.0))
    washer = BRepAlgoAPI_Cut(cyl(bx, by, 12.0, 12.0, WASHER_MM), cyl(bx, by, 11.0, r_hole, WASHER_MM + 2.0))
    poly = BRepBuilderAPI_MakePolygon()
    for k in range(6):
        a = math.radians(60.0 * k)
        poly.Add(gp_Pnt(bx + 11.0 * math.cos(a), by + 11.0 * math.sin(a), -NUT_MM))
    poly.Close()
    hexagon = BRepPrimAPI_MakePrism(BRepBuilderAPI_MakeFace(poly.Wire()).Face(), gp_Vec(0, 0, NUT_MM)).Shape()
    nut = BRepAlgoAPI_Cut(hexagon, cyl(bx, by, -NUT_MM - 1.0, r_shank, NUT_MM + 2.0)).Shape()
    return [
        ("PLATE", plate),
        ("WEB", box(*WEB)),
        ("TUBE", tube),
        ("BOLT M12x40", bolt.Shape()),
        ("WASHER", washer.Shape()),
        ("HEX_NUT", nut),
    ]


GUSSET = ((94.0, 140.0, 12.0), (144.0, 152.0, 62.0))  # a block on the plate against the web's -x face


def write_step_with_gusset(path: Path) -> Path:
    """The part with :data:`GUSSET` added: it covers 12 mm of the web's -x fillet."""
    return write_step(path, gusset=True)


CLAMP = ((300.0, 0.0, 12.0), (340.0, 30.0, 40.0))  # a block on the plate, on layer FIXTURE_CLAMPS in the STEP


def write_step(path: Path, names: bool = True, gusset: bool = False, inches: bool = False, clamp: bool = False) -> Path:
    """The part as a STEP assembly (AP214, millimetres or ``inches``), each body a named product (``names`` False:
    unnamed, and the bolt's parts named nothing that tells what they are)."""
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.Interface import Interface_Static
    from OCP.Message import Message, Message_Gravity
    from OCP.STEPCAFControl import STEPCAFControl_Writer
    from OCP.STEPControl import STEPControl_AsIs
    from OCP.TCollection import TCollection_ExtendedString
    from OCP.TDataStd import TDataStd_Name
    from OCP.TDocStd import TDocStd_Document
    from OCP.TopLoc import TopLoc_Location
    from OCP.XCAFApp import XCAFApp_Application
    from OCP.XCAFDoc import XCAFDoc_DocumentTool

    for printer in Message.DefaultMessenger_s().Printers():
        printer.SetTraceLevel(Message_Gravity.Message_Fail)
    doc = TDocStd_Document(TCollection_ExtendedString("XmlOcaf"))
    XCAFApp_Application.GetApplication_s().InitDocument(doc)
    tool = XCAFDoc_DocumentTool.ShapeTool_s(doc.Main())
    assembly = tool.NewShape()
    TDataStd_Name.Set_s(assembly, TCollection_ExtendedString("BENCH_PART"))
    bodies = _ocp_bodies()
    if gusset:
        from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox
        from OCP.gp import gp_Pnt

        bodies.append(("GUSSET", BRepPrimAPI_MakeBox(gp_Pnt(*GUSSET[0]), gp_Pnt(*GUSSET[1])).Shape()))
    if clamp:
        from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox
        from OCP.gp import gp_Pnt

        bodies.append(("BLOCK", BRepPrimAPI_MakeBox(gp_Pnt(*CLAMP[0]), gp_Pnt(*CLAMP[1])).Shape()))
    if inches:  # the same part drawn in inches, the document told so
        from OCP.BRepBuilderAPI import BRepBuilderAPI_Transform
        from OCP.gp import gp_Pnt, gp_Trsf

        scale = gp_Trsf()
        scale.SetScale(gp_Pnt(0.0, 0.0, 0.0), 1.0 / 25.4)
        bodies = [(n, BRepBuilderAPI_Transform(s, scale, True).Shape()) for n, s in bodies]
        XCAFDoc_DocumentTool.SetLengthUnit_s(doc, 0.0254)
    for k, (name, shape) in enumerate(bodies):
        label = tool.AddShape(shape, False)
        TDataStd_Name.Set_s(label, TCollection_ExtendedString(name if names else f"SOLID{k + 1}"))
        tool.AddComponent(assembly, label, TopLoc_Location())
        if name == "BLOCK":
            XCAFDoc_DocumentTool.LayerTool_s(doc.Main()).SetLayer(label, TCollection_ExtendedString("FIXTURE_CLAMPS"))
    tool.UpdateAssemblies()
    writer = STEPCAFControl_Writer()  # its controller sets the defaults: the unit after it
    Interface_Static.SetCVal_s("write.step.unit", "INCH" if inches else "MM")
    writer.SetNameMode(True)
    writer.Transfer(doc, STEPControl_AsIs)
    assert writer.Write(str(path)) == IFSelect_RetDone
    return path


def write_stl(path: Path, solid_header: bool = True) -> Path:
    """The plate (no hole), the web and the tube as one binary STL (several bodies, one mesh), millimetres; its
    80-byte header starts with ``solid`` as many exporters write it (``solid_header``)."""
    import trimesh

    (x0, y0, z0), (x1, y1, z1) = PLATE
    plate = trimesh.creation.box(extents=(x1 - x0, y1 - y0, z1 - z0))
    plate.apply_translation(((x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2))
    (a0, b0, c0), (a1, b1, c1) = WEB
    web = trimesh.creation.box(extents=(a1 - a0, b1 - b0, c1 - c0))
    web.apply_translation(((a0 + a1) / 2, (b0 + b1) / 2, (c0 + c1) / 2))
    (tx, ty, tz), r_out, r_in, h = TUBE
    tube = trimesh.creation.annulus(r_min=r_in, r_max=r_out, height=h, sections=64)
    tube.apply_translation((tx, ty, tz + h / 2))
    data = trimesh.util.concatenate([plate, web, tube]).export(file_type="stl")
    if solid_header:
        data = b"solid exported by a CAD program".ljust(80, b" ") + data[80:]
    path.write_bytes(data)
    return path
