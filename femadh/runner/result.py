"""What a run returns: data only (arrays and numbers, picklable, no solver internals).

- :class:`RunResult` - what every run has: its name and scene, ``status`` ("running" until
  the run decides, then "converged", "failed", "interrupted" or "time limit"), ``error``,
  ``exit_code`` of a stopped run, ``timings``, ``out_dir``, the ``headline`` numbers with
  their estimated errors, :meth:`~RunResult.summary` (summary.json) and
  :meth:`~RunResult.to_csv`.
- :class:`ContactResult` - a contact scene: the approach/retract curves with every force
  column, the jumps, the error breakdown, the grid, the instrument's record.
- :class:`MeniscusRunResult` - a meniscus scene: one force curve per liquid, radius, method.

The run's life (status "running" on disk from the start, the outcome mapped to a status, the
final summary) is :mod:`femadh.runner.lifecycle`'s, the same for every kind.
"""
import csv
from dataclasses import dataclass, field
import numpy as np

#: short names of curve columns for :meth:`ContactResult.curve` (csv name -> short)
SHORT = {"d_m": "d", "h0_m": "h0", "F_LJ_N": "F_LJ", "F_el_N": "F_el", "F_ex_N": "F_ex",
         "r_c_m": "r_c", "n_iter": "n_iter", "residual_m": "residual",
         "converged": "converged", "stable": "stable", "F_cap_N": "F_cap", "F_LJa_N": "F_LJa",
         "F_ela_N": "F_ela"}
#: the statuses of a run stopped at a safe point (resumable)
STOPPED = ("interrupted", "time limit")


@dataclass
class RunResult:
    """What every run returns (a contact, meniscus or study point's run).

    Attributes
    ----------
    name : str
        The scene's name.
    scene : Scene
        The scene that was run.
    status : str
        "running" until the run decides; then "converged", "failed" (``error`` says where),
        "interrupted" (SIGINT/SIGTERM) or "time limit".
    error : str or None
        Why the run did not converge or stopped.
    timings : dict
        Seconds per phase; ``total_s`` the run's.
    out_dir : str or None
        The folder the outputs were written into (None: nothing written).
    headline : dict
        The headline numbers (e.g. max adhesion, N) and, as ``<name>_error``, their
        estimated errors (same unit).
    exit_code : int or None
        A stopped run's exit code: 130 (SIGINT), 143 (SIGTERM), 6 (time limit); None for a
        run that converged or failed (the command line exits 0 or 3).
    failure_kind : str or None
        What ended a run that did not converge, by the exception's type
        (:func:`femadh.estimate.guards.failure_kind`: "analysis_radius", "trapping",
        "bound", "budget", "convergence", "time_limit", "interrupted", "error", ...;
        "accuracy": an accuracy request not met); None for a converged run. The refine loops
        switch on it.
    """

    name: str
    scene: object
    status: str = "running"
    error: str | None = None
    timings: dict = field(default_factory=dict)
    out_dir: str | None = None
    headline: dict = field(default_factory=dict)
    exit_code: int | None = None
    failure_kind: str | None = None

    #: the scene kind ("contact", "meniscus")
    kind = None

    @property
    def wall_time(self):
        """The run's wall time (s)."""
        return float(self.timings.get("total_s", 0.0))

    def stop(self, exc, where=""):
        """The run stopped at a safe point by ``exc`` (an Interrupted or TimeLimitReached):
        its status, error (``where`` appended) and exit code."""
        from ..estimate.guards import failure_kind

        self.status, self.error, self.exit_code = exc.status, f"{exc}{where}", exc.exit_code
        self.failure_kind = failure_kind(exc)

    def fail(self, error, kind="error"):
        """The run failed: ``error`` says where and why, ``kind`` what kind of failure it is
        (:attr:`failure_kind`)."""
        self.status, self.error, self.failure_kind = "failed", error, kind

    def summary(self, status=None):
        """summary.json of the run as a dict (``status`` overrides the result's)."""
        raise NotImplementedError(f"{type(self).__name__} has no summary")

    def table(self):
        """(header, rows) of the run's csv (:meth:`to_csv`)."""
        raise NotImplementedError(f"{type(self).__name__} has no table")

    def to_csv(self, path):
        """The run's curves as one csv (:meth:`table`); returns ``path``."""
        header, rows = self.table()
        with open(path, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(header)
            w.writerows(rows)
        return path


@dataclass
class ContactResult(RunResult):
    """A contact run (the fields of :class:`RunResult` and these).

    Attributes
    ----------
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
    warnings : list of str
    stopped_in_figures : dict or None
        A run stopped while its figures were drawn (status "interrupted" or "time limit"):
        the outcome it had reached before them ({"status", "error", "failure_kind"}; its
        numbers are complete). summary.json keeps it, and ``--resume`` ends the run with that
        outcome, drawing only the figures not yet on disk
        (:func:`femadh.runner.figures.resume_figures`). None otherwise.
    """

    branches: dict = field(default_factory=dict)
    jumps: list = field(default_factory=list)
    equilibrium_curve: dict | None = None
    profiles: dict = field(default_factory=dict)
    nodes: np.ndarray | None = None
    estimates: dict = field(default_factory=dict)
    warnings: list = field(default_factory=list)
    accuracy: dict = field(default_factory=dict)
    grid: dict = field(default_factory=dict)
    instrument: dict | None = None
    stopped_in_figures: dict | None = None

    kind = "contact"

    def curve(self, branch):
        """Arrays of one branch with short names: d, h0, F_LJ, F_el, F_ex, r_c, n_iter,
        residual, converged, stable, and F_cap / F_LJa / F_ela where the scene has them."""
        return {SHORT.get(k, k): v for k, v in self.branches[branch].items()}

    def table(self):
        """Both branches in one table (the columns of curve.csv after a "branch" column)."""
        rows = []
        header = None
        for b, cols in self.branches.items():
            header = header or ["branch"] + list(cols)
            n = len(next(iter(cols.values())))
            for i in range(n):
                rows.append([b] + [_cell(cols[k][i]) for k in cols])
        return header or ["branch"], rows

    def summary(self, status=None):
        """summary.json of a contact run (:func:`contact_summary`)."""
        return contact_summary(self, status)


def _cell(x):
    if isinstance(x, (bool, np.bool_)):
        return bool(x)
    if isinstance(x, (int, np.integer)):
        return int(x)
    return repr(float(x))


#: what meniscus.csv and summary.json say the meniscus columns mean
MENISCUS_NOTE = (
    "Capillary force on the sphere, attractive positive, normalised by 4 pi R gamma with R "
    "the solid tip radius; the adsorbed film (thickness h from the isotherm) covers sphere "
    "and flat, the film-covered sphere has radius R + h and, in contact, D = -2h "
    "(paper 2 Fig 2b); zero contact angle on the films. 'no-film' is the exact meniscus on "
    "bare solids (h = 0).")
MENISCUS_COLUMNS = ["liquid", "tip_radius_m", "method", "p_ratio", "film_m", "kelvin_radius_m",
                    "force_N", "force_over_4piRgamma", "neck_radius_m", "force_error_N"]


@dataclass
class MeniscusRunResult(RunResult):
    """A meniscus run (the fields of :class:`RunResult` and these).

    Attributes
    ----------
    curves : dict
        ``(liquid, tip_radius_m, method)`` -> dict of arrays (p_ratio, film_m,
        kelvin_radius_m, force_N, force_over_4piRgamma, neck_radius_m and the estimated error
        force_error_N; nan where no meniscus exists).
    errors : list of dict
        The points without a meniscus (liquid, tip_radius_m, method, p_ratio and why).
    headline : dict
        ``max_force_N[liquid,R,method]``: the largest capillary force of each curve (N) and,
        as ``..._error``, the estimated error at it (nan: not estimated, the circular
        approximation); set when the run ends.
    """

    curves: dict = field(default_factory=dict)
    errors: list = field(default_factory=list)

    kind = "meniscus"

    def table(self):
        """Every curve in one table (:data:`MENISCUS_COLUMNS`)."""
        rows = [[liq, repr(R), meth] + [repr(float(c[k][i])) for k in MENISCUS_COLUMNS[3:]]
                for (liq, R, meth), c in self.curves.items() for i in range(len(c["p_ratio"]))]
        return MENISCUS_COLUMNS, rows

    def summary(self, status=None):
        """summary.json of a meniscus run."""
        from .._version import __version__

        return {"femadh_version": __version__, "scene_file": self.scene.path,
                "status": status or self.status, "error": self.error, "note": MENISCUS_NOTE,
                "scene": self.scene.resolved, "domain_errors": self.errors,
                "timings_s": self.timings, "wall_time_s": self.wall_time}


def meniscus_headline(curves):
    """The largest force of each meniscus curve (N) and its estimated error (the error of
    that point; nan where not estimated): ``max_force_N[liquid,R,method]`` and
    ``max_force_N[liquid,R,method]_error`` (R in m, as ``%g``)."""
    out = {}
    for (liq, R, meth), c in curves.items():
        f = np.asarray(c["force_N"], float)
        if not np.any(np.isfinite(f)):
            continue
        k = int(np.nanargmax(f))
        key = f"max_force_N[{liq},{R:g},{meth}]"
        out[key] = float(f[k])
        out[f"{key}_error"] = float(np.asarray(c["force_error_N"], float)[k])
    return out


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
            "failure_kind": res.failure_kind,
            # the scene actually run (an adaptive trial's; its rows' checksums are seeded
            # with it)
            "run_id": scene_id(scene),
            "sign_convention": SIGN_NOTE, "scene": scene.resolved, "branches": branches,
            "jumps": res.jumps, "headline": res.headline, "error_estimates": res.estimates,
            "instrument": instrument_summary(res),
            "accuracy": res.accuracy, "grid": res.grid, "warnings": res.warnings,
            # (only a run stopped in its figures: what --resume ends it with)
            **({"stopped_in_figures": res.stopped_in_figures}
               if getattr(res, "stopped_in_figures", None) is not None else {}),
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
    if "pull_off_tail" in res.instrument:
        # the spring holds the whole sphere: the pull-off's share beyond the analysis radius
        out["pull_off_tail"] = res.instrument["pull_off_tail"]
    return out
