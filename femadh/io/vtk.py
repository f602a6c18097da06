"""VTK output of FE states for ParaView/PyVista (written with meshio).

Per state: ``vtk/<branch>_<k>.vtu`` with the (r, z) mesh (x = r, y = z) as quadratic triangles
("triangle6": the P2 nodes, so the volume keeps the FE solution's resolution), the displacement
as a 3-component vector (u_r, u_z, 0) for ParaView's "Warp By Vector", the stresses sigma_rr,
sigma_zz, sigma_tt, sigma_rz and von Mises (Pa, L2-projected onto continuous P2 in each
region), the cell data ``region`` (0 = top layer ... substrate; interface nodes are repeated per
region so stress jumps stay sharp), and
``vtk/<branch>_surface_<k>.vtu`` with the surface polyline: w, gap h, P_LJ, contact pressure.
``<branch>.pvd`` collects them with the timestep = the state number, so ParaView plays the
sweep in the order it ran (d is a field of every file). Every file is written to a temporary
name and renamed into place: a reader (or a resumed run) never sees half a file.
"""
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np

from ..elastic.fe.fields import fe_point_fields
from .atomic import save_atomic, write_atomic


def write_state(out_dir, branch, index, state, problem):
    """Write the volume and surface .vtu of one state; returns their paths (relative)."""
    import meshio

    op = problem.operator
    vdir = Path(out_dir) / "vtk"
    vdir.mkdir(parents=True, exist_ok=True)
    u = op.full_field(state.p_total)
    fields = fe_point_fields(op, u)
    proj = op.field_projector
    pts = np.column_stack([proj.points, np.zeros(len(proj.points))])
    vol = f"{branch}_{index:04d}.vtu"
    mesh = meshio.Mesh(pts, [("triangle6", proj.cells)], point_data=fields,
                       cell_data={"region": [proj.cell_region]})
    save_atomic(vdir / vol, lambda tmp: meshio.write(tmp, mesh, file_format="vtu"))
    r = problem.grid.nodes
    spts = np.column_stack([r, state.w, np.zeros_like(r)])
    lines = np.column_stack([np.arange(r.size - 1), np.arange(1, r.size)])
    sdata = {"w": state.w, "gap": state.h, "P_contact": state.p_contact,
             "P_net": state.p_total}
    for name, pr in state.p_effects.items():
        sdata[f"P_{name}"] = pr
    surf = f"{branch}_surface_{index:04d}.vtu"
    smesh = meshio.Mesh(spts, [("line", lines)], point_data=sdata)
    save_atomic(vdir / surf, lambda tmp: meshio.write(tmp, smesh, file_format="vtu"))
    return f"vtk/{vol}", f"vtk/{surf}"


def write_pvd(path, entries):
    """ParaView collection: entries = [(timestep, file, part)]; rewritten whole each time."""
    rows = "\n".join(f'    <DataSet timestep="{t!r}" group="" part="{part}" file={quoteattr(f)}/>'
                     for t, f, part in entries)
    write_atomic(path, '<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n'
                 f"  <Collection>\n{rows}\n  </Collection>\n</VTKFile>\n")
