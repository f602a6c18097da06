"""Figures a researcher would draw for a run (matplotlib, Agg backend, PNG, written atomically).

- every contact scene: ``force_curve.png`` - force on the sphere against separation, approach
  and retract in two colours, each active effect's force, the jumps as arrows, a zoom on the
  adhesion peak, the DMT and JKR pull-off of the scene's own work of adhesion; for arclength
  runs the traced equilibrium curve with its unstable branch. A run with jumps gets a second
  panel, the hysteresis loop zoomed to the folds (on the whole curve the jumps of paper 1
  Fig 4 are 50 uN on a 3-mN scale, 0.07 nm apart on a 7-nm sweep: invisible);
- sigma-gap LJ scenes (paper 1 Figs 3-4): ``profiles_and_forces.png`` - the paper's panels
  (deformation, LJ and contact pressure profiles, forces, contact radius with JKR/DMT,
  iterations);
- meniscus scenes: ``meniscus_force.png`` (paper 2 Fig 1 style); regime maps: their figures.
Units are chosen from the magnitudes (nm or um, pN ... mN).
"""
import math

import numpy as np

from .atomic import save_atomic


#: legend names of branches whose key is not what a reader should see
BRANCH_LABELS = {"retract_edge_branch": "retract (edge route, no approach)"}

def _pyplot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def _save(fig, path, dpi=100):
    """PNG, atomically; fast zlib level (the files are small either way)."""
    save_atomic(path, lambda p: fig.savefig(p, dpi=dpi, pil_kwargs={"compress_level": 1}))


def force_unit(values):
    """(scale, label) so that values * scale are between 1 and 1000 in the returned unit."""
    m = float(np.nanmax(np.abs(values))) if np.size(values) else 1.0
    for scale, label in ((1e12, "pN"), (1e9, "nN"), (1e6, "µN"), (1e3, "mN")):
        if m * scale < 1000:
            return scale, label
    return 1.0, "N"


def value_error_text(v, err=None, digits=5):
    """``"v ± err"`` as metrology writes it: the error to one significant digit, the value
    rounded to the decimal place of that digit (``-1.6020443 ± 5e-07``, ``109.497 ± 0.008``,
    ``31.15 ± 0.03``): a value printed to fewer places hides digits its estimate supports (a
    newcomer read -1.602 ± 5e-07 mN, 95 errors from the true -1.6020443), to more it claims
    digits the estimate does not. The value keeps at most 15 significant digits (a double's);
    below 1e-3 or from 1e6 on it is written with an exponent (``1.234e-15 ± 3e-18``).
    Without an error (None or not finite) the value to ``digits`` significant digits alone;
    an error of exactly 0 is printed as ``± 0`` beside those digits. Dimensionless: the
    caller scales both numbers to one unit."""
    if err is None or not np.isfinite(err) or not np.isfinite(v):
        return f"{v:.{digits}g}"
    if err == 0:
        return f"{v:.{digits}g} ± 0"
    e = float(f"{abs(err):.1g}")          # rounded first: 0.0096 -> 0.01 sets the place
    place = math.floor(math.log10(e))     # the decimal exponent of the error's one digit
    mag = math.floor(math.log10(abs(v))) if v else place
    place = max(place, mag - 14)
    # the form and the digits from the value rounded to that place (9.99996e6 +- 100 is
    # 1.00000e+07, 6e-4 +- 0.005 is 0.001), the rounding itself by the format
    r = round(v, -place)
    rmag = math.floor(math.log10(abs(r))) if r else place
    expo = r != 0 and not 1e-3 <= abs(r) < 1e6
    if abs(v) < 0.5 * 10.0 ** place:
        txt = "0"
    elif not expo:
        txt = f"{r:.{max(-place, 0)}f}"
    else:
        txt = f"{r:.{max(rmag - place, 0)}e}"
    if float(txt) == 0:
        txt = txt.lstrip("-")             # (no "-0.00")
    etxt = f"{e:.0e}" if expo and not 1e-3 <= e < 1e6 else f"{e:.0f}" if e >= 1 else f"{e:.1g}"
    return f"{txt} ± {etxt}"


def force_text(x, err=None):
    """A force as femadh states it, in the terminal and in a figure alike: in the unit that
    fits the force itself (:func:`force_unit` of ``x`` alone), its estimated error to one
    significant digit in the same unit and the force to that digit's decimal place
    (:func:`value_error_text`: ``"31.15 ± 0.03 µN"``); without an error (None or not
    finite) the force to five significant digits alone. ``x``, ``err`` in N."""
    s, unit = force_unit([x])
    return f"{value_error_text(x * s, None if err is None else err * s)} {unit}"


def max_adhesion_text(hl):
    """"max adhesion 31.15 ± 0.03 µN at d = 1.13 ± 0.01 nm" from a headline: the force and
    the separation it is reached at, each to the place its own error supports (the
    separation of a flat maximum is known to ~1e-2 at the defaults, not to four digits).
    The terminal's line and the force curve's inset both."""
    e_f, e_d = hl.get("max_adhesion_N_error"), hl.get("d_at_max_adhesion_m_error")
    d = value_error_text(hl["d_at_max_adhesion_m"] * 1e9, None if e_d is None else e_d * 1e9,
                         4)
    return f"max adhesion {force_text(hl['max_adhesion_N'], e_f)} at d = {d} nm"


def length_unit(values):
    """(scale, label) for lengths: nm below 1 um, else um (mm above 1 mm)."""
    m = float(np.nanmax(np.abs(values))) if np.size(values) else 1.0
    if m < 1e-6:
        return 1e9, "nm"
    if m < 1e-3:
        return 1e6, "µm"
    return 1e3, "mm"


def figure_names(res):
    """The file names of a contact run's figures, in the order they are drawn."""
    names = ["force_curve.png"]
    sc = res.scene
    if "lj" in sc.effects and sc.gap is not None and res.profiles:
        names.append("profiles_and_forces.png")
    if getattr(res, "instrument", None) is not None:
        names.append("instrument.png")
    return names


def contact_figures(res, folder, only=None):
    """The figures of a contact run into ``folder`` (``only``: those of these file names);
    returns their paths."""
    from pathlib import Path

    draw = {"force_curve.png": force_curve, "profiles_and_forces.png": paper1_panels,
            "instrument.png": instrument_figure}
    folder = Path(folder)
    return [draw[name](res, folder / name) for name in figure_names(res)
            if only is None or name in only]


#: figures laid out before their data (:func:`prepare`), each taken by the next figure drawn
#: with that layout
_PREPARED = {}
#: ticks made ready on each axis of a prepared figure (an axis shows up to ~10; one that
#: needs more makes them as it draws)
_TICKS = 12


def prepare():
    """Lay out the six-panel figure of :func:`paper1_panels` before its data arrives: its
    Axes and the Tick objects of its 12 axes, ~0.1 s of the figure's ~0.4 s (a figure
    worker does this while the run solves, so that the run does not wait for it). A tick
    made now is the one a draw would make (each copies the first tick's properties, as
    matplotlib's own lazy ticks do), so the picture is the same, byte for byte."""
    plt = _pyplot()
    fig, ax = plt.subplots(2, 3, figsize=(15, 8.5))
    for a in ax.ravel():
        for axis in (a.xaxis, a.yaxis):
            axis.get_major_ticks(_TICKS)
    _PREPARED["panels"] = fig


def _panels_figure(plt):
    """(figure, its six axes in reading order): the one :func:`prepare` made, else new."""
    fig = _PREPARED.pop("panels", None)
    if fig is None:
        fig, _ = plt.subplots(2, 3, figsize=(15, 8.5))
    return fig, list(fig.axes)


def warm_up():
    """Import matplotlib and draw a small figure off-screen: its fonts, text layout and
    mathtext caches are then ready (a figure worker does this while the run solves)."""
    import io

    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(2, 1.5))
    ax.plot([0, 1], [0, 1], "-o", label="µ σ")
    ax.plot([], [], marker=r"$\rightarrow$", ls="")
    ax.set(xlabel="d (nm)", title="warm-up")
    ax.legend(fontsize=7)
    fig.savefig(io.BytesIO(), format="png", dpi=50)
    plt.close(fig)
    from .. import reference  # noqa: F401  (the panels' JKR/DMT lines)
    from ..laws import registry  # noqa: F401  (the effects' labels)


def instrument_figure(res, path):
    """What the instrument records beside what the contact does: left, the force the spring
    reads against the drive z, approach and retract, each jump an arrow at fixed z; right, the
    contact's own F(d) (the traced equilibrium curve where there is one, its unstable parts
    dashed; else the displacement-controlled branches) with the instrument's states on it."""
    plt = _pyplot()
    ins = res.instrument
    paths = ins["paths"]
    allF = np.concatenate([p["F_N"] for p in paths.values()])
    fs, fl = force_unit(allF)
    alld = np.concatenate([p["d_m"] for p in paths.values()] + [p["z_m"] for p in
                                                                 paths.values()])
    ls, ll = length_unit(alld)
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
    colors = {"approach": "tab:blue", "retract": "tab:red"}
    for b, p in paths.items():
        z, F, kind = p["z_m"], p["F_N"], p["kind"]
        start = 0
        for i in range(1, len(z) + 1):     # one line per run between jumps
            if i == len(z) or kind[i] == "land":
                ax[0].plot(z[start:i] * ls, F[start:i] * fs, color=colors[b],
                           label=b if start == 0 else None)
                start = i
    for j in ins["jumps"]:
        if not np.isfinite(j["F_after_N"]):
            continue
        ax[0].annotate("", xy=(j["z_m"] * ls, j["F_after_N"] * fs),
                       xytext=(j["z_m"] * ls, j["F_before_N"] * fs),
                       arrowprops={"arrowstyle": "->", "color": colors[j["branch"]]})
    k = ins["spring"]["stiffness_N_per_m"]
    ax[0].axhline(0, color="0.7", lw=0.8)
    ax[0].set(xlabel=f"drive z = d + F/k ({ll})", ylabel=f"force the instrument reads ({fl}, "
              "tension +)", title=f"instrument, k = {k:.3g} N/m")
    ax[0].legend()
    eq = res.equilibrium_curve
    if eq is not None and len(eq["d_m"]):
        d, F, st = eq["d_m"], eq["F_ex_N"], np.asarray(eq["stable"], bool)
        ax[1].plot(np.where(st, d, np.nan) * ls, np.where(st, F, np.nan) * fs, color="0.3",
                   label="contact F_ex(d), stable")
        ax[1].plot(np.where(~st, d, np.nan) * ls, np.where(~st, F, np.nan) * fs, "--",
                   color="0.3", label="unstable")
    else:
        for b, c in res.branches.items():
            ax[1].plot(c["d_m"] * ls, c["F_ex_N"] * fs, color="0.3", lw=1,
                       label="contact F_ex(d), displacement-controlled" if b == "approach"
                       else None)
    for b, p in paths.items():
        pts = np.array([kd == "point" for kd in p["kind"]])
        ax[1].plot(p["d_m"][pts] * ls, p["F_N"][pts] * fs, ".", ms=3, color=colors[b],
                   label=f"held by the instrument ({b})")
    ax[1].axhline(0, color="0.7", lw=0.8)
    # where the contact acts: from the deepest state to a few times the farthest jump
    far = max([j["d_fold_m"] for j in ins["jumps"]], default=None)
    if far is not None and far > 0:
        lo = min(float(np.min(p["d_m"])) for p in paths.values())
        hi = min(lo + 4 * (far - lo), float(np.max(alld)))
        ax[1].set_xlim(lo * ls, hi * ls)
        near = np.concatenate([p["F_N"][(p["d_m"] >= lo) & (p["d_m"] <= hi)]
                               for p in paths.values()])
        if near.size:
            pad = 0.05 * (near.max() - near.min() + 1e-300)
            ax[1].set_ylim((near.min() - pad) * fs, (near.max() + pad) * fs)
    ax[1].set(xlabel=f"separation d ({ll})", ylabel=f"F ({fl})",
              title="the contact's own curve (near contact)")
    ax[1].legend(fontsize=8)
    fig.tight_layout()
    _save(fig, path)
    plt.close(fig)
    return path


def _effect_lines(res):
    """(column, sign on the sphere, label) of each force the run has: the force on the
    sphere is minus the force on the disk."""
    from ..laws.registry import outputs

    labels = {o.force: o.label for o in outputs().values()}
    out = [("F_ex_N", -1.0, "total (−F_ex)")]
    cols = next(iter(res.branches.values())).keys()
    for c in cols:
        if c.startswith("F_") and c not in ("F_ex_N", "F_tail_N"):
            if c == "F_el_N":
                out.append((c, 1.0, "asperity contact (σ-gap)"))
            else:
                sign = -1.0 if c != "F_ela_N" else 1.0
                out.append((c, sign, labels.get(c, c)))
    return out


def force_curve(res, path):
    """Force on the sphere (adhesive negative) against the separation d."""
    plt = _pyplot()
    sc = res.scene
    allF = np.concatenate([c["F_ex_N"] for c in res.branches.values()])
    alld = np.concatenate([c["d_m"] for c in res.branches.values()])
    fs, fl = force_unit(allF)
    ls, ll = length_unit(alld)
    loop = bool(res.jumps)
    fig = plt.figure(figsize=(15 if loop else 11, 5.2))
    # fixed layout (tight_layout draws the figure twice): the legend right of the axes
    ax = fig.add_axes([0.06, 0.1, 0.42, 0.83] if loop else [0.08, 0.1, 0.62, 0.83])
    styles = {"approach": "-", "retract": "--"}
    lines = _effect_lines(res)
    for i, (col, sign, label) in enumerate(lines):
        for b, c in res.branches.items():
            if col not in c or (col != "F_ex_N" and not np.any(c[col])):
                continue
            # a retract traced another way (the edge route's branch) draws as the retract
            kind = "retract" if b.startswith("retract") else b
            name = BRANCH_LABELS.get(b, b)
            if col == "F_ex_N":
                d, F = branch_with_folds(res, b, c)
                ax.plot(d * ls, -F * fs, styles.get(kind, "-"),
                        color=BRANCH_COLOURS.get(kind, "k"), lw=2, label=f"{label}, {name}")
                continue
            ax.plot(c["d_m"] * ls, sign * c[col] * fs, styles.get(kind, "-"),
                    color=EFFECT_COLOURS[(i - 1) % len(EFFECT_COLOURS)], lw=1,
                    label=f"{label}, {name}")
    if res.equilibrium_curve is not None and len(res.equilibrium_curve["d_m"]):
        e = res.equilibrium_curve
        Fu = np.where(~e["stable"], -e["F_ex_N"], np.nan)
        ax.plot(e["d_m"] * ls, Fu * fs, ":", color="grey", lw=1.5,
                label="unstable equilibria (traced)")
    _jump_arrows(ax, res, fs, ls)
    hl = res.headline
    if hl.get("work_of_adhesion_J_per_m2"):
        W = hl["work_of_adhesion_J_per_m2"]
        for val, name, st in ((hl["dmt_pull_off_N"], "DMT 2πRW", "-."),
                              (hl["jkr_pull_off_N"], "JKR 1.5πRW", ":")):
            ax.axhline(-val * fs, color="grey", ls=st, lw=0.8,
                       label=f"{name} (W = {W:.3g} J/m²)")
    ax.axhline(0, color="k", lw=0.5)
    ax.set(xlabel=f"separation d ({ll})", ylabel=f"force on the sphere ({fl}), adhesion < 0",
           title=f"{sc.name}: R = {sc.sphere.radius * length_unit([sc.sphere.radius])[0]:g} "
                 f"{length_unit([sc.sphere.radius])[1]}, E* = {sc.e_star / 1e9:.3g} GPa"
                 + (f", σ = {sc.gap.sigma * 1e9:g} nm ({sc.gap.contact_model})"
                    if sc.gap else ", smooth sphere"))
    _adhesion_zoom(ax, res, ls, ll)
    ax.grid(alpha=0.3)
    if loop:
        zoom = fig.add_axes([0.545, 0.1, 0.25, 0.83])
        lo, hi = draw_hysteresis_loop(zoom, res, fs, fl)
        # where the zoom is on the whole curve: a shaded strip of its separations (its
        # force range is a few percent of this axis' and would not show as a box)
        ax.axvspan(lo * ls, hi * ls, color="0.88", zorder=0)
        ax.annotate("zoom →", xy=(hi * ls, 0.97), xycoords=("data", "axes fraction"),
                    xytext=(3, 0), textcoords="offset points", fontsize=7, color="0.3",
                    va="top")
        ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(0.805, 0.93),
                  bbox_transform=fig.transFigure, borderaxespad=0)
        ax.set_title(ax.get_title(), fontsize=10)
    else:
        ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0)
    _save(fig, path)
    plt.close(fig)
    return path


#: approach and retract: two colours (and solid / dashed) wherever a figure shows both
BRANCH_COLOURS = {"approach": "tab:blue", "retract": "tab:red"}
#: each effect's force: colours that are neither branch's
EFFECT_COLOURS = ("tab:orange", "tab:green", "tab:purple", "tab:brown", "tab:olive",
                  "tab:cyan", "tab:pink")


def branch_with_folds(res, branch, c):
    """(d, F_ex) of a branch in the order it was traced with each jump inserted: the fold
    state (where the branch ends) and a break (nan) before the landing state, so the line
    follows the branch to its fold and the jump is left to its arrow."""
    d, F = list(c["d_m"]), list(c["F_ex_N"])
    sign = -1.0 if branch == "approach" else 1.0     # the approach runs towards smaller d
    pts = [(sign * x, 1, x, f) for x, f in zip(d, F)]
    for j in res.jumps:
        if j["branch"] != branch:
            continue
        pts.append((sign * j["d_fold_m"], 0, j["d_fold_m"], j["F_ex_before_N"]))
        pts.append((sign * j["d_land_m"], 0.5, np.nan, np.nan))
        pts.append((sign * j["d_land_m"], 0.7, j["d_land_m"], j["F_ex_after_N"]))
    pts.sort(key=lambda p: (p[0], p[1]))
    return np.array([p[2] for p in pts]), np.array([p[3] for p in pts])


def _jump_arrows(ax, res, fs, ls, lw=1.2):
    """Each jump as an arrow from its fold state to its landing state, in its branch's
    colour."""
    for j in res.jumps:
        ax.annotate("", xy=(j["d_land_m"] * ls, -j["F_ex_after_N"] * fs),
                    xytext=(j["d_fold_m"] * ls, -j["F_ex_before_N"] * fs),
                    arrowprops={"arrowstyle": "-|>", "color": BRANCH_COLOURS.get(
                        j["branch"], "C3"), "lw": lw, "mutation_scale": 12})


def draw_hysteresis_loop(ax, res, fs, fl):
    """The loop between the jumps, zoomed: x from the first to the last fold padded by a
    sweep step (or the folds' spread), y over what both branches do there; the computed
    states marked, the folds crossed, the jumps as arrows, the loop shaded. Returns the
    zoom's separation range (m)."""
    folds = [j["d_fold_m"] for j in res.jumps] + [j["d_land_m"] for j in res.jumps]
    lo, hi = min(folds), max(folds)
    d_all = np.concatenate([c["d_m"] for c in res.branches.values()])
    steps = np.diff(np.unique(d_all))
    step = float(np.median(steps)) if steps.size else (hi - lo)
    pad = max(step, hi - lo, 1e-12)
    lo, hi = lo - pad, hi + pad
    ls, ll = length_unit([abs(lo), abs(hi), hi - lo])
    ys = []
    traced = {}
    for b, c in res.branches.items():
        d, F = branch_with_folds(res, b, c)
        traced[b] = (d, F)
        ax.plot(d * ls, -F * fs, "-" if b == "approach" else "--",
                color=BRANCH_COLOURS.get(b, "k"), lw=2, label=b)
        on = (c["d_m"] >= lo) & (c["d_m"] <= hi)
        ax.plot(c["d_m"][on] * ls, -c["F_ex_N"][on] * fs, "o", ms=4,
                color=BRANCH_COLOURS.get(b, "k"))
        sel = np.isfinite(d) & (d >= lo) & (d <= hi)
        ys.append(-F[sel] * fs)
    for j in res.jumps:
        ax.plot([j["d_fold_m"] * ls], [-j["F_ex_before_N"] * fs], "x", ms=7, mew=2,
                color=BRANCH_COLOURS.get(j["branch"], "k"))
        ys.append(np.array([-j["F_ex_before_N"] * fs, -j["F_ex_after_N"] * fs]))
    _jump_arrows(ax, res, fs, ls, lw=2.0)
    y = np.concatenate(ys)
    span = float(y.max() - y.min()) or abs(float(y.max())) or 1.0
    ax.set_xlim(lo * ls, hi * ls)
    ax.set_ylim(y.min() - 0.12 * span, y.max() + 0.12 * span)
    if "approach" in traced and "retract" in traced:
        # the loop: between the two branches over the folds' interval
        grid = np.linspace(min(folds), max(folds), 200)
        fa = np.interp(grid, *_finite_sorted(*traced["approach"]))
        fr = np.interp(grid, *_finite_sorted(*traced["retract"]))
        ax.fill_between(grid * ls, -fa * fs, -fr * fs, color="0.85", zorder=0,
                        label="hysteresis loop")
    hl = res.headline
    energy = (f", energy lost per cycle {hl['hysteresis_J']:.3g} J" if "hysteresis_J" in hl
              else "")
    ax.set(xlabel=f"separation d ({ll})", ylabel=f"force on the sphere ({fl})")
    ax.set_title(f"hysteresis loop (zoom){energy}", fontsize=9)
    ax.plot([], [], "o", color="0.3", ms=4, label="computed state (lines join them)")
    ax.plot([], [], "x", color="0.3", label="fold (the branch ends)")
    ax.plot([], [], color="0.3", marker=r"$\rightarrow$", ls="", ms=12, label="jump")
    ax.legend(fontsize=7, loc="best")
    ax.grid(alpha=0.3)
    return lo, hi


def _finite_sorted(d, F):
    """A branch's finite points in increasing d (for interpolation across its fold: the
    branch up to the fold, then the landing branch)."""
    ok = np.isfinite(d)
    order = np.argsort(d[ok], kind="stable")
    return d[ok][order], F[ok][order]


def _adhesion_zoom(ax, res, ls, ll):
    """An inset around the adhesion peak when the repulsive range dwarfs it, in the peak's
    force unit (the one its title and the terminal state it in)."""
    tot = -np.concatenate([c["F_ex_N"] for c in res.branches.values()])
    d = np.concatenate([c["d_m"] for c in res.branches.values()])
    peak = float(np.min(tot))
    if peak >= 0 or np.max(tot) < 5 * abs(peak):
        return
    near = np.abs(tot) <= 3 * abs(peak)
    fs, fl = force_unit([peak])     # (not the whole curve's: mN on a Fig 3 run)
    ins = ax.inset_axes([0.38, 0.52, 0.36, 0.38])
    for b, c in res.branches.items():
        sel = np.abs(c["F_ex_N"]) <= 3 * abs(peak)
        ins.plot(c["d_m"][sel] * ls, -c["F_ex_N"][sel] * fs, "-" if b == "approach" else "--",
                 color=BRANCH_COLOURS.get(b, "k"), lw=1.2)
    ins.axhline(0, color="k", lw=0.5)
    hl = res.headline
    if hl.get("work_of_adhesion_J_per_m2"):
        # the DMT/JKR lines of the main axes, readable at this scale
        for key, st in (("dmt_pull_off_N", "-."), ("jkr_pull_off_N", ":")):
            ins.axhline(-hl[key] * fs, color="grey", ls=st, lw=0.8)
    if "max_adhesion_N" in hl:
        F, dm = hl["max_adhesion_N"], hl["d_at_max_adhesion_m"]
        ins.plot([dm * ls], [-F * fs], "v", color="C3")
        # the very words and digits of the terminal's line (femadh.runner.report)
        ins.set_title(max_adhesion_text(hl), fontsize=7)
    ins.set_xlabel(f"d ({ll})", fontsize=6, labelpad=1)
    ins.set_ylabel(f"force ({fl})", fontsize=6, labelpad=1)
    ins.tick_params(labelsize=6)
    ins.set_xlim(np.min(d[near]) * ls, np.max(d[near]) * ls)
    ins.grid(alpha=0.3)


def paper1_panels(res, path):
    """Paper 1 Fig 3-style panels: (a) w(r), (b) P_LJ(r), (c) P_el(r), (d) forces vs d,
    (e) r_c vs -F_ex with JKR/DMT of the scene's own work of adhesion, (f) iterations and
    -log10(residual) per state."""
    from ..reference import dmt_contact_radius, jkr_contact_radius

    plt = _pyplot()
    sc = res.scene
    rs, rl = length_unit(res.nodes)
    fig, ax = _panels_figure(plt)
    first = next(iter(res.profiles))
    prof = res.profiles[first]
    cmap = plt.get_cmap("viridis")
    n = len(prof["d_m"])
    for i in range(n):
        c = cmap(i / max(1, n - 1))
        # each profile on its own nodes (a grid that follows the contact edge changes them)
        r = np.asarray(prof["r_m"][i] if "r_m" in prof else res.nodes, float)
        ax[0].plot(r * rs, prof["w_m"][i] * 1e9, color=c,
                   label=f"{round(prof['d_m'][i] * 1e9, 2) + 0.0:.2f}")  # no "-0.00"
        ax[1].plot(r * rs, prof["P_LJ_Pa"][i] * 1e-6, color=c)
        ax[2].plot(r * rs, prof["P_el_Pa"][i] * 1e-6, color=c)
    ax[0].set(xlabel=f"r ({rl})", ylabel="w (nm)", title=f"(a) disk deformation, {first}")
    ax[0].legend(title="d (nm)", fontsize=6, ncol=2)
    ax[1].set(xlabel=f"r ({rl})", ylabel="P_LJ (MPa)", title="(b) LJ pressure")
    ax[2].set(xlabel=f"r ({rl})", ylabel="P_el (MPa)", title="(c) contact pressure")
    allF = np.concatenate([np.abs(c[k]) for c in res.branches.values()
                           for k in ("F_LJ_N", "F_ex_N", "F_el_N")])
    fs, fl = force_unit(allF)
    styles = {"approach": "-o", "retract": "--s"}
    for b, c in res.branches.items():
        st = styles.get(b, "-")
        ax[3].plot(c["d_m"] * 1e9, -c["F_LJ_N"] * fs, st, ms=3, label=f"-F_LJ {b}")
        ax[3].plot(c["d_m"] * 1e9, -c["F_ex_N"] * fs, st, ms=3, label=f"-F_ex {b}")
        ax[3].plot(c["d_m"] * 1e9, c["F_el_N"] * fs, st, ms=3, label=f"F_el {b}")
        ax[4].plot(-c["F_ex_N"] * fs, c["r_c_m"] * rs, st, ms=3, label=f"femadh {b}")
        ax[5].plot(c["d_m"] * 1e9, c["n_iter"], st, ms=3, label=f"iterations {b}")
        ax[5].plot(c["d_m"] * 1e9, -np.log10(np.maximum(c["residual_m"] / 1e-9, 1e-300)), st,
                   ms=3, label=f"-log10(residual/nm) {b}")
    for j in res.jumps:
        ax[3].axvline(j["d_fold_m"] * 1e9, color="grey", lw=0.8, ls=":")
    ax[3].set(xlabel="d (nm)", ylabel=f"force on the sphere ({fl}), adhesion < 0",
              title="(d) forces vs separation")
    ax[3].legend(fontsize=7)
    W = res.headline.get("work_of_adhesion_J_per_m2")
    if W:
        allEx = np.concatenate([-c["F_ex_N"] for c in res.branches.values()])
        R, E = sc.sphere.radius, sc.e_star
        F = np.linspace(min(allEx.min(), -2 * np.pi * R * W), allEx.max(), 200)
        ax[4].plot(F * fs, [jkr_contact_radius(f, R, E, W) * rs for f in F], "k-", lw=1,
                   label=f"JKR (W = {W:.3g} J/m²)")
        ax[4].plot(F * fs, [dmt_contact_radius(f, R, E, W) * rs for f in F], "k--", lw=1,
                   label="DMT")
    ax[4].set(xlabel=f"-F_ex, force on the sphere ({fl})", ylabel=f"r_c ({rl})",
              title="(e) contact radius")
    ax[4].legend(fontsize=7)
    ax[5].set(xlabel="d (nm)", ylabel="iterations; -log10(residual / nm)",
              title="(f) iterations, -log10 residual")
    ax[5].legend(fontsize=7)
    Rs, Rl = length_unit([sc.sphere.radius])
    fig.suptitle(f"{sc.name}: R = {sc.sphere.radius * Rs:g} {Rl}, E* = {sc.e_star / 1e9:.1f} GPa, "
                 f"σ = {sc.gap.sigma * 1e9:g} nm ({sc.gap.contact_model})")
    fig.subplots_adjust(left=0.05, right=0.98, bottom=0.07, top=0.92, wspace=0.25, hspace=0.3)
    _save(fig, path)
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
    save_atomic(out / "regime_map.png", lambda p: fig.savefig(p, dpi=110))
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
    save_atomic(out / "regime_curves.png", lambda p: fig.savefig(p, dpi=110))
    plt.close(fig)


def meniscus_forces(res, path):
    """Force / (4 pi R gamma) against p/psat per liquid (panels), method (style), radius
    (colour), in the style of paper 2 Fig 1; from a MeniscusRunResult."""
    plt = _pyplot()
    scene = res.scene
    nl = len(scene.liquids)
    fig, axes = plt.subplots(1, nl, figsize=(5.2 * nl, 4.3), squeeze=False)
    styles = {"fe": "-", "shooting": "o", "circular": "--", "no-film": ":"}
    colors = plt.get_cmap("viridis")(np.linspace(0, 0.85, len(scene.radii)))
    for ax, lq in zip(axes[0], scene.liquids):
        for c, R in zip(colors, scene.radii):
            Rs, Rl = length_unit([R])
            for meth in scene.methods:
                cur = res.curves.get((lq.name, R, meth))
                if cur is None:
                    continue
                ax.plot(cur["p_ratio"], cur["force_over_4piRgamma"], styles.get(meth, "-"),
                        color=c, ms=3, label=f"{meth}, R = {R * Rs:g} {Rl}")
        ax.axhline(1.0, color="grey", lw=0.8)
        ax.set(xlabel="p/psat", ylabel="F / 4πRγ", title=lq.name, xlim=(0, 1))
        ax.grid(alpha=0.3)
    axes[0][0].legend(fontsize=6, ncol=2)
    fig.tight_layout()
    save_atomic(path, lambda p: fig.savefig(p, dpi=110))
    plt.close(fig)
    return path
