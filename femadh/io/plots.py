"""Figures a researcher would draw from a run (matplotlib, Agg backend, PNG)."""
import numpy as np


def _pyplot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def paper1_panels(result, path, *, max_profiles=12):
    """Paper 1 Fig 3-style panels: (a) w(r), (b) P_LJ(r), (c) P_el(r), (d) forces vs d,
    (e) r_c vs -F_ex, (f) iterations and -log10(residual) per step."""
    from ..reference import dmt_contact_radius, jkr_contact_radius, surface_energy_from_hamaker

    plt = _pyplot()
    problem, scene = result.problem, result.scene
    r_um = problem.grid.nodes * 1e6
    fig, ax = plt.subplots(2, 3, figsize=(15, 8.5))
    ax = ax.ravel()
    first = next(iter(result.sweeps))
    states = result.sweeps[first].states
    pick = states[:: max(1, len(states) // max_profiles)]
    cmap = plt.get_cmap("viridis")
    for i, s in enumerate(pick):
        c = cmap(i / max(1, len(pick) - 1))
        lbl = f"{s.d * 1e9:.2f}"
        ax[0].plot(r_um, s.w * 1e9, color=c, label=lbl)
        ax[1].plot(r_um, s.p_effects.get("lj", 0 * s.w) * 1e-6, color=c)
        ax[2].plot(r_um, s.p_contact * 1e-6, color=c)
    ax[0].set(xlabel="r (µm)", ylabel="w (nm)", title=f"(a) disk deformation, {first}")
    ax[0].legend(title="d (nm)", fontsize=6, ncol=2)
    ax[1].set(xlabel="r (µm)", ylabel="P_LJ (MPa)", title="(b) LJ pressure")
    ax[2].set(xlabel="r (µm)", ylabel="P_el (MPa)", title="(c) contact pressure")
    styles = {"approach": "-o", "retract": "--s"}
    for b in result.sweeps:
        c = result.curve(b)
        st = styles.get(b, "-")
        ax[3].plot(c["d"] * 1e9, -c["F_LJ"] * 1e3, st, ms=3, label=f"-F_LJ {b}")
        ax[3].plot(c["d"] * 1e9, -c["F_ex"] * 1e3, st, ms=3, label=f"-F_ex {b}")
        ax[3].plot(c["d"] * 1e9, c["F_el"] * 1e3, st, ms=3, label=f"F_el {b}")
        ax[4].plot(-c["F_ex"] * 1e3, c["r_c"] * 1e6, st, ms=3, label=f"femadh {b}")
        sw = result.sweeps[b]
        ax[5].plot([s.d * 1e9 for s in sw.states], [s.n_iter for s in sw.states], st, ms=3,
                   label=f"iterations {b}")
        ax[5].plot([s.d * 1e9 for s in sw.states],
                   [-np.log10(max(s.residual / 1e-9, 1e-300)) for s in sw.states], st, ms=3,
                   label=f"-log10(residual/nm) {b}")
    for j in result.jumps:
        ax[3].axvline(j.d_fold * 1e9, color="grey", lw=0.8, ls=":")
    ax[3].set(xlabel="d (nm)", ylabel="force on slider (mN)", title="(d) forces vs separation")
    ax[3].legend(fontsize=7)
    if "lj" in scene.effects and scene.gap is not None:
        lj = scene.effects["lj"]
        dg = surface_energy_from_hamaker(lj.hamaker, scene.gap.sigma, lj.z0)  # eq 17
        allF = np.concatenate([-result.curve(b)["F_ex"] for b in result.sweeps])
        F = np.linspace(min(allF.min(), -2 * np.pi * scene.sphere.radius * dg), allF.max(), 200)
        R, E = scene.sphere.radius, scene.e_star
        ax[4].plot(F * 1e3, [jkr_contact_radius(f, R, E, dg) * 1e6 for f in F], "k-", lw=1,
                   label="JKR (eq 17 Δγ)")
        ax[4].plot(F * 1e3, [dmt_contact_radius(f, R, E, dg) * 1e6 for f in F], "k--", lw=1,
                   label="DMT (eq 17 Δγ)")
    ax[4].set(xlabel="-F_ex, force on slider (mN)", ylabel="r_c (µm)", title="(e) contact radius")
    ax[4].legend(fontsize=7)
    ax[5].set(xlabel="d (nm)", title="(f) iterations, -log10 residual")
    ax[5].legend(fontsize=7)
    fig.suptitle(f"{scene.name}: R = {scene.sphere.radius * 1e3:g} mm, "
                 f"E* = {scene.e_star / 1e9:.1f} GPa, "
                 + (f"σ = {scene.gap.sigma * 1e9:g} nm ({scene.gap.contact_model})"
                    if scene.gap else "smooth sphere"))
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def regime_figures(pts, out_dir):
    """regime_map.png (pull-off vs Tabor mu against Maugis-Dugdale, JKR and DMT; fold
    separations; hysteresis) and regime_curves.png (traced F(d) curves of the smallest, middle
    and largest mu, unstable branches dashed, with the approach and retract paths)."""
    import math
    from pathlib import Path

    import numpy as np

    from ..reference.maugis import lj_dugdale_lambda, maugis_pull_off

    plt = _pyplot()
    out = Path(out_dir)
    fig, ax = plt.subplots(1, 3, figsize=(15, 4.2))
    mu_fine = np.logspace(-1.2, math.log10(6), 60)
    ax[0].semilogx(mu_fine, [maugis_pull_off(lj_dugdale_lambda(m)) for m in mu_fine], "k-",
                   label="Maugis-Dugdale, λ = 1.157 μ")
    ax[0].axhline(2.0, color="grey", ls="--", label="DMT 2πRΔγ")
    ax[0].axhline(1.5, color="grey", ls=":", label="JKR 1.5πRΔγ")
    ax[0].semilogx([p.mu for p in pts], [p.pull_off for p in pts], "o",
                   label="femadh LJ sphere")
    ax[0].set(xlabel="Tabor μ", ylabel="pull-off / πRΔγ", title="pull-off force (load control)")
    ax[0].legend(fontsize=8)
    for p in pts:
        if p.jump_in:
            ax[1].semilogx(p.mu, p.jump_in, "v", color="C0")
            ax[1].semilogx(p.mu, p.jump_out, "^", color="C1")
    ax[1].set(xlabel="Tabor μ", ylabel="d / z0 at the fold",
              title="jump-in (▼, approach) and jump-out (▲, retract)")
    ax[2].loglog([p.mu for p in pts if p.hysteresis > 0],
                 [p.hysteresis for p in pts if p.hysteresis > 0], "s-")
    ax[2].set(xlabel="Tabor μ", ylabel="work per cycle / (πRΔγ z0)",
              title="approach-retract hysteresis")
    for a in ax:
        a.grid(alpha=0.3, which="both")
    fig.tight_layout()
    fig.savefig(out / "regime_map.png", dpi=110)
    plt.close(fig)
    # the traced curves themselves, unstable branches dashed, paths of the experiment
    show = [p for p in pts if p.mu in (pts[0].mu, pts[len(pts) // 2].mu, pts[-1].mu)] or pts[:3]
    fig, ax = plt.subplots(1, len(show), figsize=(5 * len(show), 4))
    for a, p in zip(np.atleast_1d(ax), show):
        c = p.curves
        st = c["curve_stable"]
        F = np.where(st, c["curve_F"], np.nan)
        Fu = np.where(~st, c["curve_F"], np.nan)
        a.plot(c["curve_d"], F, "k-", lw=1, label="stable")
        a.plot(c["curve_d"], Fu, "k--", lw=1, label="unstable (traced)")
        a.plot(c["approach_d"], c["approach_F"], "C0:", lw=2, label="approach path")
        a.plot(c["retract_d"], c["retract_F"], "C1:", lw=2, label="retract path")
        a.set(xlabel="d / z0", ylabel="F / πRΔγ (tension > 0)", title=f"μ = {p.mu:.3g}",
              xlim=(min(c["curve_d"]), 12))
        a.grid(alpha=0.3)
        a.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out / "regime_curves.png", dpi=110)
    plt.close(fig)


def meniscus_forces(scene, results, path):
    """Force / (4 pi R gamma) vs p/psat per liquid (panels), method (style), radius (colour),
    in the style of paper 2 Fig 1."""
    plt = _pyplot()
    nl = len(scene.liquids)
    fig, axes = plt.subplots(1, nl, figsize=(5.2 * nl, 4.3), squeeze=False)
    styles = {"fe": "-", "shooting": "o", "circular": "--", "no-film": ":"}
    colors = plt.get_cmap("viridis")(np.linspace(0, 0.85, len(scene.radii)))
    for ax, lq in zip(axes[0], scene.liquids):
        for c, R in zip(colors, scene.radii):
            for meth in scene.methods:
                res = results[lq.name, R, meth]
                x = [p for p, r in zip(scene.p_ratios, res) if not isinstance(r, Exception)]
                f = [r.force_over_4piRgamma for r in res if not isinstance(r, Exception)]
                ax.plot(x, f, styles.get(meth, "-"), color=c, ms=3,
                        label=f"{meth}, R = {R * 1e9:g} nm")
        ax.axhline(1.0, color="grey", lw=0.8)
        ax.set(xlabel="p/psat", ylabel="F / 4πRγ", title=lq.name, xlim=(0, 1))
        ax.grid(alpha=0.3)
    axes[0][0].legend(fontsize=6, ncol=2)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
