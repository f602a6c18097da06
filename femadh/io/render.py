"""``femadh render RUN_DIR``: an off-screen PyVista picture of one state of an FE run - the
near-contact zone of the half-space, deformed (displacement magnified) and coloured by a
field (von Mises by default) in MPa (displacements in nm), with the axes in micrometres.

A run writes its states' VTK only with ``[output] vtk = true``; otherwise the state asked for
is exported first from fields.csv (:func:`femadh.io.vtk.export_states`, ~1-2 s for the body's
factorisation) and kept in ``vtk/`` beside the picture. On a machine without a display VTK
renders through EGL (no X server, no warning).
"""
import json
import os
from pathlib import Path
import re

import numpy as np

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


#: what each field is called on the colour bar, its unit, and the factor from SI to it
FIELD_LABELS = {"von_mises": ("von Mises stress", "MPa", 1e-6),
                "sigma_rr": ("σ_rr", "MPa", 1e-6), "sigma_zz": ("σ_zz", "MPa", 1e-6),
                "sigma_tt": ("σ_θθ", "MPa", 1e-6), "sigma_rz": ("σ_rz", "MPa", 1e-6),
                "displacement": ("|displacement|", "nm", 1e9)}


def _headless():
    """Without a display, render through EGL: VTK's default X window would print a 'bad X
    server connection' warning before falling back."""
    if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")


def _states(run_dir):
    """(state, branch) of the committed states in curve.csv."""
    import csv

    with open(run_dir / "curve.csv", newline="") as f:
        return [(int(r["state"]), r["branch"]) for r in csv.DictReader(f)]


def render_run(run_dir, *, state=-1, field="von_mises", png=None, zoom=1.5):
    """Render state ``state`` (its number in the run, as in curve.csv; -1: the last approach
    state) of the FE run in ``run_dir`` to ``png`` (default RUN_DIR/render.png); returns the
    PNG path. A state without VTK files is exported first (:func:`~.vtk.export_states`).

    Raises OutputError naming the folder when it holds no FE run or no such state, and
    DependencyError when PyVista is not installed.
    """
    run_dir = Path(run_dir)
    _headless()
    try:
        import pyvista as pv
    except ImportError:
        raise DependencyError("femadh render needs pyvista: pip install 'femadh[fe]'") from None
    if not (run_dir / "curve.csv").exists():
        raise OutputError(f"{run_dir} holds no femadh run (no curve.csv)")
    states = _states(run_dir)
    if not states:
        raise OutputError(f"{run_dir} holds no committed state")
    if state == -1:
        app = [k for k, b in states if b == "approach"] or [k for k, _ in states]
        state = app[-1]
    if state not in {k for k, _ in states}:
        raise OutputError(f"{run_dir} has no state {state}; its states are "
                          f"{states[0][0]}..{states[-1][0]}")
    entries = []
    for branch in ("approach", "retract"):
        if (run_dir / f"{branch}.pvd").exists():
            entries += _pvd_entries(run_dir / f"{branch}.pvd")
    # a listed file that is gone (deleted by hand) is exported again
    hits = [rel for t, rel in entries if int(t) == state and (run_dir / rel).exists()]
    if hits:
        rel = hits[0]
    else:
        from .vtk import export_states

        rel = export_states(run_dir, [state])[state][0]
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
    name, unit, factor = FIELD_LABELS.get(field, (field, "SI", 1.0))
    values = np.asarray(clip.point_data[field]) * factor
    if values.ndim == 2:
        values = np.linalg.norm(values, axis=1)
    shown = f"{name} ({unit})"
    clip.point_data[shown] = values
    warped = clip.warp_by_vector("displacement", factor=scale)
    warped.points[:] /= 1e-6
    pl = pv.Plotter(off_screen=True, window_size=(1100, 700))
    # the bar inside the window (the default sits on its right edge, labels cut off)
    pl.add_mesh(warped, scalars=shown, cmap="viridis", show_edges=True, edge_color="grey",
                line_width=0.3,
                scalar_bar_args={"title": shown, "vertical": True, "fmt": "%.3g",
                                 "position_x": 0.80, "position_y": 0.15, "width": 0.06,
                                 "height": 0.7, "title_font_size": 14, "label_font_size": 12})
    pl.add_text(f"{summary['scene']['name']}: state {state}; displacement magnified "
                f"{scale:.2g}x; axes in µm", font_size=10)
    # the bounds' axis titles go through a font without "µ": the titles are viewport text
    pl.show_bounds(xtitle=" ", ytitle=" ", font_size=9)
    pl.add_text("r (µm)", position=(0.47, 0.06), viewport=True, font_size=9)
    pl.add_text("z (µm)", position=(0.19, 0.48), viewport=True, font_size=9)
    pl.view_xy()
    # the body on the left three quarters, the bar on the right
    pl.camera.zoom(0.9)
    out = Path(png) if png else run_dir / "render.png"
    save_atomic(out, lambda p: pl.screenshot(str(p)))
    pl.close()
    return out
