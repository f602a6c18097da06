"""Studies: mesh convergence and accuracy vs time of the FE operator against the exact
operator (same nodes, same pressures, same solver) - the Green function of the homogeneous
half-space, or the Hankel-transform operator of a layered one - and of that operator in N.
"""
import csv
from dataclasses import replace
from pathlib import Path
import sys
import time

import numpy as np

#: FE mesh ladder, coarse -> fine: (growth, surface_fraction); each level halves both sizes
FE_LEVELS = ((0.5, 1.0), (0.25, 0.5), (0.125, 0.25), (0.0625, 0.125))


def _sweep(problem, scene):
    from ..contact import trace
    from ..contact.forces import state_forces

    t0 = time.perf_counter()
    a = trace(problem, scene.d_values, branch="approach", tol=scene.tolerance,
              max_iter=scene.max_iter)
    states = list(a.states)
    if "retract" in scene.directions:
        r = trace(problem, scene.d_values[::-1], branch="retract", tol=scene.tolerance,
                  start=a.states[-1], max_iter=scene.max_iter)
        states += r.states
    wall = time.perf_counter() - t0
    f = np.array([state_forces(problem, s) for s in states])
    return f, wall


def _try_sweep(problem, scene, shape):
    """_sweep, or NaN forces and the reason when a level fails (a coarse level may not
    resolve a fold: the study goes on and says so)."""
    from ..errors import FemadhError

    try:
        f, wall = _sweep(problem, scene)
        return f, wall, ""
    except FemadhError as exc:
        return np.full(shape, np.nan), 0.0, f"failed: {exc}".replace("|", "/")


def judge(scene, nodes):
    """The exact operator a scene's FE body is judged against, on N = ``nodes``: the Green
    function of the homogeneous half-space, or for a layered scene the Hankel-transform
    operator of its stack (:mod:`femadh.judges`; seconds per N for layers much
    thinner than the analysis radius)."""
    from ..elastic import GreenOperator, RadialGrid

    grid = RadialGrid.uniform(scene.analysis_radius, nodes)
    if scene.layers:
        from ..judges import HankelLayeredOperator

        return HankelLayeredOperator(grid, scene.layers, scene.disk, scene.slider)
    return GreenOperator(grid, scene.e_star)


def convergence(scene, *, levels=3, green_factors=(0.25, 0.5, 1, 2), reference_factor=4,
                progress=None):
    """FE mesh ladder vs the exact operator on the scene's nodes (the Green function, or the
    Hankel-transform operator of a layered scene), and that operator in N.

    Returns a list of row dicts: method ("fe", "green" or "hankel"), level/N, dofs, error of
    F_ex over the sweep relative to the peak |F_ex| of the reference, compliance error, and
    the wall time split into mesh / assembly / factorisation / condensation / sweep (s).
    """
    from ..elastic.fe import FESettings
    from ..scene import build_operator, build_problem

    say = progress or (lambda msg: None)
    base = FESettings() if scene.fe_settings is None else scene.fe_settings
    name = "hankel" if scene.layers else "green"
    rows = []
    say(f"{name} reference on N = {scene.nodes}")
    exact = judge(scene, scene.nodes)
    grid = exact.grid
    f_ref, _ = _sweep(build_problem(scene, exact), scene)
    peak = np.abs(f_ref[:, 2]).max()
    for k, (growth, frac) in enumerate(FE_LEVELS[:levels]):
        settings = replace(base, growth=growth, surface_fraction=frac)
        say(f"FE level {k}: growth {growth}, surface fraction {frac}")
        op = build_operator(scene, grid=grid, settings=settings)
        f, wall, note = _try_sweep(build_problem(scene, op), scene, f_ref.shape)
        rows.append({"method": "fe", "level": k, "N": scene.nodes, "dofs": op.n_dofs,
                     "error_F_ex": float(np.abs(f[:, 2] - f_ref[:, 2]).max() / peak),
                     "note": note,
                     "error_compliance": float(np.abs(op.compliance - exact.compliance).max()
                                               / np.abs(exact.compliance).max()),
                     **{f"t_{k2}": v for k2, v in op.timings.items()}, "t_sweep": wall})
    # the exact operator in N against a finer one (its own discretisation error)
    n_ref = int(scene.nodes * reference_factor)
    say(f"{name} N-ladder against N = {n_ref}")
    f_fine, _ = _sweep(build_problem(scene, judge(scene, n_ref)), scene)
    peak_fine = np.abs(f_fine[:, 2]).max()
    for fac in green_factors:
        n = max(8, int(scene.nodes * fac))
        t0 = time.perf_counter()
        op = judge(scene, n)
        t_op = time.perf_counter() - t0
        f, wall, note = _try_sweep(build_problem(scene, op), scene, f_fine.shape)
        rows.append({"method": name, "level": "", "N": n, "dofs": n,
                     "error_F_ex": float(np.abs(f[:, 2] - f_fine[:, 2]).max() / peak_fine),
                     "note": note,
                     "error_compliance": "", "t_mesh": 0.0, "t_assembly": t_op,
                     "t_factorisation": 0.0, "t_condensation": 0.0, "t_sweep": wall})
    return rows


COLUMNS = ["method", "level", "N", "dofs", "error_F_ex", "error_compliance", "t_mesh",
           "t_assembly", "t_factorisation", "t_condensation", "t_sweep", "note"]


def write_convergence(rows, out_dir, title=""):
    """convergence.csv, convergence.md and convergence.png (error vs DOFs, vs time)."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    with open(out / "convergence.csv", "w", newline="") as f:
        w = csv.DictWriter(f, COLUMNS)
        w.writeheader()
        for r in rows:
            w.writerow({k: r.get(k, "") for k in COLUMNS})
    lines = ["| " + " | ".join(COLUMNS) + " | total (s) |", "|" + "---|" * (len(COLUMNS) + 1)]
    for r in rows:
        tot = sum(r[k] for k in COLUMNS if k.startswith("t_"))
        cells = [f"{r.get(k, ''):.3g}" if isinstance(r.get(k), float) else str(r.get(k, ""))
                 for k in COLUMNS]
        lines.append("| " + " | ".join(cells) + f" | {tot:.3g} |")
    (out / "convergence.md").write_text(f"# Convergence study {title}\n\n" + "\n".join(lines)
                                        + "\n")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 2, figsize=(12, 4.5))
    exact = "Hankel" if any(r["method"] == "hankel" for r in rows) else "Green"
    for meth, mk in (("fe", "o-"), ("green", "s--"), ("hankel", "s--")):
        rr = [r for r in rows if r["method"] == meth]
        if not rr:
            continue
        ax[0].loglog([r["dofs"] for r in rr], [r["error_F_ex"] for r in rr], mk,
                     label=f"FE vs {exact} (same nodes)" if meth == "fe" else f"{exact} vs 4N")
        tot = [sum(r[k] for k in COLUMNS if k.startswith("t_")) for r in rr]
        ax[1].loglog(tot, [r["error_F_ex"] for r in rr], mk, label=meth)
    ax[0].set(xlabel="degrees of freedom", ylabel="max |ΔF_ex| / peak |F_ex|",
              title="error vs size")
    ax[1].set(xlabel="wall time (s)", ylabel="max |ΔF_ex| / peak |F_ex|", title="error vs time")
    for a in ax:
        a.grid(True, which="both", alpha=0.3)
        a.legend(loc="lower left")
    # stacked time split of the FE levels
    fe = [r for r in rows if r["method"] == "fe"]
    if fe:
        ins = ax[1].inset_axes([0.58, 0.55, 0.4, 0.42])
        bottom = np.zeros(len(fe))
        for k in ("t_mesh", "t_assembly", "t_factorisation", "t_condensation", "t_sweep"):
            v = np.array([r[k] for r in fe])
            ins.bar(range(len(fe)), v, bottom=bottom, label=k[2:])
            bottom += v
        ins.set_xticks(range(len(fe)), [f"L{r['level']}" for r in fe])
        ins.set_ylabel("s", fontsize=7)
        ins.tick_params(labelsize=7)
        ins.legend(fontsize=6)
    fig.suptitle(f"Convergence {title}")
    fig.tight_layout()
    fig.savefig(out / "convergence.png", dpi=110)
    plt.close(fig)
    return out / "convergence.md"


def default_progress():
    return (lambda msg: print(msg, file=sys.stderr)) if sys.stderr.isatty() else None
