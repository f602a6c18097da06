"""Paper 1's 2-mm glass slider on a magnetic disk with a 2-10 nm carbon overcoat against the
bare disk: the layered FE body (same-mesh differences) beside the Hankel-transform operator.

``python -m validation.layered.slider`` writes results/layered_slider.md and .png.
"""
import time

import numpy as np

from femadh.contact import AsperityGap, ContactProblem, trace
from femadh.contact.forces import state_forces
from femadh.elastic import GreenOperator
from femadh.elastic.fe import FEOperator, Layer
from femadh.indenter import Sphere
from femadh.judges import HankelLayeredOperator
from femadh.laws import LennardJones
from femadh.materials import composite_modulus

from .common import DISK, RESULTS, SLIDER, SLIDER_R, fmt, rel, slider_grid, write_result

#: diamond-like carbon overcoat: E 100-300 GPa (the issue's range), nu 0.25 (assumed)
OVERCOAT_NU = 0.25


def slider_curves(op, sigma):
    """Approach and retract sweeps (2 -> -5 nm, 0.2 nm) of paper 1's slider on ``op``: d,
    forces, contact radius per state, the jumps and the wall time."""
    grid_d = np.round(np.arange(2.0, -5.0001, -0.2), 10) * 1e-9
    p = ContactProblem(op, Sphere(SLIDER_R), {"lj": LennardJones(1e-19, 0.165e-9)},
                       AsperityGap(sigma))
    t0 = time.perf_counter()
    a = trace(p, grid_d, branch="approach", tol=1e-19)
    r = trace(p, grid_d[::-1], branch="retract", tol=1e-19, start=a.states[-1])
    wall = time.perf_counter() - t0
    states = a.states + r.states
    f = np.array([state_forces(p, s) for s in states])
    return {"d": np.array([s.d for s in states]), "F_LJ": f[:, 0], "F_el": f[:, 1],
            "F_ex": f[:, 2],
            "r_c": np.array([s.r_c for s in states]), "n_app": len(a.states),
            "jumps": a.jumps + r.jumps, "wall": wall}


def main():
    """Write results/layered_slider.md and .png."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    grid = slider_grid()
    cases = [(t, E) for t in (2e-9, 5e-9, 10e-9) for E in (100e9, 300e9)]
    green_op = GreenOperator(grid, composite_modulus(DISK, SLIDER))
    bare_op = FEOperator.layered(grid, DISK, sphere=SLIDER)
    ops = []
    for t, E in cases:
        coat = [Layer(t, E, OVERCOAT_NU)]
        t0 = time.perf_counter()
        op = FEOperator.layered(grid, DISK, coat, SLIDER)
        build = time.perf_counter() - t0
        # same-mesh bare body: a "coat" of the disk's own material, so the FE discretisation
        # error cancels from the coating's effect
        same = FEOperator.layered(grid, DISK,
                                  [Layer(t, DISK.youngs_modulus, DISK.poisson_ratio)], SLIDER)
        ops.append((t, E, op, build, same, HankelLayeredOperator(grid, coat, DISK, SLIDER)))
    out = {}
    lines = []
    changes = []
    for sigma in (1e-9, 0.5e-9):
        green = slider_curves(green_op, sigma)
        fe_bare = slider_curves(bare_op, sigma)
        rows = [(t, E, op, build, slider_curves(op, sigma), slider_curves(ref_op, sigma),
                 slider_curves(same_op, sigma))
                for t, E, op, build, same_op, ref_op in ops]
        out[sigma] = (green, fe_bare, rows)

        def feats(c):
            n = c["n_app"]
            k = int(np.argmax(c["F_ex"][:n]))
            jin = [j.d_fold for j in c["jumps"] if j.branch == "approach"]
            jout = [j.d_fold for j in c["jumps"] if j.branch == "retract"]
            return (c["F_ex"][k], c["d"][k], c["r_c"][n - 1], c["F_el"][n - 1],
                    jin[0] if jin else None, jout[-1] if jout else None)

        g = feats(green)
        lines.append(f"\n### sigma = {sigma * 1e9:g} nm\n")
        lines.append("| body | operator | max F_ex (uN) | at d (nm) | r_c at d = -5 nm (um) | "
                     "contact force F_el at -5 nm (uN) | jump-in d (nm) | jump-out d (nm) | "
                     "change of max F_ex vs bare | change of F_el(-5 nm) vs bare |")
        lines.append("|---|---|---|---|---|---|---|---|---|---|")

        def row(label, opname, f, ref_f):
            lines.append(
                f"| {label} | {opname} | {f[0] * 1e6:.5f} | {f[1] * 1e9:.1f} | "
                f"{f[2] * 1e6:.4f} | {f[3] * 1e6:.4f} | {fmt(f[4] and f[4] * 1e9, '.2f')} | "
                f"{fmt(f[5] and f[5] * 1e9, '.2f')} | "
                f"{'-' if ref_f is None else f'{f[0] / ref_f[0] - 1:+.2e}'} | "
                f"{'-' if ref_f is None else f'{f[3] / ref_f[3] - 1:+.2e}'} |")
            if ref_f is not None and "bare" not in label:
                changes.append(max(abs(f[0] / ref_f[0] - 1), abs(f[3] / ref_f[3] - 1)))

        row("bare disk", "Green (E*)", g, None)
        row("bare disk", "FE + sphere Green", feats(fe_bare), g)
        for t, E, op, build, fe, ref, same in rows:
            fs = feats(same)
            row(f"{t * 1e9:g} nm, {E / 1e9:g} GPa", "FE (vs same-mesh bare)", feats(fe), fs)
            row(f"{t * 1e9:g} nm, {E / 1e9:g} GPa", "reference (vs Green bare)", feats(ref), g)
        worst = max(np.abs(fe["F_ex"] - ref["F_ex"]).max() / np.abs(ref["F_ex"]).max()
                    for _, _, _, _, fe, ref, _ in rows)
        bare_err = rel(fe_bare["F_ex"], green["F_ex"])
        lines.append(f"\nFE vs reference over both branches, all coatings: max |dF_ex| = "
                     f"{worst:.1e} of the peak. FE bare vs Green: {bare_err:.1e}.")
        lines.append("\nBuild (s) / DOFs / sweep (s) of the coated FE operators: " + "; ".join(
            f"{t * 1e9:g} nm {E / 1e9:g} GPa: {b:.2f} / {op.n_dofs} / {fe['wall']:.2f}"
            for t, E, op, b, fe, _, _ in rows) + f". Green sweep: {green['wall']:.2f} s.")

    # figure: sigma = 1 nm curves and the coating's effect
    green, fe_bare, rows = out[1e-9]
    fig, ax = plt.subplots(1, 2, figsize=(12, 4.5))
    n = green["n_app"]
    ax[0].plot(green["d"][:n] * 1e9, green["F_ex"][:n] * 1e6, "k-", label="bare, approach")
    ax[0].plot(green["d"][n:] * 1e9, green["F_ex"][n:] * 1e6, "k--", label="bare, retract")
    t, E, _, _, fe, ref, same = rows[-1]
    ax[0].plot(fe["d"][:n] * 1e9, fe["F_ex"][:n] * 1e6, "r:", lw=2,
               label=f"{t * 1e9:g} nm / {E / 1e9:g} GPa coat (FE)")
    ax[0].set_xlabel("d (nm)")
    ax[0].set_ylabel("F_ex (uN), adhesive > 0")
    ax[0].set_ylim(-150, 45)       # the adhesive part (the sweep reaches -1.6 mN at -5 nm)
    ax[0].legend(fontsize=8)
    ax[0].set_title("paper 1 slider, sigma = 1 nm (adhesive range)")
    for t, E, _, _, fe, ref, same in rows:
        m = fe["n_app"]
        line, = ax[1].plot(fe["d"][:m] * 1e9, (fe["F_ex"][:m] - same["F_ex"][:m]) * 1e9,
                           label=f"{t * 1e9:g} nm, {E / 1e9:g} GPa")
        ax[1].plot(ref["d"][:m] * 1e9, (ref["F_ex"][:m] - green["F_ex"][:m]) * 1e9, "--",
                   color=line.get_color())
    ax[1].set_xlabel("d (nm)")
    ax[1].set_ylabel("F_ex(coated) - F_ex(bare) (nN)")
    ax[1].set_title("coating effect, approach: FE (solid), reference (dashed, coincident)")
    ax[1].legend(fontsize=7)
    fig.tight_layout()
    RESULTS.mkdir(exist_ok=True)
    fig.savefig(RESULTS / "layered_slider.png", dpi=110)
    text = f"""# Paper 1's slider on a carbon-overcoated disk (validation/layered/slider.py)

Paper 1 (adhesion-aspects-in-mems-nems): R = 2 mm glass slider (E = 83 GPa, nu = 0.21) on a
magnetic disk (E = 163 GPa, nu = 0.3), LJ A = 1e-19 J, z0 = 0.165 nm, sigma-gap (Fig 3: 1 nm;
Fig 4: 0.5 nm), N = 200 nodes on a = sqrt(2R x 10 nm) = {grid.radius * 1e6:.2f} um, d from 2 to
-5 nm in 0.2 nm steps, approach and retract. The disk carries a carbon overcoat of t = 2, 5,
10 nm with E = 100 or 300 GPa (nu = {OVERCOAT_NU}, assumed for diamond-like carbon); the slider's
own compliance is its half-space Green function (the pair is not one E* any more).

The FE coating effects are differences to a same-mesh "bare" body (a coat of the disk's own
material, identical mesh), so the FE discretisation error (~1e-4 of the force) cancels; the
reference (Hankel-transform) operator's effects are differences to the exact Green solution.
{''.join(x + chr(10) for x in lines)}
## Reading

The contact radius at d = -5 nm is ~3.6 um, so t/a = 6e-4 ... 3e-3 and the overcoat's moduli
are within a factor 2 of the disk's: the coat changes the surface compliance at the contact's
wavelengths by O(t/a) x (modulus contrast). The maximum adhesion force and the contact force
move by at most {100 * max(changes):.2f} % (a 300-GPa coat, stiffer than the disk, lowers the
adhesion and raises the contact force at given d; a 100-GPa coat, softer, does the opposite;
both grow linearly with t). The contact radius r_c (area-equivalent radius of the nodes held
at h = sigma) does not move at all: it changes in node steps (32 nm, 0.9 %), far more than the
coat shifts the contact edge. Jump separations are unchanged at the 0.2-nm sweep resolution.
The force-separation curves of Figs 3/4 are the same at plotting accuracy: paper 1's
homogeneous-E* treatment is adequate for nm-thick overcoats under a mm-sized slider, and a coat
matters only when t is comparable to the contact radius (see layered_film.md). FE and reference
agree on the size and sign of every effect (to ~1e-6 of the force; the coat's effect is
1e-4 ... 1e-3).
"""
    write_result("layered_slider.md", text)


if __name__ == "__main__":
    main()
