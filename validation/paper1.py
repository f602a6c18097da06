"""Paper 1 (sphere-disk LJ contact), sections 4-5: femadh vs the paper, both contact models.

Run ``python -m validation.paper1`` (add ``--quick`` for the coarse mesh the tests use). It
prints and writes ``validation/results/paper1_table.md``. Paper values are read off the text
(sec 4-5); every difference is discussed in validation/README.md.
"""
import argparse
import copy
import math
import time
from pathlib import Path

import numpy as np

try:
    import tomllib
except ModuleNotFoundError:
    import tomli as tomllib

from femadh.reference import (contact_lj_force_estimate, max_rigid_lj_force,
                              surface_energy_from_hamaker, tabor_parameter, dmt_pull_off)
from femadh.contact.forces import state_forces
from femadh.runner.contact import solve_sweeps
from femadh.scene import scene_from_dict

HERE = Path(__file__).resolve().parent
SCENES = HERE / "scenes"
RESULTS = HERE / "results"

#: what the paper states in its text (sec 4-5), for the table
PAPER = {
    "fig3": {"F_LJ_deep_mN": 0.25, "max_F_ex_mN": 0.03, "d_max_nm": 1.1, "snap_in_nm": None},
    "fig4": {"F_LJ_deep_mN": None, "max_F_ex_mN": 0.3, "d_max_nm": None, "snap_in_nm": 1.0,
             "r_c_at_zero_um": 3.7, "tabor": 1.64},
}


def scene(file, nodes=None, **over):
    """Load a bundled scene with overrides, e.g. scene('paper1_fig3', sigma='0.5 nm')."""
    data = tomllib.loads((SCENES / f"{file}.toml").read_text())
    data = copy.deepcopy(data)
    if nodes:
        data["solver"]["nodes"] = nodes
    for k, v in over.items():
        if k in ("sigma", "contact_model"):
            data["effects"]["asperity_gap"][k] = v
        elif k == "name":
            data["scene"]["name"] = v
        else:
            raise KeyError(k)
    return scene_from_dict(data, str(SCENES / f"{file}.toml"))


def _r_c_at_zero_force(c):
    """Contact radius where F_ex crosses zero on a branch (linear interpolation), or nan."""
    f, r = c["F_ex"], c["r_c"]
    for k in range(len(f) - 1):
        if r[k] > 0 and r[k + 1] > 0 and f[k] * f[k + 1] <= 0 and f[k] != f[k + 1]:
            t = f[k] / (f[k] - f[k + 1])
            return r[k] + t * (r[k + 1] - r[k])
    return math.nan


def _curve(problem, states):
    f = np.array([state_forces(problem, s) for s in states]).reshape(-1, 3)
    return {"d": np.array([s.d for s in states]), "F_LJ": f[:, 0], "F_el": f[:, 1],
            "F_ex": f[:, 2], "r_c": np.array([s.r_c for s in states])}


def measure(sc):
    """The table's quantities for one scene (approach branch unless stated), from its states
    (solved here, nothing written)."""
    lj = sc.effects["lj"]
    t0 = time.perf_counter()
    problem, sweeps, error = solve_sweeps(sc)
    row = {"status": "failed" if error else "converged", "wall_s": time.perf_counter() - t0,
           "error": error}
    if "approach" not in sweeps:
        return row
    states = sweeps["approach"].states
    c = _curve(problem, states)
    row["states"] = {b: sw.states for b, sw in sweeps.items()}
    row["problem"] = problem
    row["d_reached_nm"] = c["d"][-1] * 1e9
    row["F_LJ_deep_mN"] = c["F_LJ"][-1] * 1e3
    k = int(np.argmax(c["F_ex"]))
    row["max_F_ex_mN"] = c["F_ex"][k] * 1e3
    row["d_max_nm"] = c["d"][k] * 1e9
    row["r_c_at_zero_um"] = _r_c_at_zero_force(c) * 1e6
    jumps = [j for sw in sweeps.values() for j in sw.jumps]
    row["jumps"] = "; ".join(f"{j.branch} {j.d_fold * 1e9:.4f} nm" for j in jumps) or "none"
    # eq 15 vs the computed F_LJ over all contact states (h0 = sigma)
    sig = sc.gap.sigma
    rel = [abs(contact_lj_force_estimate(sig, s.r_c, lj.hamaker, lj.z0, sc.sphere.radius)
               - f) / f for s, f in zip(states, c["F_LJ"]) if s.r_c > 0]
    row["eq15_max_rel_diff"] = max(rel) if rel else math.nan
    # do eq 8 and eq 10 hold inside the contact?
    row["eq8_min_h_minus_sigma_nm"] = min(float(np.min(s.h)) - sig for s in states) * 1e9
    # eq 10, w = C (P - p_c), recomputed from each state's own pressures (not read from a
    # solver diagnostic): inside the contact and outside it
    C = problem.C
    r10 = [np.abs(s.w - C @ s.p_total) for s in states]
    row["eq10_inside_nm"] = max(float(np.max(r[s.active], initial=0.0))
                                for r, s in zip(r10, states)) * 1e9
    row["eq10_residual_nm"] = max(float(np.max(r[~s.active], initial=0.0))
                                  for r, s in zip(r10, states)) * 1e9
    dg = surface_energy_from_hamaker(lj.hamaker, sig, lj.z0)           # eq 17
    row["tabor_eq17_sigma"] = tabor_parameter(sc.sphere.radius, dg, sc.e_star, sig)
    row["tabor_eq17_z0"] = tabor_parameter(sc.sphere.radius, dg, sc.e_star, lj.z0)
    row["AR/8z0^2_uN"] = max_rigid_lj_force(lj.hamaker, lj.z0, sc.sphere.radius) * 1e6
    row["2piR_dgamma_eq17_uN"] = dmt_pull_off(sc.sphere.radius, dg) * 1e6
    return row


def cases(quick):
    n = 100 if quick else None
    out = []
    for fig, sig in (("fig3", "1.0 nm"), ("fig4", "0.5 nm")):
        for model in ("complementarity", "hertz-closure"):
            out.append((fig, model, scene("paper1_fig3", n, sigma=sig, contact_model=model,
                                          name=f"paper1-{fig}-{model}")))
    for sig in ("0.25 nm", "0.20 nm", "0.18 nm", "0.165 nm", "0.16 nm", "0.15 nm"):
        out.append((f"fig6 σ={sig}", "complementarity",
                    scene("paper1_fig6_sigma0.20", n, sigma=sig, name=f"fig6-{sig}")))
    return out


def table(quick=False):
    rows = []
    for fig, model, sc in cases(quick):
        m = measure(sc)
        m.pop("states", None)
        m.pop("problem", None)
        rows.append({"case": fig, "model": model, **m})
    return rows


COLS = ["case", "model", "status", "d_reached_nm", "F_LJ_deep_mN", "max_F_ex_mN", "d_max_nm",
        "r_c_at_zero_um", "jumps", "eq15_max_rel_diff", "eq8_min_h_minus_sigma_nm",
        "eq10_inside_nm", "eq10_residual_nm", "tabor_eq17_sigma", "tabor_eq17_z0",
        "AR/8z0^2_uN", "2piR_dgamma_eq17_uN", "wall_s"]


def _fmt(v):
    if isinstance(v, float):
        return "nan" if math.isnan(v) else f"{v:.4g}"
    return str(v)


def markdown(rows):
    lines = ["| " + " | ".join(COLS) + " |", "|" + "---|" * len(COLS)]
    for r in rows:
        lines.append("| " + " | ".join(_fmt(r.get(c, "")) for c in COLS) + " |")
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="N = 100 instead of the scenes' N")
    args = ap.parse_args(argv)
    rows = table(args.quick)
    md = markdown(rows)
    print(md)
    RESULTS.mkdir(exist_ok=True)
    name = "paper1_table_quick.md" if args.quick else "paper1_table.md"
    (RESULTS / name).write_text("# Paper 1 vs femadh (generated by validation/paper1.py)\n\n"
                                + md + "\n")


if __name__ == "__main__":
    main()
