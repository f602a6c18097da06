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

Binary, uncompressed: zlib took 80 ms of a state's ~95 ms (1.1 MB of the 200-node Fig 3
body), the raw arrays 8 ms for 1.8 MB (validation/results/fe_pace.md). A run streams these
files only with ``[output] vtk = true``; :func:`export_states` writes the states a user asks
for afterwards from ``fields.csv`` (what ``femadh render`` does).
"""
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np

from ..contact.state import net_pressure
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
    save_atomic(vdir / vol, lambda tmp: meshio.write(tmp, mesh, file_format="vtu",
                                                     compression=None))
    r = problem.grid.nodes
    spts = np.column_stack([r, state.w, np.zeros_like(r)])
    lines = np.column_stack([np.arange(r.size - 1), np.arange(1, r.size)])
    sdata = {"w": state.w, "gap": state.h, "P_contact": state.p_contact,
             "P_net": state.p_total}
    for name, pr in state.p_effects.items():
        sdata[f"P_{name}"] = pr
    surf = f"{branch}_surface_{index:04d}.vtu"
    smesh = meshio.Mesh(spts, [("line", lines)], point_data=sdata)
    save_atomic(vdir / surf, lambda tmp: meshio.write(tmp, smesh, file_format="vtu",
                                                      compression=None))
    return f"vtk/{vol}", f"vtk/{surf}"


def write_pvd(path, entries):
    """ParaView collection: entries = [(timestep, file, part)]; rewritten whole each time."""
    rows = "\n".join(f'    <DataSet timestep="{t!r}" group="" part="{part}" file={quoteattr(f)}/>'
                     for t, f, part in entries)
    write_atomic(path, '<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n'
                 f"  <Collection>\n{rows}\n  </Collection>\n</VTKFile>\n")


class _SavedState:
    """The parts of a State that the VTK writer reads, rebuilt from fields.csv."""

    def __init__(self, d, w, h, p_effects, p_contact):
        self.d, self.w, self.h = d, w, h
        self.p_effects, self.p_contact = p_effects, p_contact

    @property
    def p_total(self):
        return net_pressure(self.p_effects, self.p_contact)


def saved_states(run_dir, problem, states):
    """{state number: (branch, state)} of a run folder's committed states, rebuilt from
    ``fields.csv`` (w, h and every pressure on every node, written as exact float reprs)."""
    import csv

    from ..laws.registry import extra_outputs

    extra = extra_outputs(problem)
    want = set(int(k) for k in states)
    rows = {}
    with open(Path(run_dir) / "fields.csv", newline="") as f:
        for r in csv.DictReader(f):
            k = int(r["state"])
            if k in want:
                rows.setdefault(k, []).append(r)
    out = {}
    for k, rs in rows.items():
        col = (lambda name: np.array([float(r[name]) for r in rs]))
        eff = {"lj": col("P_LJ_Pa")} if "lj" in problem.effects else {}
        for o in extra:
            eff[o.name] = col(o.field)
        out[k] = (rs[0]["branch"], _SavedState(float(rs[0]["d_m"]), col("w_m"), col("h_m"),
                                               eff, col("P_el_Pa")))
    return out


def export_states(run_dir, states, problem=None):
    """Write the volume and surface VTK files of the given committed states of an FE run
    folder (numbers as in curve.csv's ``state``) and a ``<branch>.pvd`` listing every state
    file in ``vtk/``; returns {state: (volume file, surface file)} (relative to run_dir).

    The scene is read again from the file summary.json names and must be the one that ran
    (same scene id); its condensed operator comes from the operator cache and the body is
    factorised here, once. Raises OutputError with the reason otherwise."""
    import re

    from ..errors import OutputError

    run_dir = Path(run_dir)
    if problem is None:
        problem = _run_problem(run_dir)
    if problem.operator.name != "fe":
        raise OutputError(f"{run_dir} holds a Green-function run: VTK needs [solver] method = "
                          "\"fe\" (the Green operator has no interior field)")
    saved = saved_states(run_dir, problem, states)
    missing = sorted(set(int(k) for k in states) - set(saved))
    if missing:
        raise OutputError(f"{run_dir} has no committed state {missing[0]} in fields.csv")
    out = {}
    for k, (branch, st) in sorted(saved.items()):
        out[k] = write_state(run_dir, branch, k, st, problem)
    # the collections list every state file present (those streamed and those exported)
    files = {}
    for f in sorted((run_dir / "vtk").glob("*.vtu")):
        m = re.fullmatch(r"(approach|retract)(_surface)?_(\d+)\.vtu", f.name)
        if m:
            files.setdefault(m.group(1), []).append(
                (int(m.group(3)), f"vtk/{f.name}", 1 if m.group(2) else 0))
    for branch, entries in files.items():
        write_pvd(run_dir / f"{branch}.pvd", sorted(entries))
    return out


def _run_problem(run_dir):
    """The problem of the scene that ran in ``run_dir`` (from summary.json's scene file)."""
    import json

    from ..errors import OutputError
    from ..scene import build_problem, load_scene, scene_id

    try:
        summary = json.loads((run_dir / "summary.json").read_text())
    except (OSError, ValueError):
        raise OutputError(f"{run_dir} holds no femadh run (no readable summary.json)") from None
    path = summary.get("scene_file")
    if not path or not Path(path).exists():
        raise OutputError(f"{run_dir}: its scene file {path!r} is gone, so its states cannot "
                          "be exported; run the scene with [output] vtk = true")
    scene = load_scene(path)
    if scene_id(scene) != summary.get("scene_id"):
        raise OutputError(f"{run_dir}: {path} changed since the run (another scene id); run it "
                          "again, or with [output] vtk = true to keep every state's VTK")
    return build_problem(scene)
