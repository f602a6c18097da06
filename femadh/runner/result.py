"""What a run returns: data only (arrays and numbers, picklable, no solver internals).

- :class:`ContactResult` - a contact scene: status, the approach/retract curves with every
  force column, the jumps, the headline numbers with their error estimates, timings.
- :class:`MeniscusRunResult` - a meniscus scene: one force curve per liquid, radius, method.

Both have ``to_csv`` and ``status`` ("running" until the run decides, then "converged",
"failed", "interrupted" or "time limit") and ``error``.
"""
import csv
from dataclasses import dataclass, field

import numpy as np

#: short names of curve columns for :meth:`ContactResult.curve` (csv name -> short)
SHORT = {"d_m": "d", "h0_m": "h0", "F_LJ_N": "F_LJ", "F_el_N": "F_el", "F_ex_N": "F_ex",
         "r_c_m": "r_c", "n_iter": "n_iter", "residual_m": "residual",
         "converged": "converged", "stable": "stable", "F_cap_N": "F_cap", "F_LJa_N": "F_LJa",
         "F_ela_N": "F_ela"}


@dataclass
class ContactResult:
    """A contact run.

    Attributes
    ----------
    name : str
    scene : Scene
    status : str
        "running" until the run decides; then "converged", "failed" (``error`` says where),
        "interrupted" or "time limit".
    error : str or None
    branches : dict
        "approach" / "retract" -> dict of arrays keyed by the curve.csv columns (d_m, h0_m,
        F_LJ_N, F_el_N, F_ex_N, r_c_m, n_iter, residual_m, converged, stable, and one force
        column per further law: F_cap_N, F_LJa_N, F_ela_N).
    jumps : list of dict
        branch, d_fold_m, d_land_m, resolution_m, F_ex_before_N, F_ex_after_N, h0_before_m,
        h0_after_m.
    equilibrium_curve : dict or None
        Arclength runs: every traced point (d_m, h0_m, F_ex_N, stable, dd_ds, residual_m).
    profiles : dict
        branch -> {"d_m": (k,), "w_m": (k, N), "P_LJ_Pa": (k, N), "P_el_Pa": (k, N)}: a few
        states' surface fields (for the figures); all of them are in fields.csv.
    nodes : ndarray
        The radial nodes (m).
    headline : dict
        The headline numbers (e.g. max adhesion) and, as ``<name>_error``, their estimated
        errors (see :mod:`femadh.runner.headline`, :mod:`femadh.runner.estimates`).
    estimates : dict
        The error breakdown: quantity -> {grid, fe_mesh, resolution, tail, tolerance, total}.
    accuracy : dict
        Accuracy mode: the target, what was chosen (nodes, analysis radius) and the steps.
    instrument : dict or None
        Scenes with an [instrument]: its spring, the paths it drives (branch -> z_m, d_m,
        F_N, kind), its jumps and the readout's resolution of each headline number
        (:mod:`femadh.instrument.readout`).
    grid : dict
        The discretisation used: kind (uniform/banded), nodes, analysis radius, band and
        spacing (banded), the spacing ratio of the estimate's coarser members and their labels.
    timings : dict
        Seconds per phase.
    warnings : list of str
    out_dir : str or None
    """

    name: str
    scene: object
    status: str = "running"
    error: str | None = None
    branches: dict = field(default_factory=dict)
    jumps: list = field(default_factory=list)
    equilibrium_curve: dict | None = None
    profiles: dict = field(default_factory=dict)
    nodes: np.ndarray | None = None
    headline: dict = field(default_factory=dict)
    estimates: dict = field(default_factory=dict)
    timings: dict = field(default_factory=dict)
    warnings: list = field(default_factory=list)
    out_dir: str | None = None
    accuracy: dict = field(default_factory=dict)
    grid: dict = field(default_factory=dict)
    instrument: dict | None = None

    kind = "contact"

    @property
    def wall_time(self):
        return float(self.timings.get("total_s", 0.0))

    def curve(self, branch):
        """Arrays of one branch with short names: d, h0, F_LJ, F_el, F_ex, r_c, n_iter,
        residual, converged, stable, and F_cap / F_LJa / F_ela where the scene has them."""
        return {SHORT.get(k, k): v for k, v in self.branches[branch].items()}

    def to_csv(self, path):
        """Both branches in one csv (the columns of curve.csv)."""
        rows = []
        header = None
        for b, cols in self.branches.items():
            header = header or ["branch"] + list(cols)
            n = len(next(iter(cols.values())))
            for i in range(n):
                rows.append([b] + [_cell(cols[k][i]) for k in cols])
        with open(path, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(header or ["branch"])
            w.writerows(rows)
        return path


def _cell(x):
    if isinstance(x, (bool, np.bool_)):
        return bool(x)
    if isinstance(x, (int, np.integer)):
        return int(x)
    return repr(float(x))


@dataclass
class MeniscusRunResult:
    """A meniscus run: ``curves[(liquid, tip_radius_m, method)]`` is a dict of arrays
    (p_ratio, film_m, kelvin_radius_m, force_N, force_over_4piRgamma, neck_radius_m and the
    estimated error force_error_N; nan where no meniscus exists), ``errors`` the points without
    one (dicts naming liquid, radius, method, p/psat and why)."""

    name: str
    scene: object
    status: str = "running"
    error: str | None = None
    curves: dict = field(default_factory=dict)
    errors: list = field(default_factory=list)
    timings: dict = field(default_factory=dict)
    out_dir: str | None = None

    kind = "meniscus"

    @property
    def wall_time(self):
        return float(self.timings.get("total_s", 0.0))

    def to_csv(self, path):
        cols = ["liquid", "tip_radius_m", "method", "p_ratio", "film_m", "kelvin_radius_m",
                "force_N", "force_over_4piRgamma", "neck_radius_m", "force_error_N"]
        with open(path, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(cols)
            for (liq, R, meth), c in self.curves.items():
                for i in range(len(c["p_ratio"])):
                    w.writerow([liq, repr(R), meth] + [repr(float(c[k][i])) for k in cols[3:]])
        return path


def contact_summary(res, status=None):
    """summary.json of a contact run."""
    from .._version import __version__

    scene = res.scene
    from ..io.writers import SIGN_NOTE

    branches = {}
    for b, cols in res.branches.items():
        n = len(cols["d_m"])
        if not n:
            continue
        k = int(np.argmax(cols["F_ex_N"]))
        branches[b] = {"n_states": n, "max_F_ex_N": float(cols["F_ex_N"][k]),
                       "d_at_max_F_ex_m": float(cols["d_m"][k]),
                       "all_converged": bool(np.all(cols["converged"])),
                       "all_stable": bool(np.all(cols["stable"]))}
    from ..scene import scene_id

    return {"femadh_version": __version__, "scene_file": scene.path,
            "status": status or res.status, "error": res.error,
            # the scene actually run (an adaptive trial's; its rows' checksums are seeded
            # with it)
            "run_id": scene_id(scene),
            "sign_convention": SIGN_NOTE, "scene": scene.resolved, "branches": branches,
            "jumps": res.jumps, "headline": res.headline, "error_estimates": res.estimates,
            "instrument": instrument_summary(res),
            "accuracy": res.accuracy, "grid": res.grid, "warnings": res.warnings,
            "timings_s": res.timings, "wall_time_s": res.wall_time}


def instrument_summary(res):
    """summary.json's "instrument": the spring and what it records (the headline's
    ``instrument_<name>`` numbers under their own names, each with its ``_error``), the jumps,
    and why a path stops short (``incomplete``); None without an instrument."""
    if res.instrument is None:
        return None
    from .instrument import INSTRUMENT_NUMBERS

    out = dict(res.instrument["spring"])
    for name in INSTRUMENT_NUMBERS:
        key = f"instrument_{name}"
        if key in res.headline:
            out[name] = res.headline[key]
            if f"{key}_error" in res.headline:
                out[f"{name}_error"] = res.headline[f"{key}_error"]
    if "instrument_stuck" in res.headline:
        out["verdict"] = "stuck" if res.headline["instrument_stuck"] else "free"
        if "instrument_release_margin_m" in res.headline:
            out["release_margin_m"] = res.headline["instrument_release_margin_m"]
    # each jump as recorded, less the readout's bookkeeping (the interval it refined)
    out["jumps"] = [{k: v for k, v in j.items() if k != "turn"}
                    for j in res.instrument["jumps"]]
    out["incomplete"] = res.instrument["incomplete"]
    return out
