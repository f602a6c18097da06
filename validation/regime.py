"""Smooth-sphere LJ regime map over the Tabor range, with estimated errors and an
accuracy-vs-time table.

``python -m validation.regime`` writes results/regime_map.md, regime_map.csv, regime_map.png
(load- and displacement-controlled pull-off vs Maugis-Dugdale, jumps, hysteresis) and
results/accuracy_regime.md (requested accuracy, achieved error against a converged reference,
estimated error, wall time). ``--mu-min``/``--mu-max`` bound the map (default 0.01, 20);
``--quick``: 5 points; ``--no-accuracy-table``: the map only.
"""
import argparse
import csv
import math
import os
from pathlib import Path
import time
import warnings

import numpy as np

from femadh.reference.maugis import (lj_dugdale_lambda, maugis_fixed_grip_pull_off,
                                     maugis_pull_off)
from femadh.studies.regime import (QUANTITIES, REGIME_HEADER, lj_sphere, regime_map,
                                   regime_row)

RESULTS = Path(__file__).resolve().parent / "results"
#: spacing (units of ell) of the converged reference of each mu of the accuracy table: its own
#: error is ~1/25 of the 1e-3 row's at 0.025 (1/9 at 0.05, mu = 20, where 0.025 would take
#: ~2800 nodes)
REFERENCES = {1.0: 0.025, 3.0: 0.025, 20.0: 0.05}
#: the requests of each mu (none finer than its reference can judge: at mu = 1 the
#: hysteresis, 0.08 below its floor 0.1, has the family's largest error constant, ~0.18
#: spacing^2, and 1e-4 takes spacing 0.0125 ell, 1058 nodes, finer than the reference)
ACCURACIES = {1.0: (1e-2, 1e-3), 3.0: (1e-2, 1e-3, 1e-4), 20.0: (1e-2, 1e-3)}


def _f(x, spec):
    return "—" if x is None or (isinstance(x, float) and math.isnan(x)) else format(x, spec)


def map_table(pts):
    lines = ["| μ | λ | N | pull-off (load) | ± est | MD | pull-off (displacement) | ± est | "
             "MD fixed grip | jump-in d/z0 | jump-out d/z0 | hysteresis | ± est | folds | "
             "grids | s | failed |", "|" + "---|" * 17]
    for p in pts:
        e = p.errors
        lines.append(
            f"| {p.mu:.3g} | {lj_dugdale_lambda(p.mu):.3g} | {p.nodes} | {_f(p.pull_off, '.5f')} "
            f"| {_f(e.get('pull_off'), '.1e')} | {p.maugis:.5f} | "
            f"{_f(p.pull_off_displacement, '.5f')} | {_f(e.get('pull_off_displacement'), '.1e')} "
            f"| {_f(p.maugis_displacement, '.5f')} | {_f(p.jump_in, '.4f')} | "
            f"{_f(p.jump_out, '.4f')} | {_f(p.hysteresis, '.4f')} | "
            f"{_f(e.get('hysteresis'), '.1e')} | {p.n_folds} | {p.n_grids} | "
            f"{p.wall_time:.2f} | {p.failed or ''} |")
    return "\n".join(lines)


def figure(pts, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    good = [p for p in pts if p.failed is None]
    mu = np.geomspace(0.01, 30, 120)
    lam = [lj_dugdale_lambda(m) for m in mu]
    fg = [maugis_fixed_grip_pull_off(x) for x in lam]
    fig, ax = plt.subplots(1, 3, figsize=(15, 4.2))
    ax[0].semilogx(mu, [maugis_pull_off(x) for x in lam], "k-", label="MD, load control")
    ax[0].semilogx(mu, [g[0] if g else np.nan for g in fg], "k--", label="MD, fixed grip")
    ax[0].semilogx([p.mu for p in good], [p.pull_off for p in good], "o", label="femadh, load")
    ax[0].semilogx([p.mu for p in good if p.pull_off_displacement],
                   [p.pull_off_displacement for p in good if p.pull_off_displacement], "s",
                   label="femadh, displacement")
    for y in (2.0, 1.5, 5 / 6):
        ax[0].axhline(y, color="grey", lw=0.5)
    ax[0].set(xlabel="Tabor μ", ylabel="pull-off / πRΔγ")
    ax[0].legend(fontsize=7)
    ax[1].semilogx([p.mu for p in good if p.jump_in], [p.jump_in for p in good if p.jump_in],
                   "v", label="jump-in")
    ax[1].semilogx([p.mu for p in good if p.jump_out], [p.jump_out for p in good if p.jump_out],
                   "^", label="jump-out")
    ax[1].set(xlabel="Tabor μ", ylabel="d / z0")
    ax[1].legend(fontsize=7)
    ax[2].loglog([p.mu for p in good if p.hysteresis > 0],
                 [p.hysteresis for p in good if p.hysteresis > 0], "s-")
    ax[2].set(xlabel="Tabor μ", ylabel="hysteresis / (πRΔγ z0)")
    for a in ax:
        a.grid(alpha=0.3, which="both")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def accuracy_table(mus=(1.0, 3.0, 20.0)):
    lines = ["| μ | requested | spacing / ell | N | quantity | achieved error | estimated | "
             "effectivity | wall time (s) |", "|---|---|---|---|---|---|---|---|---|"]
    for mu in mus:
        ref = lj_sphere(mu, spacing=REFERENCES[mu])
        for acc in ACCURACIES[mu]:
            t0 = time.perf_counter()
            p = lj_sphere(mu, accuracy=acc)
            dt = time.perf_counter() - t0
            for k in QUANTITIES:
                v, r = getattr(p, k), getattr(ref, k)
                if v is None or r is None:
                    continue
                floor = max(abs(r), 0.1) if k == "hysteresis" else abs(r)
                true = abs(v - r) / floor
                est = p.relative_error(k)
                eff = est / true if true else math.inf
                lines.append(f"| {mu:g} | {acc:g} | {p.resolution.spacing:.3g} | {p.nodes} | "
                             f"{k} | {true:.2e} | {est:.2e} | {eff:.2f} | {dt:.2f} |")
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--mu-min", type=float, default=0.01)
    ap.add_argument("--mu-max", type=float, default=20.0)
    ap.add_argument("--no-accuracy-table", action="store_true")
    args = ap.parse_args(argv)
    warnings.simplefilter("ignore")
    RESULTS.mkdir(exist_ok=True)
    mus = np.geomspace(args.mu_min, args.mu_max, 5 if args.quick else 20)
    load0 = os.getloadavg()[0]
    t0 = time.perf_counter()
    pts = regime_map(mus, accuracy=1e-3, progress=lambda i, p: print(
        f"mu = {p.mu:.4g}: {'failed: ' + p.failed if p.failed else 'ok'} "
        f"({p.wall_time:.1f} s)", flush=True))
    wall = time.perf_counter() - t0
    load1 = os.getloadavg()[0]
    with open(RESULTS / "regime_map.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(REGIME_HEADER)
        for p in pts:
            w.writerow(regime_row(p))
    figure(pts, RESULTS / "regime_map.png")
    text = f"""# Smooth-sphere LJ regime map (validation/regime.py)

R = 1 um, A = 1e-19 J, z0 = 0.165 nm; accuracy = 1e-3 requested at every point; pull-offs
/ (pi R dg), separations / z0, hysteresis / (pi R dg z0); "± est" are the a-posteriori
estimated absolute errors. MD = Maugis-Dugdale at lambda = 1.157 mu (load control: most
negative load; fixed grip: vertical tangent of P(D), none below lambda = 0.938).

Bistable points (μ > 0.81, where Maugis-Dugdale has a fixed-grip pull-off) are traced with
the grid following the contact edge (`femadh.studies.smooth_sphere.trace_edge_point`): the
contact branch by Newton in its edge radius c on a grid whose nodes move with the edge (the
Green operator scaled exactly, C = λ C0), the approach branch by Newton in its centre gap
on the centre band, from the jump-out separation to the jump-in fold, the folds as extrema
of d(c) and d(g); two grids per point, two folds traced (the unstable branch between them,
with its two further folds at μ ≥ 5, is not); with accuracy = 1e-3 the states meet the
residual 1e-4 x accuracy x z0. The others by arclength
on the static band (`trace_point`). "grids": grids of the trace.

{map_table(pts)}

{len(pts)} points, mu = {mus[0]:.3g} ... {mus[-1]:.3g}: {wall:.1f} s wall time on a shared 2-core
machine, one BLAS thread, load average {load0:.1f} at the start and {load1:.1f} at the end
(the times are indicative at a load above 2; the nodes, grids and folds are the counts).
{len([p for p in pts if p.failed])} points failed. Before the edge-following trace (the whole curve by
arclength on a band re-centred in steps): 1088 s on the same kind of machine, N 80 -> 852, 84 grids and
843 s at μ = 20 (validation/results/regime_cost.md: where the time went).
"""
    (RESULTS / "regime_map.md").write_text(text)
    print(text)
    if not (args.quick or args.no_accuracy_table):
        acc = accuracy_table()
        (RESULTS / "accuracy_regime.md").write_text(
            "# Accuracy on demand: the regime map (validation/regime.py)\n\nAchieved error "
            "against a converged reference (the same trace at spacing "
            + ", ".join(f"{v:g} ell at μ = {k:g}" for k, v in REFERENCES.items())
            + "), relative (hysteresis: to max(value, 0.1)); estimated = the result's own "
            "a-posteriori estimate; wall time includes the coarser member (load average "
            f"{os.getloadavg()[0]:.1f} when written: times indicative above 2). Every point "
            "here is bistable (μ > 0.81): traced with the grid following the contact edge "
            "(femadh.studies.smooth_sphere.trace_edge_point).\n\n" + acc + "\n")
        print(acc)


if __name__ == "__main__":
    main()
