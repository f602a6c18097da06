"""The sigma-gap curve traced by arclength (femadh.contact.sigma_arclength) against the
stepping solver: stable states, folds, hysteresis, cost. Writes results/sigma_continuation.md.

    python -m validation.sigma_continuation        (~1 min, one BLAS thread)
"""
import copy
import os
from pathlib import Path
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")


from femadh.contact import trace  # noqa: E402
from femadh.contact.forces import state_forces  # noqa: E402
from femadh.contact.sigma_arclength import curve_state, path_w_at, trace_sigma_curve  # noqa
from femadh.runner.run import run  # noqa: E402
from femadh.scene import build_problem, load_scene, scene_from_dict  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "validation" / "results" / "sigma_continuation.md"
REPEAT = 3


def _variant(scene, **solver):
    raw = copy.deepcopy(scene.raw)
    for k, v in solver.items():
        if v is None:
            raw["solver"].pop(k, None)
        else:
            raw["solver"][k] = v
    return scene_from_dict(raw, scene.path)


def _smoothed(scene):
    """The scene with its eq 20 adhesion as the smoothed law (the contact-set model is no
    single curve: refused by the arclength continuation)."""
    raw = copy.deepcopy(scene.raw)
    raw["effects"]["asperity_adhesion"]["model"] = "smoothed"
    return scene_from_dict(raw, scene.path)


def _best(fn):
    times, out = [], None
    for _ in range(REPEAT):
        t = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t)
    return min(times), out


def compare(scene):
    """Measured agreement and cost of the traced curve against the stepped run."""
    arc = _variant(scene, continuation="arclength")
    t_steps, rs = _best(lambda: run(scene, None, figures=False, progress=False,
                                    estimate=False))
    t_arc, ra = _best(lambda: run(arc, None, figures=False, progress=False, estimate=False))
    problem = build_problem(scene)
    d, tol = scene.d_values, scene.tolerance
    t_sweep, (ap, rt) = _best(lambda: _sweeps(problem, d, tol))
    t_curve, curve = _best(lambda: trace_sigma_curve(problem, d[0], d[-1], tol=tol,
                                                     scale=abs(d[1] - d[0]), ds=1.0,
                                                     ds_max=1.0))

    def F(dk, wk):
        return state_forces(problem, curve_state(problem, dk, wk, True))[2]
    worst, n = 0.0, 0
    for sweep, branch in ((ap, "approach"), (rt, "retract")):
        for st in sweep.states:
            w = path_w_at(curve, branch, st.d)
            f = state_forces(problem, st)[2]
            worst = max(worst, abs(F(st.d, w) - f) / abs(f))
            n += 1
    jumps = ap.jumps + rt.jumps
    fold_rows = []
    for j in jumps:
        sign = -1.0 if j.branch == "approach" else 1.0
        near = min(curve.folds, key=lambda f: abs(f.d - j.d_fold))
        fold_rows.append((j.branch, j.d_fold, near.d, sign * (near.d - j.d_fold) / j.resolution))
    released = sum(problem.energy(j.before.w, j.d_land) - problem.energy(j.after.w, j.d_land)
                   for j in jumps)
    bound = sum(abs(state_forces(problem, j.after)[2] - state_forces(problem, j.before)[2])
                * j.resolution for j in jumps)
    f_max = max(F(p.d, p.w) for p in curve.points)
    f_pull = max([state_forces(problem, s)[2] for s in rt.states]
                 + [state_forces(problem, j.before)[2] for j in rt.jumps])
    return {"nodes": problem.grid.n, "t_steps": t_steps, "t_arc": t_arc,
            "t_sweep": t_sweep, "t_curve": t_curve, "status": (rs.status, ra.status),
            "worst": worst, "n_states": n, "folds": fold_rows, "n_points": len(curve.points),
            "n_pieces": len(curve.tracers), "n_folds": len(curve.folds),
            "released": released, "bound": bound, "cycle": curve.cycle_work(F) if jumps
            else 0.0, "walk_hyst": ra.headline.get("hysteresis_J", 0.0),
            "f_max": f_max, "f_pull": f_pull,
            "jumps_arc": len(ra.jumps), "jumps_steps": len(rs.jumps)}


def _sweeps(problem, d, tol):
    ap = trace(problem, d, branch="approach", tol=tol)
    rt = trace(problem, d[::-1], branch="retract", tol=tol, start=ap.states[-1])
    return ap, rt


def adaptive(scene):
    """The scene as shipped (adaptive grid, accuracy, error estimates): both continuations."""
    arc = _variant(scene, continuation="arclength")
    out = {}
    for name, sc in (("steps", scene), ("arclength", arc)):
        t = time.perf_counter()
        res = run(sc, None, figures=False, progress=False)
        out[name] = (time.perf_counter() - t, res)
    return out


def main():
    fig3 = load_scene(ROOT / "validation/scenes/paper1_fig3.toml")
    fig4 = load_scene(ROOT / "validation/scenes/paper1_fig4.toml")
    rows = {"Fig 4 (sigma = 0.5 nm), N = 200": compare(_variant(fig4, nodes=200,
                                                                 accuracy=None)),
            "Fig 3 (sigma = 1 nm), N = 200": compare(_variant(fig3, nodes=200)),
            "Fig 8 (rho = 179 um^-2), eq 20 as the smoothed law, N = 200":
                compare(_smoothed(load_scene(ROOT / "validation/scenes/"
                                             "paper1_fig8_rho179.toml")))}
    ad = adaptive(fig4)
    lines = ["# The sigma-gap curve by arclength vs the stepping solver",
             "",
             "`python -m validation.sigma_continuation` (one BLAS thread; times are the best "
             f"of {REPEAT}). The traced curve (femadh/contact/sigma_arclength.py) is evaluated "
             "at every stepped state's d on its displacement-controlled path "
             "(`path_w_at`); folds are compared with the stepped jumps' d_fold (the fold lies "
             "within one halved step, `resolution`, in the travel direction: offset in "
             "[0, 1]); the cycle work is the loop integral of F dd on the curve "
             "(`EquilibriumCurve.cycle_work`), the hysteresis as an area.", ""]
    for name, r in rows.items():
        lines += [f"## {name}", "",
                  "| quantity | value |", "|---|---|",
                  f"| status (steps, arclength) | {r['status']} |",
                  f"| stable states compared | {r['n_states']} |",
                  f"| worst relative F_ex difference | {r['worst']:.2g} |",
                  f"| curve points / active-set pieces / folds | {r['n_points']} / "
                  f"{r['n_pieces']} / {r['n_folds']} |",
                  f"| jumps (steps, arclength path) | {r['jumps_steps']}, {r['jumps_arc']} |"]
        for b, d_s, d_c, off in r["folds"]:
            lines.append(f"| {b} jump: stepped d_fold, nearest curve fold (offset in "
                         f"resolutions) | {d_s * 1e9:.7f} nm, {d_c * 1e9:.7f} nm ({off:.2f}) |")
        if r["released"]:
            lines += [f"| hysteresis: stepped jump energies | {r['released']:.6g} J |",
                      f"| hysteresis: cycle work on the curve | {r['cycle']:.6g} J |",
                      f"| hysteresis: the arclength path's jump energies | "
                      f"{r['walk_hyst']:.6g} J |",
                      f"| stepping-resolution bound sum dF x resolution | {r['bound']:.3g} J |"]
        lines += [f"| largest tension: curve, displacement-controlled | {r['f_max']:.6g} N, "
                  f"{r['f_pull']:.6g} N |",
                  f"| run time: steps, arclength (ratio) | {r['t_steps']:.3f} s, "
                  f"{r['t_arc']:.3f} s ({r['t_arc'] / r['t_steps']:.2f}) |",
                  f"| solver only: stepped sweeps, traced curve (ratio) | "
                  f"{r['t_sweep']:.3f} s, {r['t_curve']:.3f} s "
                  f"({r['t_curve'] / r['t_sweep']:.2f}) |", ""]
    (ts, rs), (ta, ra) = ad["steps"], ad["arclength"]
    lines += ["## Fig 4 as shipped (adaptive grid, accuracy 3e-3, error estimates)", "",
              "| quantity | steps | arclength |", "|---|---|---|",
              f"| status | {rs.status} | {ra.status} |",
              f"| nodes | {rs.accuracy['nodes']} | {ra.accuracy['nodes']} |",
              f"| wall time | {ts:.2f} s | {ta:.2f} s |"]
    for k in ("max_adhesion_N", "jump_in_d_m", "jump_out_d_m", "hysteresis_J"):
        lines.append(f"| {k} | {rs.headline.get(k, float('nan')):.7g} | "
                     f"{ra.headline.get(k, float('nan')):.7g} |")
    lines += ["", f"Load average while measuring: {', '.join(f'{x:.2f}' for x in os.getloadavg())} "
              "(2 cores; the ratios are the comparable numbers).", "",
              "## Notes", "",
              "- On the discrete grid the JKR-side unstable branch is one active-set piece per "
              "node, joined at events; near the jump-out the curve has lattice micro-loops "
              "(a corner fold and a smooth fold per node, d within ~1e-12 m), so the "
              "displacement-controlled retract read off the curve (`walk`: the nearest "
              "stable piece along the curve first) takes a cascade of micro-jumps before "
              "the jump-out, where the stepping solver's energy descent (landing.py) jumps "
              "from the first micro-fold straight to the free surface. Its last fold is "
              "then a few 1e-13 m further out; the hysteresis differs by less than the "
              "stepping resolution's bound.",
              "- Fig 8 with the smoothed eq 20 law: the jump-in (near 1.376 nm) lies inside "
              "one 0.2-nm grid step and moves no gap by more than MAX_CORRECTION_FRACTION, so "
              "the corrector alone lands on the contact branch in one step; the stepping "
              "solver finds it by the step's energy (it releases more than the trapezoid "
              "rule can miss along one branch: `stepping.crossed_fold`), halves down to the "
              "fold and lands there. Before that check it reported no jump-in and a "
              "hysteresis short by the jump-in's energy.",
              "- The largest tension on the whole curve exceeds the displacement-controlled "
              "pull-off where the curve has an unstable JKR side (Fig 4); on Fig 3 (no "
              "folds) the difference is the peak between the 0.2-nm grid states.",
              "- The shipped Fig 4's pull-off separation differs between the two by ~2e-13 m "
              "(about one stepping resolution step: the bracketed fold search's decision "
              "solve fails one step before the last stable state, a path dependence at a "
              "contact fold, within the jump's stated error).",
              "- Cost: the traced curve has a point per contact node (each active-set change "
              "is an event), the stepped sweep one per grid step. Since the stepping solver "
              "brackets a fold instead of halving blindly and its landing's descent stops "
              "at round-off, the two cost about the same with folds (Fig 4, Fig 8); without "
              "folds (Fig 3) the curve costs more, and the runner's per-state outputs add "
              "to it."]
    OUT.write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    import argparse

    # no arguments: --help says what it writes instead of running it
    argparse.ArgumentParser(prog="python -m validation.sigma_continuation",
                            description=__doc__.split("\n\n")[0]).parse_args()
    main()
