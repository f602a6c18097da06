"""Least-squares fit of scene parameters and the contact-point offset to a measured curve.

Unknowns: 1-3 scene keys (dotted, as ``femadh study sweep --vary`` takes them, e.g.
``effects.lennard_jones.hamaker``, ``materials.composite_modulus``,
``materials.disk.youngs_modulus``, ``effects.asperity_gap.sigma``,
``effects.capillary.relative_pressure``) and ``z_offset_m``, the measured z at which femadh's
separation d is zero (``d = z - z_offset``). Residual: model force minus measured force (N,
AFM sign), one per measured point. Every evaluation with new scene values is a femadh run
(``estimate=False``, no files); the offset needs no run (the run's curve is shifted).

Jacobian: forward differences of relative step ``rel_step`` in each scene key, the runs of
one Jacobian evaluated in parallel on worker processes (the studies' spawn pool and worker
setup; each worker keeps the surface operator of its grid, reused while the varied key does
not change it, e.g. a Hamaker constant); when there are at least as many workers as scene
keys + 1, the difference runs are started together with the run of each new trial point, so an
accepted step costs one run's wall time. The offset's column is the slope of the
interpolated model.

A scene without ``[solver] nodes`` has an adaptive grid that is planned again for every
parameter value: the model then jumps with the grid and finite differences measure those
jumps. Pin the grid (explicit ``nodes``) for a fit.

Uncertainty: the covariance ``s^2 (J^T J)^-1`` with ``s^2 = RSS / (n - p)`` (n points, p
unknowns, the offset included) at the solution; standard errors are the square roots of its
diagonal, the correlation matrix its normalisation. A parameter the data cannot identify -
a Jacobian column that vanishes, a near-singular ``J^T J``, a relative standard error above 1,
or a correlation beyond +-0.999 - is a :class:`FitError` naming it, not a number.
"""
from dataclasses import dataclass, field
import math
import time

import numpy as np

from ..errors import FemadhError, SceneError
from .model import initial_offset, sim_curve

OFFSET = "z_offset_m"
#: the offset's scale in the solver's unknowns (m): data are nm-scale contact curves
OFFSET_SCALE = 1e-9
#: identifiability thresholds (see the module docstring)
MAX_REL_STDERR = 1.0
MAX_CORRELATION = 0.999
MAX_CONDITION = 1e12          # of J^T J with unit-norm columns


class FitError(FemadhError):
    """A fit that cannot give an answer: a parameter the data cannot identify, the evaluation
    budget spent, or a femadh run failing at a trial point. One line saying which and why."""


@dataclass
class FitResult:
    """A finished fit. ``keys``: the scene keys then ``z_offset_m``; ``values``, ``stderr``
    in SI; ``correlation`` (p x p); ``rss`` (N^2), ``rms`` (N) of the residual; ``n``
    points; ``runs`` femadh runs, ``nfev``/``njev`` residual/Jacobian evaluations;
    ``wall_time`` (s); ``residual`` per point (N); ``sim`` the model at the solution."""

    keys: list
    values: np.ndarray
    stderr: np.ndarray
    correlation: np.ndarray
    rss: float
    rms: float
    n: int
    runs: int
    nfev: int
    njev: int
    wall_time: float
    workers: int
    residual: np.ndarray = field(repr=False, default=None)
    sim: object = field(repr=False, default=None)

    def as_json(self):
        """``{KEY: {"value", "stderr"}, ..., "z_offset_m": {...}, "fit": {...}}`` (SI)."""
        out = {k: {"value": float(v), "stderr": float(s)}
               for k, v, s in zip(self.keys, self.values, self.stderr)}
        out["fit"] = {"rms_residual_N": self.rms, "points": self.n, "femadh_runs": self.runs,
                      "residual_evaluations": self.nfev, "jacobian_evaluations": self.njev,
                      "workers": self.workers, "wall_time_s": self.wall_time,
                      "correlation": {"order": list(self.keys),
                                      "matrix": self.correlation.tolist()}}
        return out


def scene_value(scene, key):
    """The SI value of a dotted key as the scene file sets it (the fit's starting value).

    Raises SceneError for a key the scene does not set (a default has no value to start
    from: set it in the scene) or one that is not a quantity.
    """
    node = scene.raw
    for part in key.split("."):
        if isinstance(node, list) and part.isdigit() and int(part) < len(node):
            node = node[int(part)]
        elif isinstance(node, dict) and part in node:
            node = node[part]
        else:
            raise SceneError(scene.path, key, "(not set)", "a key the scene sets to a number "
                             "or quantity (the fit starts from the scene's value; see "
                             "`femadh keys`)")
    if isinstance(node, bool) or not isinstance(node, (int, float, str)):
        raise SceneError(scene.path, key, node, "a number or a quantity to fit")
    if isinstance(node, (int, float)):
        return float(node)
    from ..units import _registry, _split

    mag, unit = _split(node)
    try:
        q = _registry().Quantity(float(mag), unit.replace("^", "**")) if mag is not None \
            else _registry().Quantity(node)
        value = float(q.to_base_units().magnitude) if hasattr(q, "to_base_units") else float(q)
    except Exception:          # pint raises many types
        raise SceneError(scene.path, key, node, "a number or a quantity to fit") from None
    return value


def check_keys(scene, keys):
    """Starting values of the keys; each must be set by the scene, numeric, and accepted by
    the scene's validation when changed (an unknown key raises SceneError with its
    did-you-mean)."""
    if not 1 <= len(keys) <= 3:
        raise SceneError("command line", "--vary", list(keys), "1 to 3 scene keys")
    if len(set(keys)) != len(keys):
        raise SceneError("command line", "--vary", list(keys), "distinct keys")
    from ..scene import replace_scene

    values = []
    for k in keys:
        try:
            v = scene_value(scene, k)
        except SceneError as exc:
            if exc.value == "(not set)":
                # an unknown key: the scene reader's message (with its did-you-mean) says
                # more, naming the --vary that gave the key (the file does not hold it)
                replace_scene(scene, {k: 1.0}, {}, True, f"--vary {k}")
            raise
        if not (math.isfinite(v) and v > 0):
            raise SceneError(scene.path, k, v, "a positive value to fit (relative steps)")
        # the scene's own value, changed by the fit: its errors name the file that holds it
        replace_scene(scene, {k: v}, {}, True, scene.path)
        values.append(v)
    return values


# --------------------------------------------------------------------------- evaluations

def simulate(scene):
    """One femadh run of a scene for the fit (no files, no error estimate): returns
    (SimCurve or None, error or None). Runs in a worker; keeps the surface operator of the
    grid (one per process, as studies do)."""
    import warnings

    from ..errors import MeshResolutionWarning
    from ..runner.run import run
    from ..studies.executors import tune_malloc, worker_operator

    tune_malloc()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", MeshResolutionWarning)
            op, _ = worker_operator(scene)
            res = run(scene, None, figures=False, progress=False, estimate=False,
                      operator=op)
    except FemadhError as exc:
        return None, f"{type(exc).__name__}: {exc}"
    if res.status != "converged":
        return None, res.error
    return sim_curve(res), None


class Evaluator:
    """femadh runs at parameter vectors, cached; in parallel on ``workers`` processes."""

    def __init__(self, scene, keys, workers=1):
        self.scene, self.keys = scene, list(keys)
        self.workers = max(1, int(workers))
        self.cache, self.runs, self._pool = {}, 0, None

    def scene_at(self, theta):
        try:
            return self.scene.replace({k: float(v) for k, v in zip(self.keys, theta)},
                                      si=True)
        except SceneError as exc:
            raise FitError(f"trial point {_label(self.keys, theta)} is not a valid scene: "
                           f"{exc}") from None

    def evaluate(self, thetas):
        """SimCurves at each parameter vector (SI), computing the missing ones together."""
        todo = [tuple(map(float, t)) for t in thetas]
        missing = list(dict.fromkeys(t for t in todo if t not in self.cache))
        if missing:
            scenes = [self.scene_at(t) for t in missing]
            if self.workers > 1 and len(missing) > 1:
                outs = list(self._executor().map(simulate, scenes))
            else:
                outs = [simulate(s) for s in scenes]
            self.runs += len(missing)
            for t, (sim, err) in zip(missing, outs):
                if sim is None:
                    raise FitError(f"the femadh run at {_label(self.keys, t)} failed: {err}")
                self.cache[t] = sim
        return [self.cache[t] for t in todo]

    def _executor(self):
        if self._pool is None:
            from concurrent.futures import ProcessPoolExecutor
            import multiprocessing as mp

            from ..studies.sweep import _worker_init

            self._pool = ProcessPoolExecutor(max_workers=self.workers,
                                             mp_context=mp.get_context("spawn"),
                                             initializer=_worker_init)
        return self._pool

    def close(self):
        if self._pool is not None:
            self._pool.shutdown(cancel_futures=True)
            self._pool = None


def _label(keys, theta):
    return ", ".join(f"{k} = {v:.6g}" for k, v in zip(keys, theta))


# --------------------------------------------------------------------------- the fit

def fit_curve(scene, curve, keys, *, workers=1, max_nfev=30, rel_step=1e-3, offset=None,
              progress=None):
    """Fit scene keys and the contact-point offset to a measured curve.

    Parameters
    ----------
    scene : Scene
        A contact scene whose sweep covers the measured range; pin ``[solver] nodes``.
    curve : ForceCurve
    keys : list of str
        1-3 dotted scene keys, each set in the scene (its value is the starting point).
    workers : int
        Processes for the runs (1: in this process).
    max_nfev : int
        Budget of residual evaluations (trial points); each costs a femadh run unless only
        the offset changed, and each Jacobian costs ``len(keys)`` runs more.
    rel_step : float
        Relative finite-difference step of the scene keys.
    offset : float, optional
        Starting offset (m); default: the best offset for the starting scene.
    progress : callable, optional
        Called with a line per residual evaluation.

    Returns
    -------
    FitResult

    Raises
    ------
    SceneError
        A key that is unknown, unset or not numeric.
    FitError
        Budget spent, a run failing, or a parameter the data cannot identify.
    """
    from scipy.optimize import least_squares

    t0 = time.perf_counter()
    theta0 = np.array(check_keys(scene, keys))
    n, p = len(curve), len(keys) + 1
    if n <= p:
        raise FitError(f"{n} measured points cannot determine {p} unknowns "
                       f"({', '.join(keys)}, {OFFSET})")
    ev = Evaluator(scene, keys, workers)
    scale = np.append(theta0, OFFSET_SCALE)
    fscale = float(np.max(np.abs(curve.force))) or 1.0
    q = len(keys)
    speculate = ev.workers >= q + 1
    counts = {"nfev": 0, "njev": 0}
    try:
        sim0, = ev.evaluate([theta0])
        for b in curve.branches():
            if b not in sim0.x:
                raise FitError(f"the curve has {b} points but the scene's sweep has no {b} "
                               "branch: add it to [sweep] directions")
        z_off0 = initial_offset(sim0, curve) if offset is None else float(offset)
        x0 = np.append(np.ones(q), z_off0 / OFFSET_SCALE)

        def thetas(x):
            return x[:q] * scale[:q]

        def stepped(x):
            th = thetas(x)
            return [th + np.eye(q)[k] * rel_step * th[k] for k in range(q)]

        def fun(x):
            counts["nfev"] += 1
            th = thetas(x)
            todo = [th] + (stepped(x) if speculate else [])
            sim = ev.evaluate(todo)[0]
            r = sim.force_at(curve.z, curve.branch, x[q] * OFFSET_SCALE) - curve.force
            if progress:
                progress(f"evaluation {counts['nfev']}: {_label(keys, th)}, {OFFSET} = "
                         f"{x[q] * OFFSET_SCALE:.6g}: rms residual "
                         f"{math.sqrt(float(r @ r) / n):.4g} N ({ev.runs} runs)")
            return r / fscale

        def jac(x):
            counts["njev"] += 1
            th = thetas(x)
            sims = ev.evaluate([th] + stepped(x))
            off = x[q] * OFFSET_SCALE
            base = sims[0].force_at(curve.z, curve.branch, off)
            J = np.empty((n, p))
            for k in range(q):
                # d r / d x_k with x_k = theta_k / theta0_k: the step in x is rel_step x_k
                J[:, k] = (sims[k + 1].force_at(curve.z, curve.branch, off) - base) \
                    / (rel_step * x[k])
                # a point that a fold moved across has the whole jump in its difference, not
                # a derivative (in the mu = 2 LJ scene such a difference was 11x the smooth
                # ones of the same point, and it grows as 1/rel_step): it would shrink the
                # standard errors; such a point carries no slope information for this key
                J[crossed(sims[0], sims[k + 1], off), k] = 0.0
            J[:, q] = sims[0].slope_at(curve.z, curve.branch, off, 1e-3 * OFFSET_SCALE) \
                * OFFSET_SCALE
            return J / fscale

        def crossed(a, b, off):
            """Points between a jump's fold in ``a`` and the same jump's fold in ``b``."""
            d = curve.z - off
            out = np.zeros(n, bool)
            for (ba, xa, _, _), (bb, xb, _, _) in zip(a.jumps, b.jumps):
                if ba == bb:
                    out |= (curve.branch == ba) & (d >= min(xa, xb)) & (d <= max(xa, xb))
            return out

        lb = np.append(np.full(q, 1e-3), -np.inf)
        # tolerances: 1e-7 relative in the unknowns is far below any standard error a
        # measured curve allows, and stops the crawl that the interpolated model's kinks
        # (and the finite-difference noise) cause at scipy's default 1e-8
        sol = least_squares(fun, x0, jac=jac, bounds=(lb, np.inf), method="trf",
                            max_nfev=max_nfev, x_scale=1.0, ftol=1e-7, xtol=1e-7,
                            gtol=1e-8)
        if sol.status == 0:
            r = sol.fun * fscale
            raise FitError(f"no convergence within the budget of {max_nfev} evaluations "
                           f"({ev.runs} femadh runs): last step {counts['nfev']} at "
                           f"{_label(keys, thetas(sol.x))}, {OFFSET} = "
                           f"{sol.x[q] * OFFSET_SCALE:.6g}, rms residual "
                           f"{math.sqrt(float(r @ r) / n):.4g} N; start nearer or raise "
                           "--max-evaluations")
        if sol.status < 0:
            raise FitError(f"least squares stopped: {sol.message}")
        Jx = jac(sol.x) * fscale                 # d r / d x (N per unit of x)
        r = sol.fun * fscale
        values = np.append(thetas(sol.x), sol.x[q] * OFFSET_SCALE)
        allkeys = list(keys) + [OFFSET]
        stderr, corr = _uncertainty(Jx, r, scale, values, allkeys)
        sim = ev.evaluate([thetas(sol.x)])[0]
    finally:
        ev.close()
    rss = float(r @ r)
    return FitResult(allkeys, values, stderr, corr, rss, math.sqrt(rss / n), n, ev.runs,
                     counts["nfev"], counts["njev"], time.perf_counter() - t0, ev.workers,
                     r, sim)


def _uncertainty(J, r, scale, values, keys):
    """Standard errors and correlations from ``s^2 (J^T J)^-1`` (``s^2 = RSS / (n - p)``);
    FitError for a parameter the data cannot identify.

    ``J`` is d r / d x in the solver's unknowns ``x = parameter / scale`` (relative for the
    scene keys, nm for the offset), so that its column norms compare like with like; the
    covariance of the parameters is ``diag(scale) cov_x diag(scale)``."""
    n, p = J.shape
    norms = np.linalg.norm(J, axis=0)
    for k in range(p):
        if not norms[k] > 1e-10 * norms.max():
            raise FitError(f"{keys[k]} cannot be identified from this curve: the simulated "
                           "curve does not change with it over the measured points (zero "
                           "Jacobian column)")
    Jn = J / norms                                  # unit columns: conditioning of shape only
    A = Jn.T @ Jn
    cond = np.linalg.cond(A)
    if not cond < MAX_CONDITION:
        w, v = np.linalg.eigh(A)
        worst = keys[int(np.argmax(np.abs(v[:, 0])))]
        raise FitError(f"{worst} cannot be identified from this curve: J^T J is near-singular "
                       f"(condition number {cond:.3g} > {MAX_CONDITION:.0e}); the data "
                       "cannot separate it from the other unknowns")
    s2 = float(r @ r) / (n - p)
    cov_n = s2 * np.linalg.inv(A)
    cov = cov_n / np.outer(norms, norms) * np.outer(scale, scale)
    stderr = np.sqrt(np.diag(cov))
    corr = cov / np.outer(stderr, stderr)
    for i in range(p):
        for j in range(i + 1, p):
            if abs(corr[i, j]) > MAX_CORRELATION:
                raise FitError(f"{keys[i]} and {keys[j]} cannot be identified separately from "
                               f"this curve: their correlation is {corr[i, j]:+.5f} (beyond "
                               f"+-{MAX_CORRELATION})")
    for k in range(p - 1):                          # the scene keys (the offset has no scale)
        rel = stderr[k] / abs(values[k])
        if rel > MAX_REL_STDERR:
            raise FitError(f"{keys[k]} cannot be identified from this curve: its relative "
                           f"standard error is {rel:.3g} (> {MAX_REL_STDERR:g}); the measured "
                           "range barely depends on it")
    return stderr, corr
