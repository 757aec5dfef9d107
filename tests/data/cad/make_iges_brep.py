"""IGES BRep fixtures (IGES 5.3 186 solids, 514 shells, 510 faces, 508 loops, 504 edges,
502 vertices) written by OpenCascade in BRep mode (write.iges.brep.mode = 1), for tribo's
IGES BRep tests (tests/cad_iges_brep.rs, tests/cad_import.rs, tests/cad_square_cup.rs).

Run from this folder:   pip install cadquery-ocp-novtk==8.0.1.1.0 && python3 make_iges_brep.py

  punch_brep.igs, die_brep.igs  the NUMISHEET'93 punch and die of make_numisheet93_tools.py
                                as solids: 190 planes, 192 cylinders, 198 tori (the punch's
                                corners spindle tori, major 2 minor 8)
  punch_nurbs_brep.igs          the punch after BRepBuilderAPI_NurbsConvert: 128 faces
                                trimmed by 126 parameter-space curves
  brep_<kind>.igs               one face on each analytic kind, in the frame origin
                                (1, 2, 3), axis (0.6, 0, 0.8), reference direction (0, 1, 0)
                                (so y = axis x x = (-0.8, 0, 0.6)): numbers IGES's ten
                                digits write exactly. Angles in radians:
    plane      190, the rectangle [-6, 6] x [-4, 5] with a round hole of radius 1.5 about
               (1, 0.5)
    cylinder   192 R 4, u in [0.3, 4], v in [-1, 2.5]
    cone       194 R 3, semi-angle 30 degrees, u in [0.3, 4], v in [-1, 2.5] (OCC's v,
               the slant length)
    sphere     196 R 5, u in [0.3, 4], v in [-1, 1.2]
    torus      198 R 5 r 2, u in [0.3, 4], v in [-1, 2.5]
    spindle    198 R 2 r 5, u in [0.3, 4], v in [-1, 1]
"""
import math
from OCP.gp import gp_Pnt, gp_Dir, gp_Ax3, gp_Ax2, gp_Circ
from OCP.Geom import (Geom_Plane, Geom_CylindricalSurface, Geom_ConicalSurface,
                      Geom_SphericalSurface, Geom_ToroidalSurface)
from OCP.BRepBuilderAPI import (BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakeEdge,
                                BRepBuilderAPI_MakeWire)
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.IGESControl import IGESControl_Controller, IGESControl_Writer
from OCP.Interface import Interface_Static
from make_numisheet93_tools import punch, die, nurbs

FRAME = gp_Ax3(gp_Pnt(1, 2, 3), gp_Dir(0.6, 0.0, 0.8), gp_Dir(0.0, 1.0, 0.0))


def write_iges_brep(shape, path):
    assert BRepCheck_Analyzer(shape).IsValid(), path
    IGESControl_Controller.Init_s()
    Interface_Static.SetIVal_s("write.iges.brep.mode", 1)  # BRep: 186/514/510/508/504/502
    w = IGESControl_Writer("MM", 1)
    assert w.AddShape(shape)
    w.ComputeModel()
    assert w.Write(path)


def patch(surface, u0, u1, v0, v1):
    f = BRepBuilderAPI_MakeFace(surface, u0, u1, v0, v1, 1e-7)
    assert f.IsDone()
    return f.Face()


def holed_plane():
    plane = Geom_Plane(FRAME)
    outer = patch(plane, -6.0, 6.0, -4.0, 5.0)
    hole = gp_Circ(gp_Ax2(plane.Value(1.0, 0.5), FRAME.Direction(), FRAME.XDirection()), 1.5)
    wire = BRepBuilderAPI_MakeWire(BRepBuilderAPI_MakeEdge(hole).Edge()).Wire()
    wire.Reverse()  # a hole runs against the outer loop
    f = BRepBuilderAPI_MakeFace(outer)
    f.Add(wire)
    return f.Face()


if __name__ == "__main__":
    p = punch()
    write_iges_brep(p, "punch_brep.igs")
    write_iges_brep(die(), "die_brep.igs")
    write_iges_brep(nurbs(p), "punch_nurbs_brep.igs")
    write_iges_brep(holed_plane(), "brep_plane.igs")
    kinds = {
        "cylinder": (Geom_CylindricalSurface(FRAME, 4.0), -1.0, 2.5),
        "cone": (Geom_ConicalSurface(FRAME, math.radians(30.0), 3.0), -1.0, 2.5),
        "sphere": (Geom_SphericalSurface(FRAME, 5.0), -1.0, 1.2),
        "torus": (Geom_ToroidalSurface(FRAME, 5.0, 2.0), -1.0, 2.5),
        "spindle": (Geom_ToroidalSurface(FRAME, 2.0, 5.0), -1.0, 1.0),
    }
    for name, (surface, v0, v1) in kinds.items():
        write_iges_brep(patch(surface, 0.3, 4.0, v0, v1), f"brep_{name}.igs")
