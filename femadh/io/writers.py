"""Writers for run results: csv (streamed as each state is computed), json summary.

Each converged state reaches disk as soon as it exists, so an interrupted or failed run keeps
everything it computed.
"""
import csv
import json
import math
from pathlib import Path

import numpy as np

from ..contact.forces import state_forces

CURVE_HEADER = ["branch", "d_m", "h0_m", "F_LJ_N", "F_el_N", "F_ex_N", "r_c_m", "n_iter",
                "residual_m", "converged"]
DIAG_HEADER = ["branch", "d_m", "stable", "n_active", "min_gap_minus_sigma_m",
               "min_contact_pressure_Pa", "eq10_violation_inside_m"]
FIELD_HEADER = ["branch", "d_m", "r_m", "w_m", "h_m", "P_LJ_Pa", "P_el_Pa"]

SIGN_NOTE = ("Forces are on the disk, paper 1 eqs 11-13 with area weights: F_LJ = sum P_LJ dA "
             "(attractive positive), F_el = sigma-gap contact force, repulsive positive; "
             "optional F_cap (capillary), F_LJa (asperity adhesion) attractive positive and "
             "F_ela (Greenwood-Williamson asperity elasticity) repulsive positive; "
             "F_ex = F_LJ + F_cap + F_LJa - F_ela - F_el. The force on the sphere is -F_ex; "
             "adhesion shows as F_ex > 0.")


#: extra curve.csv columns, by effect name (only for the effects a scene names), with the sign
#: that makes them positive in their own sense (attractive, or repulsive for asperity_elastic);
#: fields.csv gets the matching pressure column (attractive positive, as the law returns it)
EFFECT_COLUMNS = {"capillary": ("F_cap_N", 1.0), "asperity_adhesion": ("F_LJa_N", 1.0),
                  "asperity_elastic": ("F_ela_N", -1.0)}
EFFECT_FIELDS = {"capillary": "P_cap_Pa", "asperity_adhesion": "P_LJa_Pa",
                 "asperity_elastic": "P_ela_Pa"}


class RunWriter:
    """Streams curve.csv, diagnostics.csv and fields.csv rows into an output folder."""

    def __init__(self, out_dir, problem, vtk=False):
        self.dir = Path(out_dir)
        self.dir.mkdir(parents=True, exist_ok=True)
        self.problem = problem
        self.vtk = vtk
        self._pvd = {}
        self._files = {}
        self._writers = {}
        self.extra = [k for k in EFFECT_COLUMNS if k in problem.effects]
        curve_header = CURVE_HEADER + [EFFECT_COLUMNS[k][0] for k in self.extra]
        field_header = FIELD_HEADER + [EFFECT_FIELDS[k] for k in self.extra]
        for name, header in (("curve", curve_header), ("diagnostics", DIAG_HEADER),
                             ("fields", field_header)):
            f = open(self.dir / f"{name}.csv", "w", newline="")
            w = csv.writer(f)
            w.writerow(header)
            self._files[name], self._writers[name] = f, w

    def write_state(self, branch, state):
        p = self.problem
        f_lj, f_el, f_ex = state_forces(p, state)
        self._writers["curve"].writerow([
            branch, _g(state.d), _g(state.h0), _g(f_lj), _g(f_el), _g(f_ex), _g(state.r_c),
            state.n_iter, _g(state.residual), state.converged]
            + [_g(EFFECT_COLUMNS[k][1] * p.grid.force(state.p_effects[k])) for k in self.extra])
        sigma = p.sigma
        self._writers["diagnostics"].writerow([
            branch, _g(state.d), state.stable, int(state.active.sum()),
            _g(float(np.min(state.h) - sigma)) if sigma is not None else "",
            _g(float(np.min(state.p_contact))) if state.active.any() else "",
            _g(state.diagnostics.get("eq10_violation_inside_m", 0.0))])
        p_lj = state.p_effects.get("lj", np.zeros_like(state.w))
        rows = np.column_stack([np.full(state.w.size, state.d), p.grid.nodes, state.w, state.h,
                                p_lj, state.p_contact]
                               + [state.p_effects[k] for k in self.extra])
        fw = self._writers["fields"]
        for row in rows:
            fw.writerow([branch] + [_g(x) for x in row])
        for f in self._files.values():
            f.flush()
        if self.vtk:
            from .vtk import write_pvd, write_state

            entries = self._pvd.setdefault(branch, [])
            vol, surf = write_state(self.dir, branch, len(entries) // 2, state, p)
            t = round(state.d * 1e9, 9)
            entries += [(t, vol, 0), (t, surf, 1)]
            write_pvd(self.dir / f"{branch}.pvd", entries)

    def write_equilibrium_curve(self, points, states):
        """equilibrium_curve.csv: every traced point of an arclength curve in arc order,
        stable or not, with the tangent's dd/ds (its sign changes at each fold)."""
        with open(self.dir / "equilibrium_curve.csv", "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["arc_index", "d_m", "h0_m", "F_ex_N", "stable", "dd_ds",
                        "residual_m"])
            for i, (pt, st) in enumerate(zip(points, states)):
                w.writerow([i, _g(st.d), _g(st.h0), _g(state_forces(self.problem, st)[2]),
                            st.stable, _g(pt.t_d), _g(st.residual)])

    def close(self):
        for f in self._files.values():
            f.close()


def _g(x):
    return repr(float(x)) if math.isfinite(x) else str(x)


def write_json(path, data):
    Path(path).write_text(json.dumps(data, indent=2, default=_json_default) + "\n")


def _json_default(o):
    if isinstance(o, (np.floating, np.integer)):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, np.bool_):
        return bool(o)
    raise TypeError(type(o))


def read_curve(path):
    """Read curve.csv into a dict of numpy arrays (and the branch labels)."""
    with open(path) as f:
        rows = list(csv.DictReader(f))
    out = {"branch": np.array([r["branch"] for r in rows])}
    for k in CURVE_HEADER[1:]:
        if k == "converged":
            out[k] = np.array([r[k] == "True" for r in rows])
        else:
            out[k] = np.array([float(r[k]) for r in rows])
    return out
