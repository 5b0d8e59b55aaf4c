"""Generates the Gmsh MSH 4.1 ASCII fixtures read by palpate-fe's tests.

Run from this directory with the Gmsh Python API (`pip install gmsh`; the
committed files were made with gmsh 4.15.2):

    python3 make_gmsh_fixtures.py

* inclusion_quad4.msh  — the rectangle [0, 10] x [0, 6] with a disk of
  radius 1.5 centred at (5, 3), meshed in 4-node quadrilaterals (recombined,
  then subdivided so no triangle is left). Physical surfaces `matrix` and
  `inclusion`; physical curves `bottom` (y = 0), `top` (y = 6), `left`
  (x = 0), `right` (x = 10) and `interface` (the circle); physical point
  `origin` (0, 0).
* inclusion_quad9.msh  — the same geometry and groups, second order (9-node
  quadrilaterals, 3-node lines; mid-nodes on the circle lie on it).
* box_hex8.msh — the box [0, 2] x [0, 1] x [0, 1] as a transfinite 4 x 2 x 2
  grid of 8-node hexahedra. Physical volume `box`; physical surfaces `bottom`
  (z = 0) and `top` (z = 1). No physical point.
"""

import gmsh


def common_options():
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
    gmsh.option.setNumber("Mesh.Binary", 0)


def entities_in_box(dim, x0, y0, z0, x1, y1, z1, eps=1e-6):
    found = gmsh.model.getEntitiesInBoundingBox(
        x0 - eps, y0 - eps, z0 - eps, x1 + eps, y1 + eps, z1 + eps, dim
    )
    return [tag for (_, tag) in found]


def inclusion(order, path):
    gmsh.initialize()
    common_options()
    gmsh.model.add("inclusion")
    occ = gmsh.model.occ
    rect = occ.addRectangle(0, 0, 0, 10, 6)
    disk = occ.addDisk(5, 3, 0, 1.5, 1.5)
    out, _ = occ.fragment([(2, rect)], [(2, disk)])
    occ.synchronize()
    # The disk is the surface whose bounding box lies within the circle's.
    inner = entities_in_box(2, 3.5, 1.5, 0, 6.5, 4.5, 0)
    outer = [t for (d, t) in out if d == 2 and t not in inner]
    gmsh.model.addPhysicalGroup(2, outer, name="matrix")
    gmsh.model.addPhysicalGroup(2, inner, name="inclusion")
    gmsh.model.addPhysicalGroup(1, entities_in_box(1, 0, 0, 0, 10, 0, 0), name="bottom")
    gmsh.model.addPhysicalGroup(1, entities_in_box(1, 0, 6, 0, 10, 6, 0), name="top")
    gmsh.model.addPhysicalGroup(1, entities_in_box(1, 0, 0, 0, 0, 6, 0), name="left")
    gmsh.model.addPhysicalGroup(1, entities_in_box(1, 10, 0, 0, 10, 6, 0), name="right")
    gmsh.model.addPhysicalGroup(1, entities_in_box(1, 3.5, 1.5, 0, 6.5, 4.5, 0), name="interface")
    gmsh.model.addPhysicalGroup(0, entities_in_box(0, 0, 0, 0, 0, 0, 0), name="origin")
    gmsh.option.setNumber("Mesh.MeshSizeMax", 1.0)
    gmsh.option.setNumber("Mesh.RecombineAll", 1)
    gmsh.option.setNumber("Mesh.Algorithm", 8)
    # Subdivide the recombined mesh so that every cell is a quadrilateral.
    gmsh.option.setNumber("Mesh.SubdivisionAlgorithm", 1)
    gmsh.option.setNumber("Mesh.ElementOrder", order)
    gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 0)
    gmsh.model.mesh.generate(2)
    gmsh.write(path)
    gmsh.finalize()


def box(path):
    gmsh.initialize()
    common_options()
    gmsh.model.add("box")
    occ = gmsh.model.occ
    vol = occ.addBox(0, 0, 0, 2, 1, 1)
    occ.synchronize()
    for c in gmsh.model.getEntities(1):
        lo = gmsh.model.getBoundingBox(*c)
        length = max(lo[3] - lo[0], lo[4] - lo[1], lo[5] - lo[2])
        gmsh.model.mesh.setTransfiniteCurve(c[1], 5 if length > 1.5 else 3)
    for s in gmsh.model.getEntities(2):
        gmsh.model.mesh.setTransfiniteSurface(s[1])
        gmsh.model.mesh.setRecombine(2, s[1])
    gmsh.model.mesh.setTransfiniteVolume(vol)
    gmsh.model.addPhysicalGroup(3, [vol], name="box")
    gmsh.model.addPhysicalGroup(2, entities_in_box(2, 0, 0, 0, 2, 1, 0), name="bottom")
    gmsh.model.addPhysicalGroup(2, entities_in_box(2, 0, 0, 1, 2, 1, 1), name="top")
    gmsh.model.mesh.generate(3)
    gmsh.write(path)
    gmsh.finalize()


if __name__ == "__main__":
    inclusion(1, "inclusion_quad4.msh")
    inclusion(2, "inclusion_quad9.msh")
    box("box_hex8.msh")
