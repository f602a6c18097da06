"""``femadh render RUN_DIR``: an off-screen PyVista picture of one state of an FE run - the
near-contact zone of the half-space, deformed (displacement magnified) and coloured by a
field (von Mises by default), with the axes in micrometres."""
import json
from pathlib import Path
import re

from ..errors import DependencyError, OutputError
from .atomic import save_atomic


def _pvd_entries(path):
    """(timestep, file) of the volume parts (part 0) of a .pvd collection, in order."""
    text = Path(path).read_text()
    out = []
    for m in re.finditer(r'timestep="([^"]+)"[^>]*part="(\d+)"[^>]*file="([^"]+)"', text):
        if m.group(2) == "0":
            out.append((float(m.group(1)), m.group(3)))
    return out


def render_run(run_dir, *, state=-1, field="von_mises", png=None, zoom=1.5):
    """Render state ``state`` (its number in the run; -1: the last approach state) of the FE run
    in ``run_dir`` to ``png`` (default RUN_DIR/render.png); returns the PNG path.

    Raises OutputError naming the folder when it holds no FE run with VTK output, and
    DependencyError when PyVista is not installed.
    """
    run_dir = Path(run_dir)
    try:
        import pyvista as pv
    except ImportError:
        raise DependencyError("femadh render needs pyvista: pip install 'femadh[fe]'") from None
    entries = []
    for branch in ("approach", "retract"):
        if (run_dir / f"{branch}.pvd").exists():
            entries += _pvd_entries(run_dir / f"{branch}.pvd")
    if not entries:
        raise OutputError(f"{run_dir} holds no FE run with VTK output (no approach.pvd): run "
                          "a scene with [solver] method = \"fe\" there first")
    if state == -1:
        approach = _pvd_entries(run_dir / "approach.pvd") if (run_dir / "approach.pvd").exists() \
            else entries
        t, rel = approach[-1]
    else:
        hits = [e for e in entries if int(e[0]) == state]
        if not hits:
            raise OutputError(f"{run_dir} has no state {state}; its VTK states are "
                              f"{int(entries[0][0])}..{int(entries[-1][0])}")
        t, rel = hits[0]
    summary = json.loads((run_dir / "summary.json").read_text())
    a = summary["scene"]["solver"]["analysis_radius_m"]
    mesh = pv.read(run_dir / rel)
    if field not in mesh.point_data:
        raise OutputError(f"{run_dir / rel} has no field {field!r}; it has "
                          + ", ".join(sorted(mesh.point_data.keys())))
    pv.OFF_SCREEN = True
    clip = mesh.clip_box([0, zoom * a, -zoom * a, 0, -1, 1], invert=False)
    disp = clip.point_data["displacement"]
    umax = max(float(abs(disp).max()), 1e-300)
    scale = 0.08 * a / umax
    warped = clip.warp_by_vector("displacement", factor=scale)
    warped.points[:] /= 1e-6
    pl = pv.Plotter(off_screen=True, window_size=(1100, 700))
    pl.add_mesh(warped, scalars=field, cmap="viridis", show_edges=True, edge_color="grey",
                line_width=0.3, scalar_bar_args={"title": field, "vertical": True})
    pl.add_text(f"{summary['scene']['name']}: state {int(t)}; displacement x {scale:.2g}; "
                "axes in um", font_size=10)
    pl.show_bounds(xtitle="r (um)", ytitle="z (um)", font_size=9)
    pl.view_xy()
    out = Path(png) if png else run_dir / "render.png"
    save_atomic(out, lambda p: pl.screenshot(str(p)))
    pl.close()
    return out
