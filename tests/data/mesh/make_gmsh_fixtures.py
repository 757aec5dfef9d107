"""Writes the Gmsh fixtures of tests/data/mesh with the real Gmsh (pip install gmsh==4.15.2).

    python3 tests/data/mesh/make_gmsh_fixtures.py

Each mesh is an OpenCascade box meshed transfinite and recombined into 8-node hexahedra,
with physical groups: the six faces of the box as surfaces named like tribo's block()
node sets ("x-", "x+", "y-", "y+", "z-", "z+"), the volume as "blank", and the corner at
the origin as the point group "origin". Files (MSH 4.1):

  block_4x2x2.msh        box [0,4]x[0,2]x[0,1], 4 x 2 x 2 cells, ASCII
  block_4x2x2_bin.msh    the same mesh, binary
  quarter_blank.msh      NUMISHEET'93 quarter blank [0,75]^2 x [0,0.81], 10 x 10 x 1, ASCII
  tetra_box.msh          a box in tetrahedra (unsupported: the importer must refuse it)
  block_4x2x2_v22.msh    block_4x2x2 in MSH 2.2, ASCII
  block_4x2x2_v22_bin.msh  the same in MSH 2.2, binary

The tests need only the committed outputs, never Gmsh.
"""
import os
import gmsh

HERE = os.path.dirname(os.path.abspath(__file__))


def box(name, size, cells, binary, hexahedra=True, version=4.1):
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add(name)
    lx, ly, lz = size
    vol = gmsh.model.occ.addBox(0, 0, 0, lx, ly, lz)
    gmsh.model.occ.synchronize()
    tol = 1e-6  # Gmsh pads bounding boxes by 1e-7
    if hexahedra:
        for _, curve in gmsh.model.getEntities(1):
            x0, y0, z0, x1, y1, z1 = gmsh.model.getBoundingBox(1, curve)
            axis = [x1 - x0, y1 - y0, z1 - z0].index(max([x1 - x0, y1 - y0, z1 - z0]))
            gmsh.model.mesh.setTransfiniteCurve(curve, cells[axis] + 1)
        for _, surf in gmsh.model.getEntities(2):
            gmsh.model.mesh.setTransfiniteSurface(surf)
            gmsh.model.mesh.setRecombine(2, surf)
        gmsh.model.mesh.setTransfiniteVolume(vol)
    else:
        gmsh.option.setNumber("Mesh.MeshSizeMax", max(size) / 2)
    # Physical groups named like tribo's block() faces.
    for _, surf in gmsh.model.getEntities(2):
        lo_hi = gmsh.model.getBoundingBox(2, surf)
        for axis, letter in enumerate("xyz"):
            if abs(lo_hi[axis + 3] - lo_hi[axis]) < tol:
                side = "-" if abs(lo_hi[axis]) < tol else "+"
                tag = gmsh.model.addPhysicalGroup(2, [surf])
                gmsh.model.setPhysicalName(2, tag, letter + side)
    tag = gmsh.model.addPhysicalGroup(3, [vol])
    gmsh.model.setPhysicalName(3, tag, "blank")
    for _, pt in gmsh.model.getEntities(0):
        x0, y0, z0, _, _, _ = gmsh.model.getBoundingBox(0, pt)
        if abs(x0) + abs(y0) + abs(z0) < tol:
            tag = gmsh.model.addPhysicalGroup(0, [pt])
            gmsh.model.setPhysicalName(0, tag, "origin")
    gmsh.model.mesh.generate(3)
    gmsh.option.setNumber("Mesh.MshFileVersion", version)
    gmsh.option.setNumber("Mesh.Binary", 1 if binary else 0)
    gmsh.write(os.path.join(HERE, name + ".msh"))
    gmsh.finalize()


box("block_4x2x2", (4.0, 2.0, 1.0), (4, 2, 2), binary=False)
box("block_4x2x2_bin", (4.0, 2.0, 1.0), (4, 2, 2), binary=True)
box("quarter_blank", (75.0, 75.0, 0.81), (10, 10, 1), binary=False)
box("tetra_box", (1.0, 1.0, 1.0), (1, 1, 1), binary=False, hexahedra=False)
box("block_4x2x2_v22", (4.0, 2.0, 1.0), (4, 2, 2), binary=False, version=2.2)
box("block_4x2x2_v22_bin", (4.0, 2.0, 1.0), (4, 2, 2), binary=True, version=2.2)
