"""One face on each analytic surface kind, written as STEP AP214 by OpenCascade, for
tribo's STEP analytic-surface tests (tests/cad_step_analytic.rs).

Run from this folder:   pip install cadquery-ocp-novtk==8.0.1.1.0 && python3 generate_analytic_faces.py

Every surface is placed in the same tilted frame: origin (1, 2, 3), axis along
(0.2, -0.3, 1), reference direction (1, 0.1, 0.04) made orthogonal to the axis (gp_Ax3),
so that no coordinate is special. Faces (parameters as STEP defines them; angles in
radians; tests/cad_step_analytic.rs holds the same numbers):

  analytic_plane.step      PLANE, the rectangle [-6, 6] x [-4, 5] with a round hole of
                           radius 1.5 about (1, 0.5): circle and line pcurves
  analytic_cylinder.step   CYLINDRICAL_SURFACE R 4, u in [0.3, 4], v in [-1, 2.5]
  analytic_band.step       CYLINDRICAL_SURFACE R 4, the whole turn, v in [0, 3]: a seam
  analytic_cone.step       CONICAL_SURFACE R 3, semi-angle 0.4, u in [0.3, 4], v in [-1, 2.5]
  analytic_sphere.step     SPHERICAL_SURFACE R 5, u in [0.3, 4], v in [-1, 1.2]
  analytic_torus.step      TOROIDAL_SURFACE R 5 r 2, u in [0.3, 4], v in [-1, 2.5]
  analytic_spindle.step    the spindle torus R 2 r 5 (OCC writes it as a
                           SURFACE_OF_REVOLUTION of its profile), u in [0.3, 4], v in [-1, 1]
  analytic_revolution.step SURFACE_OF_REVOLUTION of a rational B-spline (an ellipse arc),
                           u in [0.3, 4], v its whole range
  analytic_extrusion.step  SURFACE_OF_LINEAR_EXTRUSION of a circle of radius 3 along
                           (0.3, 0.2, 1), u in [0.5, 3], v in [0, 2.5]
  analytic_offset.step     OFFSET_SURFACE 1.5 of the cylinder of radius 4
"""
import math
from OCP.gp import gp_Pnt, gp_Dir, gp_Ax3, gp_Ax1, gp_Ax2, gp_Vec, gp_Circ, gp_Pnt2d
from OCP.Geom import (Geom_Plane, Geom_CylindricalSurface, Geom_ConicalSurface,
                      Geom_SphericalSurface, Geom_ToroidalSurface, Geom_SurfaceOfRevolution,
                      Geom_SurfaceOfLinearExtrusion, Geom_OffsetSurface, Geom_Circle)
from OCP.Geom import Geom_Ellipse, Geom_TrimmedCurve
from OCP.GeomConvert import GeomConvert
from OCP.BRepBuilderAPI import (BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakeEdge,
                                BRepBuilderAPI_MakeWire)
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.STEPControl import STEPControl_Writer, STEPControl_AsIs
from OCP.Interface import Interface_Static

FRAME = gp_Ax3(gp_Pnt(1, 2, 3), gp_Dir(0.2, -0.3, 1.0), gp_Dir(1.0, 0.1, 0.04))


def write(face, name):
    assert BRepCheck_Analyzer(face).IsValid(), name
    Interface_Static.SetCVal_s("write.step.schema", "AP214IS")
    Interface_Static.SetCVal_s("write.step.unit", "MM")
    w = STEPControl_Writer()
    w.Transfer(face, STEPControl_AsIs)
    assert w.Write(f"analytic_{name}.step") == 1


def patch(surface, u0, u1, v0, v1):
    f = BRepBuilderAPI_MakeFace(surface, u0, u1, v0, v1, 1e-7)
    assert f.IsDone()
    return f.Face()


def holed_plane():
    plane = Geom_Plane(FRAME)
    outer = patch(plane, -6.0, 6.0, -4.0, 5.0)
    centre = plane.Value(1.0, 0.5)
    hole = gp_Circ(gp_Ax2(centre, FRAME.Direction(), FRAME.XDirection()), 1.5)
    wire = BRepBuilderAPI_MakeWire(BRepBuilderAPI_MakeEdge(hole).Edge()).Wire()
    wire.Reverse()  # a hole runs against the outer loop
    f = BRepBuilderAPI_MakeFace(outer)
    f.Add(wire)
    return f.Face()


def profile_spline():
    """A rational B-spline in the frame's (x, z) half plane, off the axis: the arc of the
    ellipse of centre o + 4 x, semi-axes 1.5 (along x) and 1 (along z), from 0.2 to 2.0,
    converted by GeomConvert."""
    o, x, z = FRAME.Location(), FRAME.XDirection(), FRAME.Direction()
    centre = gp_Pnt(o.X() + 4 * x.X(), o.Y() + 4 * x.Y(), o.Z() + 4 * x.Z())
    # gp_Ax2(P, N, Vx): the ellipse's plane normal N = -y so that its y axis is z.
    normal = gp_Dir(-FRAME.YDirection().X(), -FRAME.YDirection().Y(), -FRAME.YDirection().Z())
    ellipse = Geom_Ellipse(gp_Ax2(centre, normal, x), 1.5, 1.0)
    return GeomConvert.CurveToBSplineCurve_s(Geom_TrimmedCurve(ellipse, 0.2, 2.0))


if __name__ == "__main__":
    axis = gp_Ax1(FRAME.Location(), FRAME.Direction())
    write(holed_plane(), "plane")
    write(patch(Geom_CylindricalSurface(FRAME, 4.0), 0.3, 4.0, -1.0, 2.5), "cylinder")
    write(patch(Geom_CylindricalSurface(FRAME, 4.0), 0.0, 2 * math.pi, 0.0, 3.0), "band")
    write(patch(Geom_ConicalSurface(FRAME, 0.4, 3.0), 0.3, 4.0, -1.0, 2.5), "cone")
    write(patch(Geom_SphericalSurface(FRAME, 5.0), 0.3, 4.0, -1.0, 1.2), "sphere")
    write(patch(Geom_ToroidalSurface(FRAME, 5.0, 2.0), 0.3, 4.0, -1.0, 2.5), "torus")
    write(patch(Geom_ToroidalSurface(FRAME, 2.0, 5.0), 0.3, 4.0, -1.0, 1.0), "spindle")
    spline = profile_spline()
    rev = Geom_SurfaceOfRevolution(spline, axis)
    write(patch(rev, 0.3, 4.0, spline.FirstParameter(), spline.LastParameter()), "revolution")
    circle = Geom_Circle(FRAME.Ax2(), 3.0)
    ext = Geom_SurfaceOfLinearExtrusion(circle, gp_Dir(0.3, 0.2, 1.0))
    write(patch(ext, 0.5, 3.0, 0.0, 2.5), "extrusion")
    off = Geom_OffsetSurface(Geom_CylindricalSurface(FRAME, 4.0), 1.5)
    write(patch(off, 0.3, 4.0, -1.0, 2.5), "offset")
