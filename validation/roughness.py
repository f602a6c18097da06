"""Paper 1 sec 5.2-6: Greenwood-Williamson statistics (Fig 7), the slider with asperity
adhesion (Fig 8) by both contact models and the paper's two Hamaker constants, eq 20 as a
range-less limit (the smoothed law converging to it), and the continuous GW model.

``python -m validation.roughness`` writes results/roughness.md, fig7.png and fig8.png (~1 min).
The smooth-sphere regime map is ``validation.regime``.
"""
import argparse
import copy
import math
from pathlib import Path
import sys
import time
import warnings

import numpy as np

try:
    import tomllib
except ModuleNotFoundError:
    import tomli as tomllib

from femadh.errors import Interrupted
from femadh.interrupt import interruptible
from femadh.io.atomic import save_atomic
from femadh.reference.gw import mean_plane_dominance_bound, paper1_table2_roughness
from femadh.runner.run import run as runner_run
from femadh.scene import scene_from_dict

from .paper1 import (HEAD, _fmt, closure_sweeps, complementarity_sweeps, curve, jumps,
                     max_adhesion, row)

HERE = Path(__file__).resolve().parent
RESULTS = HERE / "results"
E_STAR = 58.48e9
DG_ASPERITY = 0.06   # paper 1 sec 6
Z0 = 0.165e-9
PAPER_FIG8 = {0: 0.022, 100: 0.05, 179: 0.151}  # min -F_ex (mN), paper Fig 8(b)


def run(scene, **kw):
    """femadh's runner (:func:`femadh.runner.run.run`), except that a run stopped by SIGINT or
    SIGTERM stops this script: the runner returns such a run ("interrupted", its states kept)
    as it does for the command line, and the loops below would go on to their next run."""
    res = runner_run(scene, **kw)
    if res.status == "interrupted":
        raise Interrupted(res.exit_code - 128)
    return res


def _plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def fig7():
    """GW statistics (eqs 23-26) for rho = 31.3, 100, 179 um^-2; numbers at p = 0.5."""
    t = np.linspace(-3, 3, 601)
    lines = ["| rho (um^-2) | AR_a at p = 0.5 (paper) | P_LJa at p = 0.5, MPa (paper) | "
             "argmin P_exa, (d - z_m)/sigma_a (paper ~1) | min P_exa (MPa) |",
             "|---|---|---|---|---|"]
    plt = _plt()
    fig, ax = plt.subplots(2, 2, figsize=(10, 7.5))
    paper = {31.3: (0.013, 5.56), 100: (0.04, 17.7), 179: (0.073, 31.8)}
    t0 = time.perf_counter()
    for rho in (31.3, 100, 179):
        r = paper1_table2_roughness(rho * 1e12)
        d = r.z_m + t * r.sigma_a
        p_el = r.elastic_pressure(d, E_STAR)
        p_lj = r.lj_pressure(d, DG_ASPERITY)
        ar = r.real_area_ratio(d)
        p_ex = p_el - p_lj
        k = int(np.argmin(p_ex))
        ax[0, 1].semilogy(t, p_el / 1e6, "-", label=f"P_ela ρ={rho}")
        ax[0, 1].semilogy(t, p_lj / 1e6, "--", label=f"P_LJa ρ={rho}")
        ax[1, 0].semilogy(t, ar, label=f"ρ={rho}")
        ax[1, 1].plot(t, p_ex / 1e6, label=f"ρ={rho}")
        lines.append(f"| {rho} | {r.real_area_ratio(r.z_m):.4f} ({paper[rho][0]}) | "
                     f"{r.lj_pressure(r.z_m, DG_ASPERITY) / 1e6:.2f} ({paper[rho][1]}) | "
                     f"{t[k]:.2f} | {p_ex[k] / 1e6:.2f} |")
    ms = (time.perf_counter() - t0) * 1e3
    r = paper1_table2_roughness(100e12)
    ax[0, 0].plot(t, np.exp(-t * t / 2) / math.sqrt(2 * math.pi), label="φ(z) σ_a")
    ax[0, 0].plot(t, r.contact_probability(r.z_m + t * r.sigma_a), label="p (contact prob.)")
    ax[0, 0].set(xlabel="(z - z_m)/σ_a", title="(a) height density, contact probability")
    ax[0, 1].set(xlabel="(d - z_m)/σ_a", ylabel="MPa", title="(b) P_ela, P_LJa", ylim=(1e-3, 1e4))
    ax[1, 0].set(xlabel="(d - z_m)/σ_a", title="(c) real area ratio AR_a")
    ax[1, 1].set(xlabel="(d - z_m)/σ_a", ylabel="MPa", title="(d) P_exa = P_ela - P_LJa",
                 ylim=(-40, 100))
    for a in ax.ravel():
        a.legend(fontsize=7)
        a.grid(alpha=0.3)
    fig.tight_layout()
    save_atomic(RESULTS / "fig7.png", lambda p: fig.savefig(p, dpi=110))
    plt.close(fig)
    bounds = [mean_plane_dominance_bound(0.165e-9, 1e-6, rho * 1e12) for rho in (10, 100)]
    return "\n".join(lines), ms, bounds, r


def slider_scene(A="1e-19 J", sigma="1.08 nm", rho=0, smoothing=None, model="complementarity",
                 gw=None, arclength=False, stop="0 nm"):
    """The paper's slider (Fig 3 scene) with sec 6's sigma = z_m, eq 20 asperity adhesion
    (exact on the contact set, or smoothed with a width ``smoothing`` x sigma), or the
    continuous Greenwood-Williamson laws (``gw`` = density)."""
    base = tomllib.loads((HERE / "scenes" / "paper1_fig3.toml").read_text())
    d = copy.deepcopy(base)
    d["effects"]["lennard_jones"]["hamaker"] = A
    d["effects"]["asperity_gap"] = {"sigma": sigma, "contact_model": model}
    # the paper's N = 200 uniform nodes, as every table here states (the Fig 3 scene itself
    # became adaptive; an adaptive run of a narrow smoothed step refines for minutes)
    d.setdefault("solver", {})["nodes"] = 200
    if rho:
        d["effects"]["asperity_adhesion"] = {
            "asperity_radius": "0.94 um", "surface_energy": f"{DG_ASPERITY} J/m^2",
            "density": f"{rho} um^-2", "contact_probability": 0.5}
        if smoothing:
            d["effects"]["asperity_adhesion"].update(model="smoothed", smoothing=smoothing)
    if gw is not None:
        del d["effects"]["asperity_gap"]
        d["effects"]["asperity_contact"] = {
            "model": "greenwood-williamson", "rms_height": "0.344 nm", "mean_height": "1.08 nm",
            "asperity_radius": "0.94 um", "density": f"{gw} um^-2",
            "surface_energy": f"{DG_ASPERITY} J/m^2"}
        d["sweep"] = {"start": "3 nm", "stop": stop, "step": "0.1 nm"}
        if arclength:
            d["solver"]["continuation"] = "arclength"
    return scene_from_dict(d, f"slider rho={rho}" if gw is None else f"slider GW rho={gw}")


def fig8():
    a_eq19 = 16 * math.pi * Z0**2 * DG_ASPERITY      # eq 19 with dg = 0.06
    hamakers = [("1e-19 J", "Table 1"), (f"{a_eq19 / 10:.4g} J", "sec 6 as printed, "
                                          "0.821e-20"),
                (f"{a_eq19:.4g} J", "eq 19 with Δγ = 0.06")]
    paper = {0: 0.022, 100: 0.05, 179: 0.151}
    lines = []
    lines.append(f"Eq 19 with Δγ = 0.06 J/m² and z0 = 0.165 nm: A = 16π z0² Δγ = {a_eq19:.4g} J. "
                 "The paper prints 0.821e-20 J = 8.21e-21 J, a factor 10 below its own eq 19.\n")
    lines += HEAD
    results = {}
    plt = _plt()
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
    for A, label in hamakers:
        for rho in (0, 100, 179):
            sc = slider_scene(A, rho=rho)
            pc, swc, errc = closure_sweeps(sc)
            pm, swm, errm = complementarity_sweeps(slider_scene(A, rho=rho))
            if label.startswith("eq 19"):
                for k, (p_, sw_, st) in enumerate(((pc, swc, "-"), (pm, swm, "--"))):
                    c = curve(p_, sw_["retract"]) if "retract" in sw_ else None
                    if c is None:
                        continue
                    name = ("closure" if k == 0 else "complementarity") + f", ρ = {rho}"
                    ax[0].plot(c["d"] * 1e9, -c["F_ex"] * 1e3, st, color=f"C{rho % 7}",
                               label=name)
                    ax[1].plot(-c["F_ex"] * 1e3, c["r_c"] * 1e6, st, color=f"C{rho % 7}",
                               label=name)
            vc = max(max_adhesion(pc, sw)[0] for sw in swc.values() if sw.states)
            vm = max(max_adhesion(pm, sw)[0] for sw in swm.values() if sw.states)
            results[(label, rho)] = (vc, vm)
            lines.append(row(f"Fig 8, A = {A} ({label}), ρ = {rho} µm⁻²: max adhesion, mN",
                             paper[rho], vc, vm,
                             f"closure {100 * (vc / paper[rho] - 1):+.0f} %, complementarity "
                             f"{100 * (vm / paper[rho] - 1):+.0f} %; snaps (closure) "
                             f"{_fmt(jumps(swc).get('approach'))} / "
                             f"{_fmt(jumps(swc).get('retract'))} nm"
                             + (f"; errors: {errc} / {errm}" if errc or errm else "")))
    ax[0].set(xlabel="d (nm)", ylabel="force on the slider −F_ex (mN)",
              title=f"Fig 8 (retract), A = {a_eq19:.3g} J")
    ax[1].set(xlabel="−F_ex (mN)", ylabel="r_c (µm)", title="contact radius")
    for a in ax:
        a.legend(fontsize=7)
        a.grid(alpha=0.3)
    fig.tight_layout()
    save_atomic(RESULTS / "fig8.png", lambda p: fig.savefig(p, dpi=110))
    plt.close(fig)
    for label in ("Table 1", "eq 19 with Δγ = 0.06", "sec 6 as printed, 0.821e-20"):
        errs = [results[(label, rho)][0] / paper[rho] - 1 for rho in (0, 100, 179)]
        errs_m = [results[(label, rho)][1] / paper[rho] - 1 for rho in (0, 100, 179)]
        lines.append(f"\n- A of {label}: closure {', '.join(f'{100 * e:+.1f} %' for e in errs)}; "
                     f"complementarity {', '.join(f'{100 * e:+.1f} %' for e in errs_m)} "
                     "(ρ = 0, 100, 179).")
    lines.append("\nThe paper's Fig 8 numbers need the closure **and** A = 16πz0²Δγ = "
                 f"{a_eq19:.3g} J (eq 19 with its Δγ = 0.06 J/m²): neither Table 1's 1e-19 J "
                 "(+22 % at ρ = 0, where the two models agree) nor the printed 0.821e-20 J. "
                 "The complementarity model, with eq 20 as its exact range-less limit (P_LJa "
                 "on the contact set: a contact node holds a net tension up to P_LJa before it "
                 "releases), cannot reach 0.151 mN with any of them: inside a contact that "
                 "satisfies eq 10 the asperities' pull is balanced by their own elastic "
                 "pressure, and the pull-off gains only what the release of the edge nodes "
                 "costs. The closure lets P_LJa act over the whole r < r_c against a Hertz "
                 "pressure it does not let respond (eq 10 violated inside).")
    return lines, results, a_eq19


def eq20_limit(rho=179, A="1e-19 J"):
    """Eq 20 in the complementarity model: the range-less limit (P_LJa on the contact set,
    exact) and the smoothed step converging to it as its width -> 0."""
    lines = ["| eq 20 in the complementarity model | width / σ | max adhesion, mN | "
             "− limit, mN |", "|---|---|---|---|"]
    lim = run(slider_scene(A, rho=rho), progress=False)
    f_lim = lim.headline["max_adhesion_N"] * 1e3
    rows = []
    for w in (0.04, 0.02, 0.01, 0.005, 0.0025):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")      # narrow steps: node stiffness warnings
            res = run(slider_scene(A, rho=rho, smoothing=w), progress=False)
        f = res.headline.get("max_adhesion_N", math.nan) * 1e3
        rows.append((w, f))
        lines.append(f"| smoothed step | {w:g} | {f:.5f} | {f - f_lim:+.5f} |")
    lines.append(f"| contact set (range-less limit, the default) | 0 | {f_lim:.5f} | 0 |")
    ws = np.array([w for w, _ in rows])
    errs = np.array([f - f_lim for _, f in rows])
    order = np.polyfit(np.log(ws[-3:]), np.log(np.abs(errs[-3:])), 1)[0]
    lines.append(f"\nρ = {rho} µm⁻², A = {A}, N = 200: the smoothed law converges to the "
                 f"contact-set limit at order {order:.2f} in the width (last three widths).\n")
    lines += ["| N | limit (contact set), mN | LJ alone (ρ = 0), mN | excess, mN |",
              "|---|---|---|---|"]
    excess, spacing = [], []
    for n in (100, 200, 400, 800):
        f_l = run(slider_scene(A, rho=rho).replace({"solver.nodes": n}), progress=False)
        f_0 = run(slider_scene(A, rho=0).replace({"solver.nodes": n}), progress=False)
        a, b = f_l.headline["max_adhesion_N"] * 1e3, f_0.headline["max_adhesion_N"] * 1e3
        excess.append(a - b)
        spacing.append(1.0 / n)
        lines.append(f"| {n} | {a:.5f} | {b:.5f} | {a - b:+.5f} |")
    order_n = np.polyfit(np.log(spacing), np.log(excess), 1)[0]
    lines.append(f"\nThe range-less limit itself converges in the mesh to the pull-off without "
                 f"eq 20: its excess falls like the node spacing (order {order_n:.2f}). A "
                 "finite pressure that acts only where h = σ does no work; in a contact that "
                 "satisfies eq 10 it is balanced by the asperities' own elastic pressure, and "
                 "its only effect - the tension an edge node holds before it releases - acts "
                 "on a ring one node wide. Eq 20 as the paper states it therefore adds "
                 "nothing to the adhesion of a consistent model; the paper's Fig 8 increase "
                 "is a property of its closure (above). For a finite effect the asperity "
                 "adhesion needs a range: the GW laws below (range σ_a).")
    return lines


def _snake(res):
    """What a failed arclength trace covered (its streamed points): (points, folds - sign
    changes of dd/ds -, smallest and largest d in nm), or None."""
    ec = res.equilibrium_curve or {}
    td, d = np.asarray(ec.get("dd_ds", ())), np.asarray(ec.get("d_m", ()))
    if not d.size:
        return None
    return d.size, int(np.sum(np.sign(td[1:]) * np.sign(td[:-1]) < 0)), d.min() * 1e9, \
        d.max() * 1e9


def gw_models():
    """The continuous GW laws on the slider (N = 200) by stepping and by arclength.

    At rho = 31.3 um^-2 both fail, and not for their budgets: the GW laws soften at 3.05x the
    stiffness of one surface node (the scene's own MeshResolutionWarning: nodes >= 1220), so
    the N = 200 discretisation is lattice-trapped. Stepping cannot polish its landing after
    the jump-in (d = 0.786 nm, Newton 200 iterations). Arclength follows the discrete curve
    faithfully - 1.2 corrector solves per point, no step collapse - but that curve is a snake
    with one pair of folds per node that snaps (the resolved curve has two folds): its lower
    folds lie at 0.79-1.77 nm, its upper ones at 0.84-2.92 nm, 110-135 points apart. Measured with
    trace_curve on this scene: 45 folds in the row's 5000 points, 111 folds in 15 000 points
    (d back down to 1.40 nm on the contact branch, ~26 legs from its end at 0.6 nm by the
    lower folds' pace), so the discrete curve needs some 20 000 points or more: a budget that
    cannot be met usefully, for a mesh-dependent answer. The fix is the mesh the warning
    asks for (N >= 1220: Krylov correctors at N > 250, a run at N = 1300 had not ended after
    6 CPU-min), not the point budget or the step control; the row stays, failing, with what
    its trace covered."""
    rows = ["| Greenwood-Williamson (continuous), Δγ_a = 0.06 | A (J) | ρ (µm⁻²) | status | "
            "max adhesion, mN |", "|---|---|---|---|---|"]
    for rho in (31.3, 100, 179):
        res = run(slider_scene(gw=rho), progress=False)
        rows.append(f"| stepping in d | 1e-19 | {rho} | {res.status} | "
                    f"{res.headline.get('max_adhesion_N', math.nan) * 1e3:.4f} |")
    for rho, stop in ((31.3, "0.6 nm"), (100, "0 nm")):
        t0 = time.perf_counter()
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            res = run(slider_scene(gw=rho, arclength=True, stop=stop), progress=False)
        trap = [w for w in caught if "snap" in str(w.message)]
        note = (f"; {len(res.jumps)} jumps, mesh-dependent (node stiffness below the law's "
                "softening)" if trap else f"; {len(res.jumps)} jumps")
        covered = _snake(res) if res.status == "failed" else None
        if covered:
            note += (f"; its {covered[0]} points snake through {covered[1]} folds between "
                     f"d = {covered[2]:.3g} and {covered[3]:.3g} nm (one pair per node that "
                     "snaps: see gw_models' docstring)")
        rows.append(f"| arclength to {stop} | 1e-19 | {rho} | {res.status}{note} "
                    f"({time.perf_counter() - t0:.0f} s) | "
                    f"{res.headline.get('max_adhesion_N', math.nan) * 1e3:.4f} |")
    return "\n".join(rows)


def main(argv=None):
    """Write results/roughness.md; 0, or 130 / 143 with one line on stderr where SIGINT /
    SIGTERM stopped it (the signals only set a flag, read at the solvers' safe points, for the
    whole script: the direct traces of Fig 8 stop at their next iteration as the runs do)."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.parse_args(argv)
    RESULTS.mkdir(exist_ok=True)
    t0 = time.perf_counter()
    try:
        with interruptible():
            f7, ms, bounds, r = fig7()
            f8, _, a_eq19 = fig8()
            lim = eq20_limit()
            gw = gw_models()
    except Interrupted as exc:
        print(f"validation.roughness: {exc} after {time.perf_counter() - t0:.0f} s: stopped, "
              f"{RESULTS / 'roughness.md'} not written", file=sys.stderr)
        return exc.exit_code
    dg_table1 = 1e-19 / (16 * math.pi * Z0**2)
    text = "\n".join([
        "# Paper 1 sec 5.2-6: asperities (validation/roughness.py)", "",
        f"Generated in {time.perf_counter() - t0:.0f} s.", "",
        "## Greenwood-Williamson statistics (Fig 7, eqs 20-26)", "",
        f"Composite roughness (Table 2): σ_a = {r.sigma_a * 1e9:.3f} nm (paper 0.344), z_m = "
        f"{r.z_m * 1e9:.2f} nm (1.08), R_a = {r.radius * 1e6:.3f} µm (0.94). Eq 26 as printed, "
        "1/sqrt(2π σ_a), neither integrates to 1 nor has units of 1/length: femadh uses "
        "1/(sqrt(2π) σ_a), with which the paper's own numbers below are reproduced (by "
        f"quadrature of eqs 23-25: {ms:.0f} ms for all Fig 7 curves).", "", f7, "",
        f"Eq 22 bounds for R_a = 1 µm: σ ≤ {bounds[0] * 1e9:.3f} nm (ρ = 10 µm⁻²; paper 1.05), "
        f"{bounds[1] * 1e9:.3f} nm (ρ = 100; paper 0.49).", "",
        f"Hamaker constants: Table 1's A = 1e-19 J (Figs 3-6) corresponds by eq 19 to Δγ = "
        f"{dg_table1:.4f} J/m², not sec 6's 0.06; with Δγ = 0.06 eq 19 gives A = "
        f"{a_eq19:.4g} J (the paper prints 0.821e-20).", "",
        "## Fig 8: slider with asperity adhesion (σ = z_m = 1.08 nm, eq 20 with p = 0.5)", "",
        *f8, "", "## Eq 20 without an arbitrary width", "", *lim, "",
        "## The continuous alternative: GW asperity laws instead of the hard σ-gap", "", gw, ""])
    (RESULTS / "roughness.md").write_text(text + "\n")
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
