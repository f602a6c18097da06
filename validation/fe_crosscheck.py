"""FE half-space vs the Green function: truncation, force curves, convergence, cost, render.

``python -m validation.fe_crosscheck`` writes results/fe_crosscheck.md, results/fe_convergence.*
and results/fe_deformed_zone.png.
"""
import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from femadh.contact import trace  # noqa: E402
from femadh.elastic import RadialGrid, disk_displacement  # noqa: E402
from femadh.elastic.fe import FEOperator, FESettings  # noqa: E402
from femadh.contact.forces import state_forces  # noqa: E402
import femadh  # noqa: E402
from femadh.io.render import render_run  # noqa: E402
from femadh.scene import build_problem  # noqa: E402
from femadh.studies.convergence import convergence, write_convergence  # noqa: E402
from validation.paper1 import scene  # noqa: E402

RESULTS = Path(__file__).resolve().parent / "results"


def truncation_table():
    g = RadialGrid.uniform(1.0, 20)
    E = 58.48e9
    exact = disk_displacement(g.nodes, g.radius, E)
    lines = ["| L / a | fixed far boundary | Boussinesq far field |", "|---|---|---|"]
    for L in (10.0, 100.0, 1e3, 1e4):
        errs = []
        for far in ("fixed", "boussinesq"):
            w = FEOperator.homogeneous(g, E, 0.3, FESettings(L, 0.125, 0.25, far)).displacement(
                np.ones(g.n))
            errs.append(np.max(np.abs(w - exact)) / exact.max())
        lines.append(f"| {L:g} | {errs[0]:.2e} | {errs[1]:.2e} |")
    return "\n".join(lines)


def curves(problem, sc):
    a = trace(problem, sc.d_values, branch="approach", tol=sc.tolerance)
    r = trace(problem, sc.d_values[::-1], branch="retract", tol=sc.tolerance, start=a.states[-1])
    return np.array([state_forces(problem, s) for s in a.states + r.states])


def crosscheck_table():
    lines = ["| case | Green sweep (s) | FE build (s): mesh / assembly / factorisation / "
             "condensation | FE sweep (s) | 2nd FE sweep, cached operator (s) | "
             "max abs(dF_ex) / peak | max abs(dF_LJ) / max F_LJ |", "|---|---|---|---|---|---|---|"]
    for label, kw in (("Fig 3, sigma = 1 nm", {}), ("Fig 4, sigma = 0.5 nm", {"sigma": "0.5 nm"})):
        sc = scene("paper1_fig3", None, **kw)
        t0 = time.perf_counter()
        pg = build_problem(sc)
        fg = curves(pg, sc)
        tg = time.perf_counter() - t0
        sc_fe = sc.replace({"solver.method": "fe", "output.vtk": False})
        t0 = time.perf_counter()
        pf = build_problem(sc_fe)
        tb = time.perf_counter() - t0
        t0 = time.perf_counter()
        ff = curves(pf, sc_fe)
        ts = time.perf_counter() - t0
        t0 = time.perf_counter()
        curves(build_problem(sc_fe, pf.operator), sc_fe)
        ts2 = time.perf_counter() - t0
        tm = pf.operator.timings
        lines.append(
            f"| {label} | {tg:.2f} | {tb:.2f}: {tm['mesh']:.2f} / {tm['assembly']:.2f} / "
            f"{tm['factorisation']:.2f} / {tm['condensation']:.2f} | {ts:.2f} | {ts2:.2f} | "
            f"{np.abs(ff[:, 2] - fg[:, 2]).max() / np.abs(fg[:, 2]).max():.2e} | "
            f"{np.abs(ff[:, 0] - fg[:, 0]).max() / np.abs(fg[:, 0]).max():.2e} |")
    return "\n".join(lines)


def render(out_png):
    """Off-screen PyVista render of the deformed contact zone (von Mises) at d = -5 nm, as
    ``femadh render`` draws it from the run's VTK files."""
    import shutil

    sc = scene("paper1_fig3", 200).replace({
        "solver.method": "fe", "output.vtk": True, "sweep.start": "2 nm",
        "sweep.stop": "-5 nm", "sweep.step": "3.5 nm", "sweep.directions": ["approach"]})
    out = Path("out/fe-render")
    shutil.rmtree(out, ignore_errors=True)
    femadh.run(sc, out_dir=out, progress=False)
    render_run(out, png=out_png)


def main():
    RESULTS.mkdir(exist_ok=True)
    t = truncation_table()
    c = crosscheck_table()
    rows = convergence(scene("paper1_fig3", 200), levels=3)
    write_convergence(rows, RESULTS, "paper1 fig3 (sigma = 1 nm, N = 200)")
    for f in ("convergence.csv", "convergence.md", "convergence.png"):
        (RESULTS / f).replace(RESULTS / f"fe_{f}")
    render(RESULTS / "fe_deformed_zone.png")
    text = ("# FE half-space vs Green function (validation/fe_crosscheck.py)\n\n"
            "## Far-field truncation: uniform disk, max error of w over the loaded nodes\n\n"
            f"{t}\n\n## Force curves, paper-1 scenes (N = 200, default mesh, both branches)\n\n"
            f"{c}\n\n## Convergence\n\nSee fe_convergence.md / fe_convergence.png.\n")
    (RESULTS / "fe_crosscheck.md").write_text(text)
    print(text)


if __name__ == "__main__":
    main()
