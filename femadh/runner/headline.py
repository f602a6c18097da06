"""The headline numbers of a contact run, read off its curves: the largest adhesion (and where),
the jump separations, the hysteresis, the contact radius where the external force vanishes,
the forces at the deepest separation; beside them the scene's own work of adhesion and the
DMT/JKR pull-off it implies (the bounds of a smooth law of that work)."""
import math

import numpy as np

from ..reference import dmt_pull_off, jkr_pull_off


def work_of_adhesion(problem):
    """Energy per area (J/m^2) to separate the surfaces from contact: -sum of the laws'
    energies at the contact gap (sigma with the sigma-gap, else the largest gap where the
    summed law turns repulsive). Eq 20 on the contact set is range-less and adds none."""
    if not problem.effects:
        return 0.0
    if problem.sigma is not None:
        h_c = problem.sigma
    else:
        scan = np.logspace(-7, -11, 4000)
        rep = np.flatnonzero(problem.pointwise_pressure(scan) < 0)
        h_c = float(scan[rep[0]]) if rep.size else float(scan[-1])
    return float(-sum(np.asarray(e.energy(np.array([h_c])))[0]
                      for e in problem.effects.values()))


def _zero_crossing(d, f, r):
    """Contact radius where F_ex crosses zero (linear interpolation), or nan."""
    for k in range(len(f) - 1):
        if r[k] > 0 and r[k + 1] > 0 and f[k] * f[k + 1] <= 0 and f[k] != f[k + 1]:
            t = f[k] / (f[k] - f[k + 1])
            return float(r[k] + t * (r[k + 1] - r[k]))
    return math.nan


def headline(res, problem):
    """Dict of the headline numbers (SI); see the module docstring."""
    out = {}
    best = None
    for b, c in res.branches.items():
        if len(c["d_m"]) == 0:
            continue
        k = int(np.argmax(c["F_ex_N"]))
        if best is None or c["F_ex_N"][k] > best[0]:
            best = (float(c["F_ex_N"][k]), float(c["d_m"][k]), b)
        out[f"r_c_at_zero_force_{b}_m"] = _zero_crossing(c["d_m"], c["F_ex_N"], c["r_c_m"])
    if best:
        out["max_adhesion_N"], out["d_at_max_adhesion_m"], out["max_adhesion_branch"] = best
    deep = res.branches.get("approach")
    if deep is not None and len(deep["d_m"]):
        out["d_deepest_m"] = float(deep["d_m"][-1])
        out["F_LJ_deepest_N"] = float(deep["F_LJ_N"][-1])
        out["F_ex_deepest_N"] = float(deep["F_ex_N"][-1])
    ins = [j for j in res.jumps if j["branch"] == "approach"]
    outs = [j for j in res.jumps if j["branch"] == "retract"]
    if ins:
        out["jump_in_d_m"] = float(ins[0]["d_fold_m"])
    if outs:
        out["jump_out_d_m"] = float(outs[-1]["d_fold_m"])
    released = [j["energy_released_J"] for j in res.jumps]
    if released and all(math.isfinite(x) for x in released):
        out["hysteresis_J"] = float(sum(released))
    spring = getattr(res.scene, "instrument", None)
    if spring is not None and res.branches:
        from .instrument import instrument_numbers

        out.update(instrument_numbers(res, spring))
    if problem is not None:
        W = work_of_adhesion(problem)
        R = problem.sphere.radius
        out["work_of_adhesion_J_per_m2"] = W
        out["dmt_pull_off_N"] = dmt_pull_off(R, W)
        out["jkr_pull_off_N"] = jkr_pull_off(R, W)
    return out

