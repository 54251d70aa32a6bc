"""STEP in through OpenCascade (cadquery-ocp): the assembly's solids with their names and layers, exact planes and
cylinders, sharp edges as lines and circular arcs, and a tessellation. The only module that imports OCP."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Surface
from OCP.BRepGProp import BRepGProp_Face
from OCP.BRepMesh import BRepMesh_IncrementalMesh
from OCP.BRepTools import BRepTools
from OCP.GeomAbs import GeomAbs_Circle, GeomAbs_Cylinder, GeomAbs_Line, GeomAbs_Plane
from OCP.gp import gp_Pnt, gp_Vec
from OCP.IFSelect import IFSelect_RetDone
from OCP.Message import Message, Message_Gravity
from OCP.STEPCAFControl import STEPCAFControl_Reader
from OCP.TCollection import TCollection_ExtendedString
from OCP.TColStd import TColStd_SequenceOfAsciiString
from OCP.TDataStd import TDataStd_Name
from OCP.TDF import TDF_Label, TDF_LabelSequence
from OCP.TDocStd import TDocStd_Document
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_REVERSED, TopAbs_SOLID
from OCP.TopExp import TopExp, TopExp_Explorer
from OCP.TopLoc import TopLoc_Location
from OCP.TopoDS import TopoDS, TopoDS_Shape
from OCP.TopTools import TopTools_IndexedDataMapOfShapeListOfShape, TopTools_IndexedMapOfShape
from OCP.XCAFApp import XCAFApp_Application
from OCP.XCAFDoc import XCAFDoc_DocumentTool, XCAFDoc_LayerTool, XCAFDoc_ShapeTool

from cell.cad.model import Body, CurveKind, Edge, Face, SurfaceKind
from cell.errors import MapError
from cell.geometry import FloatArray

MM = 1e-3  # OpenCascade gives STEP geometry in millimetres whatever the file's units [m per unit]
LINEAR_DEFLECTION_MM = 0.2  # the tessellation's largest distance to the exact surface [mm]
ANGULAR_DEFLECTION_RAD = math.radians(15.0)  # and its largest angle between neighbouring facets
CURVE_POINTS = 33  # a curve that is no line or circle: this many points
UNIT_NAMES = {"millimetre": "mm", "centimetre": "cm", "metre": "m", "inch": "in"}


def _quiet() -> None:
    """OpenCascade prints its statistics to stdout: only its failures, which the reader turns into MapError."""
    for printer in Message.DefaultMessenger_s().Printers():
        printer.SetTraceLevel(Message_Gravity.Message_Fail)


def _name(label: TDF_Label) -> str:
    attr = TDataStd_Name()
    if label.FindAttribute(TDataStd_Name.GetID_s(), attr):
        return str(attr.Get().ToExtString()).strip()
    return ""


def _layers(layers: XCAFDoc_LayerTool, label: TDF_Label) -> tuple[str, ...]:
    found = layers.GetLayers(label)
    return tuple(str(found.Value(i + 1).ToExtString()) for i in range(found.Length()))


def _solids(
    tool: XCAFDoc_ShapeTool, layers: XCAFDoc_LayerTool, source: str
) -> list[tuple[str, tuple[str, ...], TopoDS_Shape]]:
    """(name, layers, located solid) of every solid in the document, assemblies walked, in the file's order; a
    body's layers are those of its instance, of its product and of the assemblies above it."""
    out: list[tuple[str, tuple[str, ...], TopoDS_Shape]] = []

    def walk(label: TDF_Label, loc: TopLoc_Location, name: str, on: tuple[str, ...] = ()) -> None:
        on = on + _layers(layers, label)
        if XCAFDoc_ShapeTool.IsReference_s(label):
            ref = TDF_Label()
            XCAFDoc_ShapeTool.GetReferredShape_s(label, ref)
            walk(ref, loc.Multiplied(XCAFDoc_ShapeTool.GetLocation_s(label)), _name(ref) or name, on)
            return
        if XCAFDoc_ShapeTool.IsAssembly_s(label):
            comps = TDF_LabelSequence()
            XCAFDoc_ShapeTool.GetComponents_s(label, comps)
            for i in range(comps.Length()):
                walk(comps.Value(i + 1), loc, name, on)
            return
        shape = XCAFDoc_ShapeTool.GetShape_s(label).Moved(loc)
        found = TopExp_Explorer(shape, TopAbs_SOLID)
        solids = []
        while found.More():
            solids.append(found.Current())
            found.Next()
        for k, solid in enumerate(solids):
            out.append((name if len(solids) == 1 else f"{name}_{k + 1}", on, solid))

    labels = TDF_LabelSequence()
    tool.GetFreeShapes(labels)
    for i in range(labels.Length()):
        label = labels.Value(i + 1)
        walk(label, TopLoc_Location(), _name(label) or Path(source).stem.upper())
    return out


def _face(face: TopoDS_Shape) -> Face:
    f = TopoDS.Face_s(face)
    surf = BRepAdaptor_Surface(f)
    u0, u1, v0, v1 = BRepTools.UVBounds_s(f)
    p, n = gp_Pnt(), gp_Vec()
    BRepGProp_Face(f).Normal((u0 + u1) / 2.0, (v0 + v1) / 2.0, p, n)  # outward: the face's orientation applied
    normal = np.array([n.X(), n.Y(), n.Z()]) / max(n.Magnitude(), 1e-300)
    at = np.array([p.X(), p.Y(), p.Z()]) * MM
    kind = surf.GetType()
    if kind == GeomAbs_Plane:
        return Face(SurfaceKind.PLANE, normal=normal, offset=float(normal @ at))
    if kind == GeomAbs_Cylinder:
        cyl = surf.Cylinder()
        o, d = cyl.Location(), cyl.Axis().Direction()
        origin, axis = np.array([o.X(), o.Y(), o.Z()]) * MM, np.array([d.X(), d.Y(), d.Z()])
        radial = (at - origin) - ((at - origin) @ axis) * axis
        sign = 1.0 if float(radial @ normal) >= 0.0 else -1.0
        return Face(SurfaceKind.CYLINDER, origin=origin, axis=axis, radius=cyl.Radius() * MM, sign=sign)
    return Face(SurfaceKind.OTHER)


def _xyz(p: gp_Pnt) -> FloatArray:
    return np.array([p.X(), p.Y(), p.Z()]) * MM


def _edge(edge: TopoDS_Shape, faces: tuple[int, int]) -> Edge | None:
    e = TopoDS.Edge_s(edge)
    if BRep_Tool.Degenerated_s(e):
        return None
    curve = BRepAdaptor_Curve(e)
    t0, t1 = curve.FirstParameter(), curve.LastParameter()
    kind = curve.GetType()
    if kind == GeomAbs_Line:
        return Edge(CurveKind.LINE, np.stack([_xyz(curve.Value(t0)), _xyz(curve.Value(t1))]), (faces,))
    if kind == GeomAbs_Circle:
        circ = curve.Circle()
        c, d = circ.Location(), circ.Axis().Direction()
        centre, axis = _xyz(c), np.array([d.X(), d.Y(), d.Z()])
        first = _xyz(curve.Value(t0))
        start = (first - centre) / max(float(np.linalg.norm(first - centre)), 1e-300)
        ends = np.stack([first, _xyz(curve.Value(t1))])
        return Edge(
            CurveKind.ARC,
            ends,
            (faces,),
            centre=centre,
            axis=axis,
            radius=circ.Radius() * MM,
            start=start,
            sweep=min(t1 - t0, 2.0 * math.pi),
        )
    pts = np.stack([_xyz(curve.Value(t)) for t in np.linspace(t0, t1, CURVE_POINTS)])
    return Edge(CurveKind.CURVE, pts, (faces,))


def _tessellation(solid: TopoDS_Shape, fmap: TopTools_IndexedMapOfShape) -> tuple[FloatArray, np.ndarray, np.ndarray]:
    BRepMesh_IncrementalMesh(solid, LINEAR_DEFLECTION_MM, False, ANGULAR_DEFLECTION_RAD, False)
    points, tris, owner = [], [], []
    at = 0
    for i in range(1, fmap.Extent() + 1):
        f = TopoDS.Face_s(fmap.FindKey(i))
        loc = TopLoc_Location()
        poly = BRep_Tool.Triangulation_s(f, loc)
        if poly is None:
            continue
        trsf = loc.Transformation()
        points += [_xyz(poly.Node(k + 1).Transformed(trsf)) for k in range(poly.NbNodes())]
        flip = f.Orientation() == TopAbs_REVERSED
        for k in range(poly.NbTriangles()):
            a, b, c = poly.Triangle(k + 1).Get()
            tris.append((at + a - 1, at + c - 1, at + b - 1) if flip else (at + a - 1, at + b - 1, at + c - 1))
            owner.append(i - 1)
        at += poly.NbNodes()
    if not tris:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.intp), np.zeros(0, dtype=np.intp)
    V = np.array(points)
    key = np.round(V / 1e-7).astype(np.int64)  # the faces' copies of one node are one vertex (closed mesh)
    _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    return V[first], inverse.reshape(-1)[np.array(tris)], np.array(owner, dtype=np.intp)


def _body(name: str, layers: tuple[str, ...], solid: TopoDS_Shape) -> Body:
    fmap = TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(solid, TopAbs_FACE, fmap)
    faces = tuple(_face(fmap.FindKey(i)) for i in range(1, fmap.Extent() + 1))
    emap = TopTools_IndexedDataMapOfShapeListOfShape()
    TopExp.MapShapesAndAncestors_s(solid, TopAbs_EDGE, TopAbs_FACE, emap)
    edges = []
    for i in range(1, emap.Extent() + 1):
        owners = sorted({fmap.FindIndex(f) - 1 for f in emap.FindFromIndex(i)})
        if len(owners) != 2:  # a cylinder's own seam line, or an edge of one face only
            continue
        edge = _edge(emap.FindKey(i), (owners[0], owners[1]))
        if edge is not None and edge.length > 1e-6:
            edges.append(edge)
    V, T, owner = _tessellation(solid, fmap)
    return Body(name, faces, tuple(edges), V, T, owner, layers)


def read_step(path: Path) -> tuple[list[Body], str]:
    """The solids of a STEP file (bodies in metres) and the length unit its header declares (``mm``, ``cm``,
    ``m``, ``in``; another name as written). Raises MapError when the file cannot be read or holds no solid."""
    src = str(path)
    _quiet()
    doc = TDocStd_Document(TCollection_ExtendedString("XmlOcaf"))
    XCAFApp_Application.GetApplication_s().InitDocument(doc)
    reader = STEPCAFControl_Reader()
    reader.SetNameMode(True)
    if reader.ReadFile(src) != IFSelect_RetDone:
        raise MapError(f"{src}: not a readable STEP file (ISO 10303-21); export the assembly as STEP AP203/AP214")
    lengths, angles, solid_angles = (TColStd_SequenceOfAsciiString() for _ in range(3))
    reader.Reader().FileUnits(lengths, angles, solid_angles)
    declared = [str(lengths.Value(i + 1).ToCString()) for i in range(lengths.Length())]
    if not reader.Transfer(doc):
        raise MapError(f"{src}: OpenCascade could not transfer the STEP file's shapes")
    tool = XCAFDoc_DocumentTool.ShapeTool_s(doc.Main())
    layers = XCAFDoc_DocumentTool.LayerTool_s(doc.Main())
    bodies = [_body(name, on, solid) for name, on, solid in _solids(tool, layers, src)]
    if not bodies:
        raise MapError(f"{src}: no solid bodies in the STEP file (surfaces or wires only?); the parts must be solids")
    unit = UNIT_NAMES.get(declared[0].lower(), declared[0]) if declared else "mm"
    return bodies, unit
