"""NUMISHEET'93 square-cup punch and die built by OpenCascade (cadquery-ocp), exported
as IGES 5.3 and STEP AP214, for tribo's CAD import tests (tests/cad_import.rs).

Run from this folder:   pip install cadquery-ocp && python3 make_numisheet93_tools.py

Dimensions (mm) as in std-lib/numisheet93.rhai and src/geometry/builders.rs:
  punch: rounded square of side 70, plan corner radius 10, nose radius 8, flat nose at
         z = 0, 58 mm high (8 of nose radius + 50 of wall);
  die:   160 x 160 block, top at z = 0, 58 mm deep, with a rounded-square opening of side
         74 and plan corner radius 12, its top edge rounded by an entry radius of 8.
Both are made as OCC makes them from a sketch: a box, the vertical edges filleted (plan
corners), then the edges of the working face filleted (nose / entry radius).

OCC writes planes, cylinders and tori as analytic entities: in IGES, 108 planes trimmed by
model-space curves and 120 surfaces of revolution (line or arc generatrix) trimmed in
their (t, angle) parameters. tribo reads those (`punch_analytic.igs`, `die_analytic.igs`)
and, from both formats, rational B-spline surfaces, for which each solid is converted with
BRepBuilderAPI_NurbsConvert (exact: circles and tori become rational quadratic B-splines)
before the `*_nurbs.igs` / `*_nurbs.step` export. `punch_analytic.step` and
`die_analytic.step` are the solids as STEP writes them by default (PLANE,
CYLINDRICAL_SURFACE, TOROIDAL_SURFACE), read as the exact NURBS they are.

`punch_assembly.step` is an assembly (OCC's XCAF document, STEPCAFControl_Writer) holding
the NURBS punch as a component placed by a rotation of 30 degrees about z then a
translation (5, -3, 2.5): CONTEXT_DEPENDENT_SHAPE_REPRESENTATION with an
ITEM_DEFINED_TRANSFORMATION, which tribo applies.
"""
from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox
from OCP.BRepFilletAPI import BRepFilletAPI_MakeFillet
from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut
from OCP.BRepBuilderAPI import BRepBuilderAPI_NurbsConvert
from OCP.TopExp import TopExp_Explorer
from OCP.TopAbs import TopAbs_EDGE
from OCP.TopoDS import TopoDS
from OCP.BRepAdaptor import BRepAdaptor_Curve
from OCP.gp import gp_Pnt
from OCP.IGESControl import IGESControl_Controller, IGESControl_Writer
from OCP.STEPControl import STEPControl_Writer, STEPControl_AsIs
from OCP.Interface import Interface_Static
from OCP.BRepCheck import BRepCheck_Analyzer


def edges(shape, keep):
    """Edges of `shape` whose two end points and midpoint satisfy keep(x, y, z)."""
    out = []
    ex = TopExp_Explorer(shape, TopAbs_EDGE)
    while ex.More():
        e = TopoDS.Edge(ex.Current())
        c = BRepAdaptor_Curve(e)
        ts = (c.FirstParameter(), 0.5 * (c.FirstParameter() + c.LastParameter()), c.LastParameter())
        if all(keep(*(lambda p: (p.X(), p.Y(), p.Z()))(c.Value(t))) for t in ts):
            out.append(e)
        ex.Next()
    return out


def fillet(shape, radius, keep):
    f = BRepFilletAPI_MakeFillet(shape)
    chosen = edges(shape, keep)
    assert chosen, "no edge to fillet"
    for e in chosen:
        f.Add(radius, e)
    f.Build()
    assert f.IsDone()
    return f.Shape()


def rounded_box(half, corner, z0, z1):
    box = BRepPrimAPI_MakeBox(gp_Pnt(-half, -half, z0), gp_Pnt(half, half, z1)).Shape()
    vertical = lambda x, y, z: abs(abs(x) - half) < 1e-9 and abs(abs(y) - half) < 1e-9
    return fillet(box, corner, vertical)


def punch():
    body = rounded_box(35.0, 10.0, 0.0, 58.0)
    return fillet(body, 8.0, lambda x, y, z: abs(z) < 1e-9)


def die():
    block = BRepPrimAPI_MakeBox(gp_Pnt(-80, -80, -58), gp_Pnt(80, 80, 0)).Shape()
    hole = rounded_box(37.0, 12.0, -60.0, 2.0)
    cut = BRepAlgoAPI_Cut(block, hole).Shape()
    opening_top = lambda x, y, z: abs(z) < 1e-9 and max(abs(x), abs(y)) < 37.0 + 1e-9
    return fillet(cut, 8.0, opening_top)


def nurbs(shape):
    c = BRepBuilderAPI_NurbsConvert(shape, True)
    out = c.Shape()
    assert BRepCheck_Analyzer(out).IsValid()
    return out


def write_iges(shape, path):
    IGESControl_Controller.Init_s()
    Interface_Static.SetIVal_s("write.iges.brep.mode", 0)  # faces: 144 trimmed surfaces
    w = IGESControl_Writer("MM", 0)
    assert w.AddShape(shape)
    w.ComputeModel()
    assert w.Write(path)


def write_step(shape, path):
    Interface_Static.SetCVal_s("write.step.schema", "AP214IS")
    Interface_Static.SetCVal_s("write.step.unit", "MM")
    w = STEPControl_Writer()
    w.Transfer(shape, STEPControl_AsIs)
    assert w.Write(path) == 1


def write_assembly(part, path):
    """`part` as the one component of an assembly, placed (see the module docs)."""
    import math
    from OCP.gp import gp_Trsf, gp_Vec, gp_Ax1, gp_Pnt, gp_Dir
    from OCP.TopLoc import TopLoc_Location
    from OCP.TDocStd import TDocStd_Document
    from OCP.XCAFApp import XCAFApp_Application
    from OCP.XCAFDoc import XCAFDoc_DocumentTool
    from OCP.TCollection import TCollection_ExtendedString
    from OCP.STEPCAFControl import STEPCAFControl_Writer
    rotation = gp_Trsf()
    rotation.SetRotation(gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), math.radians(30))
    translation = gp_Trsf()
    translation.SetTranslation(gp_Vec(5.0, -3.0, 2.5))
    doc = TDocStd_Document(TCollection_ExtendedString("MDTV-XCAF"))
    XCAFApp_Application.GetApplication_s().InitDocument(doc)
    shapes = XCAFDoc_DocumentTool.ShapeTool_s(doc.Main())
    assembly = shapes.NewShape()
    component = shapes.AddShape(part, False)
    shapes.AddComponent(assembly, component, TopLoc_Location(translation.Multiplied(rotation)))
    shapes.UpdateAssemblies()
    Interface_Static.SetCVal_s("write.step.schema", "AP214IS")
    Interface_Static.SetCVal_s("write.step.unit", "MM")
    w = STEPCAFControl_Writer()
    assert w.Transfer(doc, STEPControl_AsIs)
    assert w.Write(path) == 1


if __name__ == "__main__":
    p, d = punch(), die()
    write_iges(p, "punch_analytic.igs")
    write_step(p, "punch_analytic.step")
    write_iges(d, "die_analytic.igs")
    write_step(d, "die_analytic.step")
    for name, shape in (("punch", p), ("die", d)):
        n = nurbs(shape)
        write_iges(n, f"{name}_nurbs.igs")
        write_step(n, f"{name}_nurbs.step")
        if name == "punch":
            write_assembly(n, "punch_assembly.step")
