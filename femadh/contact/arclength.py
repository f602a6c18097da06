"""Pseudo-arclength continuation of smooth surface problems: folds are traced, not jumped.

For a problem without the sigma-gap (every effect a smooth law of the gap, e.g. a smooth LJ
sphere, or Greenwood-Williamson asperity pressures) the equilibria form a curve in (w, d),

    F(w, d) = K w - P(b(d) - w) = 0,        b(d) = d + shape(r)   (paper 1 eqs 5-6),

which turns back in d at every jump-in and jump-out (a fold: dd/ds = 0 and one eigenvalue of
the Hessian crosses zero). Parametrising by the separation d, as :func:`trace` does, a fold is
found only as the place where the branch stops; here the curve is followed by its arclength s
with Keller's bordered system

    [ K + diag(P')   -P' ] [dw]   [ -F ]
    [ omega t_w^T    t_d ] [dd] = [ -N ],   N = t . (x - x_pred),

which stays regular through simple folds, so the unstable branch between them is traced too and
each fold is located as the root of t_d (Brent's method on the step length). Lengths are
scaled by ``scale`` (e.g. z0) and the displacement part of the norm is the nodal mean square
(omega = 1/N), so one unit of s is one ``scale`` of separation or of typical displacement.

The displacement-controlled approach and retract paths follow from the curve: each path walks
the stable segments and, at a fold, jumps at fixed d to the next stable segment that exists at
that d (:meth:`EquilibriumCurve.walk`, :meth:`EquilibriumCurve.branch`).

Linear algebra: the bordered matrix changes little from step to step, so one LU factorisation
preconditions (right-preconditioned GMRES, dense O(N^2) mat-vecs) the solves of many steps and
is refreshed only when GMRES slows down; most steps then cost O(N^2), not O(N^3).
"""
import math
import time

import numpy as np
from scipy import linalg
from scipy.linalg import lapack

from ..errors import ConvergenceError
from ..interrupt import check as safe_point
from .curve import CurvePoint, EquilibriumCurve, Fold, bracketed_root
from .stability import is_positive_definite

#: Newton iterations allowed per corrector
MAX_ITER = 15
#: a corrector whose residual stalls (falls by less than half per iteration) within this
#: factor of the tolerance has reached the rounding floor: converged
ROUNDING_SLACK = 10.0
#: relative accuracy of a Newton step's linear solve (inexact Newton: ample for convergence)
NEWTON_RTOL = 1e-4
#: GMRES iterations before the preconditioning factorisation is refreshed (small grids); on
#: larger ones an O(N^3) refresh costs ~N/3 O(N^2) mat-vecs, so up to N/GMRES_PER_NODE
#: iterations are allowed (the Jacobian changes only near the moving contact edge: a
#: low-rank change that GMRES absorbs in a few iterations per changed node)
GMRES_MAX = 8
GMRES_PER_NODE = 25
#: below this many nodes each linear solve factorises afresh: an LU costs 0.1 ms at N = 130
#: and 0.5 ms at 260 (one BLAS thread, measured); preconditioned GMRES needs ~6-10
#: iterations per solve here, and traces at N = 232-290 took the same time either way
DIRECT_MAX_N = 250
#: with direct solves the stability is verified by the Hessian every this many points
HESSIAN_EVERY = 8
#: a grid exchange (regrid) carries the state over at fixed d where |dd/ds| exceeds this
#: (well posed away from folds); closer to a fold, where the problem at fixed d turns
#: singular, on the hyperplane through the interpolated state normal to the interpolated
#: tangent (the bordered system stays regular there), so the grid can follow the contact
#: edge through folds: on the JKR side the edge travels ~0.05 z0 R / ell (mu = 20: ~200 ell)
#: while |dd/ds| < 0.05
REGRID_MIN_TD = 0.05
#: the step length is tuned so that the corrector moves no gap by more than about this
#: fraction of itself away from the prediction (the predictor error grows like step^2)
TARGET_CORRECTION = 0.05
#: after a corrector failure the step stays below this fraction of the failed one, a ceiling
#: that then rises by CEILING_GROWTH per accepted point
BASIN_MARGIN = 0.8
CEILING_GROWTH = 1.05
#: the predictor may change no gap by more than this fraction of itself (resolves the law)
MAX_GAP_CHANGE = 0.3
#: the smallest step length, relative to the first one, before the trace gives up
MIN_STEP_FRACTION = 1e-6
#: largest fraction of its gap one corrector step may close (LJ repulsion grows like h^-9)
CORRECTOR_GAP_CLOSURE = 0.3
#: consecutive unit tangents must be within acos(MIN_TANGENT_COS) = 30 degrees
MIN_TANGENT_COS = math.cos(math.radians(30.0))
#: corrector attempts (each after halving the step) allowed for one new point; a healthy
#: trace needs a few, a fold a dozen (halving 1 -> 1e-3); more means the corrector and the
#: tangent disagree (e.g. a law whose derivative is inconsistent with its value)
MAX_ATTEMPTS_PER_POINT = 40


class _Bordered:
    """Linear solves with the bordered Jacobian of one state, cheaply, along the whole curve.

    An LU factorisation of the bordered matrix at some earlier state preconditions GMRES on the
    exact current matrix (applied as dense mat-vecs, O(N^2)). Along a curve the Jacobian changes
    slowly, so a factorisation serves many points; it is refreshed (O(N^3)) only when GMRES
    needs more than ``krylov_max`` iterations. Below DIRECT_MAX_N nodes every solve factorises
    afresh (cheaper there than the Krylov iterations). ``n_factor`` counts factorisations.
    """

    def __init__(self, problem, omega):
        self.problem, self.omega = problem, omega
        self.n = problem.grid.n
        # the border row is scaled like a row of K (Pa/m) so the matrix is well balanced
        self.kappa = float(np.mean(np.diag(problem.K)))
        self.lu = None
        self.n_factor = 0
        self.n_krylov = 0
        self.krylov_max = max(GMRES_MAX, self.n // GMRES_PER_NODE)
        self.direct = self.n < DIRECT_MAX_N

    def matrix(self, D, t):
        n, K = self.n, self.problem.K
        M = np.empty((n + 1, n + 1))
        M[:n, :n] = K
        M[np.arange(n), np.arange(n)] += D
        M[:n, n] = -D
        M[n, :n] = self.kappa * self.omega * t[:n]
        M[n, n] = self.kappa * t[n]
        return M

    def solve(self, D, t, rhs, rtol, atol=0.0):
        """x with M(D, t) x = rhs, M = [[K + diag D, -D], [kappa omega t_w, kappa t_d]],
        to rtol * |rhs| or atol (residual units: Pa), whichever is larger."""
        if self.lu is not None and not self.direct:
            n, K = self.n, self.problem.K
            kt = self.kappa * self.omega * t[:n]
            ktd = self.kappa * t[n]

            def mv(x):
                y = np.empty(n + 1)
                y[:n] = K @ x[:n] + D * (x[:n] - x[n])
                y[n] = kt @ x[:n] + ktd * x[n]
                return y
            x, its = _gmres(mv, self._lu_solve, rhs, max(rtol * _norm(rhs), atol),
                            self.krylov_max)
            self.n_krylov += its
            if x is not None:
                return x
        lu, piv, info = lapack.dgetrf(self.matrix(D, t), overwrite_a=True)
        if info > 0:
            raise ConvergenceError("bordered Jacobian is singular", residual=math.nan,
                                   n_iter=0)
        self.lu = (lu, piv)
        self.n_factor += 1
        return self._lu_solve(rhs)

    def _lu_solve(self, y):
        return lapack.dgetrs(*self.lu, y)[0]


def _norm(x):
    return math.sqrt(float(x @ x))


def _gmres(mv, pre, b, tol, m):
    """Right-preconditioned GMRES from x = 0, no restart: x with |b - A x| <= tol (the true
    residual, in b's units), A x = mv(x), preconditioner pre(y) ~ A^-1 y.

    Returns (x, iterations), x None if m iterations do not reach tol (or break down). A
    lean version of scipy's gmres: on a few hundred unknowns its per-call overhead (~0.3 ms)
    exceeded the iterations' own cost.
    """
    beta = _norm(b)
    if beta <= tol:
        return np.zeros_like(b), 0
    V = np.empty((m + 1, b.size))
    Z = np.empty((m, b.size))
    H = np.zeros((m + 1, m))
    cs, sn = np.zeros(m), np.zeros(m)
    g = np.zeros(m + 1)
    g[0] = beta
    V[0] = b / beta
    for j in range(m):
        Z[j] = pre(V[j])
        w = mv(Z[j])
        for _ in range(2):       # classical Gram-Schmidt, twice (as stable as modified)
            h = V[:j + 1] @ w
            w -= h @ V[:j + 1]
            H[:j + 1, j] += h
        H[j + 1, j] = h_next = _norm(w)
        for i in range(j):       # previous Givens rotations on the new column
            H[i, j], H[i + 1, j] = (cs[i] * H[i, j] + sn[i] * H[i + 1, j],
                                    -sn[i] * H[i, j] + cs[i] * H[i + 1, j])
        r = math.hypot(H[j, j], H[j + 1, j])
        if not r > 0 or not np.isfinite(r):
            return None, j + 1
        cs[j], sn[j] = H[j, j] / r, H[j + 1, j] / r
        H[j, j], H[j + 1, j] = r, 0.0
        g[j + 1] = -sn[j] * g[j]
        g[j] *= cs[j]
        if abs(g[j + 1]) <= tol or j == m - 1:
            y = linalg.solve_triangular(H[:j + 1, :j + 1], g[:j + 1], check_finite=False)
            x = y @ Z[:j + 1]
            if abs(g[j + 1]) <= tol and np.all(np.isfinite(x)):
                return x, j + 1
            return None, j + 1
        V[j + 1] = w / h_next
    return None, m


class _Tracer:
    """Predictor-corrector machinery shared by the trace and the fold location."""

    def __init__(self, problem, scale, tol, curve):
        problem.require_collocated("the arclength tracer")
        self.problem, self.scale, self.tol, self.curve = problem, scale, tol, curve
        self.n = problem.grid.n
        self.omega = 1.0 / self.n
        self.lin = _Bordered(problem, self.omega)
        self.seg = None

    def register(self):
        """Make this grid the curve's next segment."""
        self.seg = len(self.curve.tracers)
        self.curve.tracers.append(self)
        return self

    def tangent(self, w, d, t_prev):
        """Unit tangent (scaled: w/scale, d/scale) at an equilibrium, oriented along t_prev."""
        D = self.problem.dpressure(self.problem.contour(d) - w)
        rhs = np.zeros(self.n + 1)
        rhs[-1] = self.lin.kappa
        t = self.lin.solve(D, t_prev, rhs, 1e-8)
        return t / math.sqrt(self.omega * (t[:-1] @ t[:-1]) + t[-1] ** 2)

    def correct(self, x_pred, t):
        """Newton on F = 0 and the hyperplane t.(x - x_pred) = 0. Returns (x, it, res, ok)."""
        problem, n, scale, omega = self.problem, self.n, self.scale, self.omega
        self.curve.n_solves += 1
        x = x_pred.copy()
        res = res_first = res_prev = math.inf
        for it in range(1, MAX_ITER + 1):
            safe_point()        # a signal stops the trace between corrector iterations
            w, d = x[:n] * scale, x[n] * scale
            h = problem.contour(d) - w
            if np.any(h <= 0):
                return x, it, math.inf, False
            P = problem.pressure(h)
            res = float(np.max(np.abs(w - problem.C @ P)))   # residual of eq (6), m
            plane = omega * (t[:n] @ (x[:n] - x_pred[:n])) + t[n] * (x[n] - x_pred[n])
            if abs(plane) < 1e-10 and (res <= self.tol or (
                    res <= ROUNDING_SLACK * self.tol and res > 0.5 * res_prev)):
                # (the second: stalled within ROUNDING_SLACK of tol, the floor of the
                # residual's rounding: measured ~1e-19 m at mu = 13, N = 600)
                return x, it, res, True
            if it == 1:
                res_first = res
            elif res > 4 * res_first or (it >= 8 and res > 1e-3 * res_first):
                return x, it, res, False  # diverging or crawling: a shorter step does better
            res_prev = res
            rhs = np.concatenate([P - problem.K @ w, [-self.lin.kappa * plane * scale]])
            # (dw, dd) in m; the step need not be more accurate than a fraction of tol (the
            # residual near convergence is rounding noise a relative criterion cannot meet)
            dx = self.lin.solve(problem.dpressure(h), t, rhs, NEWTON_RTOL,
                                atol=0.01 * self.tol * self.lin.kappa)
            closing = dx[:n] - dx[n]
            alpha = 1.0
            if np.any(closing > 0):
                alpha = min(1.0, float(np.min(CORRECTOR_GAP_CLOSURE * h[closing > 0]
                                              / closing[closing > 0])))
            x = x + alpha * dx / scale
        return x, MAX_ITER, res, False


def _residual(problem, w, d):
    """max |w - C P(h)| (m): the residual of eq (6)."""
    return float(np.max(np.abs(w - problem.C @ problem.pressure(problem.contour(d) - w))))


def _hessian_stable(problem, w, d):
    return is_positive_definite(problem.energy_hessian(problem.contour(d) - w))


def _negative_modes(problem, w, d):
    """Negative eigenvalues of the energy Hessian at a fold state other than the one closest
    to zero (the mode that crosses zero there)."""
    ev = linalg.eigvalsh(problem.energy_hessian(problem.contour(d) - w), check_finite=False)
    return int(np.sum(ev < 0) - (ev[np.argmin(np.abs(ev))] < 0))


def trace_curve(problem, d_start, d_end, *, tol, scale, ds, ds_max=None, w_start=None,
                max_points=5000, progress=None, regrid=None, stop=None, on_point=None,
                target_correction=TARGET_CORRECTION):
    """Follow the equilibrium curve from separation d_start until it passes d_end (m).

    Parameters
    ----------
    problem : ContactProblem
        A problem without the sigma-gap (``problem.gap is None``).
    d_start, d_end : float
        Separations (m) where the curve starts (solved there first) and where it ends.
    tol : float
        Residual of eq (6) every point meets (m) (up to ROUNDING_SLACK times it where the
        residual stalls at its rounding floor).
    scale : float
        Length (m) of one unit of arclength (e.g. z0).
    ds : float
        First step length (units of ``scale``); adapted afterwards.
    ds_max : float, optional
        Largest step length (default: 20 * ds).
    target_correction : float, optional
        The step length is tuned so that the corrector moves no gap by more than about this
        fraction of itself (default TARGET_CORRECTION; a predictor 4x further off is
        rejected). Where only the folds, landings and extrema of the curve are read (each
        located on the curve itself, not interpolated between points) a larger value takes
        fewer points.
    progress : callable(float), optional
        Called with the fraction of |d_end - d_start| covered so far.
    regrid : callable(problem, w, d) -> ContactProblem or None, optional
        Asked after each accepted point for a grid that suits the state better (e.g. fine
        around the contact edge, which has moved); the state is interpolated to the new grid,
        solved again (at the same d, or near a fold on the tangent's normal hyperplane: see
        :func:`_carry_over`), and the trace goes on there (a new segment of the curve:
        :attr:`CurvePoint.seg`; ``on_point`` sees the carried-over point too). None keeps
        the grid; a refused exchange is recorded in ``curve.refused``.
    stop : callable(EquilibriumCurve) -> bool, optional
        Asked after each accepted point; True ends the trace there (before d_end).
    on_point : callable(int, CurvePoint), optional
        Called with each point as it is accepted (streams it to disk; may raise to stop).

    Notes
    -----
    Stability (positive-definite energy Hessian) changes exactly where one eigenvalue crosses
    zero, i.e. at folds of a gradient system's curve; it is carried from point to point by fold
    parity and verified by a Cholesky factorisation at the first point and whenever the
    preconditioner is refreshed away from a fold. A disagreement (a bifurcation, or two
    folds inside one step) stops the trace with a ConvergenceError.

    Raises
    ------
    ConvergenceError
        If the step length collapses (the corrector fails at every step size), the stability
        check disagrees with the fold count, or the curve needs more than ``max_points``
        points; the partial curve is attached as ``.curve``.
    """
    from .complementarity import solve_complementarity

    if problem.gap is not None:
        raise ValueError("arclength continuation needs a problem without the sigma-gap")
    t0 = time.perf_counter()
    n = problem.grid.n
    ds_max = 20 * ds if ds_max is None else ds_max
    direction = math.copysign(1.0, d_end - d_start)
    curve = EquilibriumCurve()
    tr = _Tracer(problem, scale, tol, curve).register()
    w0 = np.zeros(n) if w_start is None else np.asarray(w_start, float)
    st = solve_complementarity(problem, d_start, w0, tol=tol, max_iter=60)
    curve.n_solves += 1
    if not st.converged:
        raise ConvergenceError("arclength start: Newton did not converge", d=d_start,
                               residual=st.residual, n_iter=st.n_iter)
    t_init = np.zeros(n + 1)
    t_init[n] = direction
    t = tr.tangent(st.w, d_start, t_init)
    curve.points.append(CurvePoint(d_start, st.w.copy(), t, _hessian_stable(problem, st.w,
                                                                             d_start),
                                   st.n_iter, st.residual))
    if on_point:
        on_point(0, curve.points[0])
    step, ds_min = ds, ds * MIN_STEP_FRACTION
    ceiling = math.inf      # step length below the last one whose corrector failed
    weights = np.r_[np.full(n, tr.omega), 1.0]

    def fail(msg, d, res, it):
        exc = ConvergenceError(msg, d=d, residual=res, n_iter=it)
        exc.curve = curve
        curve.wall_time = time.perf_counter() - t0
        return exc

    check_next = False
    stopped = False
    attempts = 0

    def shorten(reason, d, res, it):
        """Halve the step after a rejected attempt; give up at the smallest step or after
        MAX_ATTEMPTS_PER_POINT attempts for one point (each is a corrector solve)."""
        nonlocal step
        if step <= ds_min * 1.0001 or attempts >= MAX_ATTEMPTS_PER_POINT:
            why = ("at the smallest step" if step <= ds_min * 1.0001 else
                   f"after {attempts} attempts at shorter steps")
            raise fail(f"arclength continuation stalled after d = {p.d * 1e9:.6g} nm "
                       f"({len(curve.points)} points): {reason} {why}", d, res, it)
        step *= 0.5

    while True:
        p = curve.points[-1]
        x = np.concatenate([p.w, [p.d]]) / scale
        h = problem.contour(p.d) - p.w
        dh_ds = (p.t[n] - p.t[:n]) * scale           # gap change per unit s (m)
        fast = np.abs(dh_ds) > 0
        if np.any(fast):   # predictor changes no gap by more than MAX_GAP_CHANGE of itself
            step = min(step, float(np.min(MAX_GAP_CHANGE * h[fast] / np.abs(dh_ds[fast]))))
        step = max(step, ds_min)
        x_pred = x + step * p.t
        factors = tr.lin.n_factor
        attempts += 1
        xc, it, res, ok = tr.correct(x_pred, p.t)
        if not ok:
            # remember where Newton's basin ended: growing right back into it wastes a
            # corrector (measured at mu = 7: 449 failures for 762 points)
            ceiling = BASIN_MARGIN * step
            shorten("the corrector did not converge", x_pred[n] * scale, res, it)
            continue
        w, d = xc[:n] * scale, xc[n] * scale
        t = tr.tangent(w, d, p.t)
        if t @ (p.t * weights) < MIN_TANGENT_COS:
            # the tangent turned too far within one step: the curve bends faster than the
            # step resolves (near folds and cusps); a shorter step follows it
            shorten("the tangent turned by more than 30 degrees", d, res, it)
            continue
        if (d - p.d) * p.t_d < 0 and p.t_d * t[n] > 0:
            # d moved against both end tangents: two folds inside the step (a narrow loop
            # near the onset of bistability) - resolve them instead of stepping over
            shorten("two folds inside one step", d, res, it)
            continue
        h_c = problem.contour(d) - w
        h_p = problem.contour(x_pred[n] * scale) - x_pred[:n] * scale
        corr = float(np.max(np.abs(h_c - h_p) / h_c))
        if corr > 4 * target_correction:
            # the predictor was poor: the point may sit on another branch
            shorten(f"the corrector moved a gap by {corr:.2g} of itself", d, res, it)
            continue
        folded = p.t_d * t[n] < 0
        stable = p.stable != folded
        fold = _locate_fold(tr, p, step, len(curve.points) - 1) if folded else None
        if stable and folded and _negative_modes(problem, fold.w, fold.d) > 0:
            # the mode crossing zero at this fold was not the only negative one: the curve
            # passes from one unstable branch to another (index 1 -> 2; measured at mu = 5-20
            # after the jump-in, a second mode turns negative), not back to a stable one
            stable = False
        # (checked when GMRES needed a fresh factorisation, or every HESSIAN_EVERY points
        # with direct solves; not next to a fold: there the symmetric energy Hessian and the
        # collocation Jacobian, whose singularity defines the fold, turn singular at slightly
        # different points, an O(h) asymmetry of the discretisation)
        due = (len(curve.points) % HESSIAN_EVERY == 0 if tr.lin.direct
               else tr.lin.n_factor != factors)
        if due and not (folded or check_next):
            if _hessian_stable(problem, w, d) != stable:
                # likely two folds inside the step (resolve them); at the smallest step a
                # bifurcation, which this continuation does not follow
                shorten(f"stability changed without a fold of the curve between d = "
                        f"{p.d * 1e9:.6g} and {d * 1e9:.6g} nm (a bifurcation?)", d, res, it)
                continue
        check_next = folded
        attempts = 0
        q = CurvePoint(d, w, t, stable, it, res, tr.seg)
        if folded:
            fold.seg = tr.seg
            curve.folds.append(fold)
        curve.points.append(q)
        step = min(ds_max, ceiling, step * min(2.0, max(0.5, math.sqrt(
            target_correction / max(corr, 1e-12)))))
        ceiling *= CEILING_GROWTH
        if progress:
            progress(min(1.0, (d - d_start) / (d_end - d_start)))
        if direction * (d - d_end) >= 0:
            break           # (the last point is recomputed at d_end before it is streamed)
        if on_point:
            on_point(len(curve.points) - 1, q)
        if stop is not None and stop(curve):
            stopped = True
            break
        if len(curve.points) >= max_points:
            raise fail(f"arclength continuation needed more than {max_points} points",
                       d, res, it)
        if regrid is not None:
            new = regrid(problem, w, d)
            moved = None if new is None else _carry_over(new, q, tr, scale, tol, curve)
            if moved is not None:
                tr, problem, n = moved[0], new, new.grid.n
                weights = np.r_[np.full(n, tr.omega), 1.0]
                curve.points.append(moved[1])
                if on_point:
                    on_point(len(curve.points) - 1, moved[1])
                check_next = False
    curve.n_factor = sum(x.lin.n_factor for x in curve.tracers)
    curve.n_krylov = sum(x.lin.n_krylov for x in curve.tracers)
    if stopped:
        curve.wall_time = time.perf_counter() - t0
        return curve
    # the last point exactly on d_end, recomputed on the curve inside the last step
    b = curve.points[-1]
    if b.d != d_end:
        try:
            w = curve.point_at(len(curve.points) - 2, d_end)
        except ConvergenceError as exc:
            raise fail(f"arclength end point: {exc}", d_end, math.nan, 0) from None
        curve.points[-1] = CurvePoint(d_end, w, tr.tangent(w, d_end, b.t), b.stable, b.n_iter,
                                      _residual(problem, w, d_end), b.seg)
    if on_point and len(curve.points) > 1:
        on_point(len(curve.points) - 1, curve.points[-1])
    curve.wall_time = time.perf_counter() - t0
    return curve


def _carry_over(problem, q, tr, scale, tol, curve):
    """Point q (on tracer tr's grid) carried to ``problem``'s grid.

    w and the tangent are interpolated in r and the state is solved again on the new grid:
    at the same d away from folds (|dd/ds| >= REGRID_MIN_TD; the seam is then at one d), else
    on the hyperplane through the interpolated state normal to the interpolated tangent (at
    a fold the problem at fixed d is singular, the bordered one is not; d moves by the grids'
    difference times |dd/ds|). The new state must lie on the same side of every fold as q
    (dd/ds of the same sign) and, away from folds, have q's stability by the Hessian.

    Returns (new tracer, new CurvePoint), or None (the old grid is kept; the reason is
    appended to ``curve.refused``).
    """
    r_old, r_new = tr.problem.grid.nodes, problem.grid.nodes
    n = problem.grid.n
    w = np.interp(r_new, r_old, q.w)
    t_old = np.r_[np.interp(r_new, r_old, q.t[:-1]), q.t[-1]]
    near_fold = abs(q.t_d) < REGRID_MIN_TD
    if near_fold:
        normal = t_old
    else:
        normal = np.zeros(n + 1)
        normal[n] = 1.0
    new = _Tracer(problem, scale, tol, curve)
    xc, it, res, ok = new.correct(np.r_[w, q.d] / scale, normal)
    if not ok:
        curve.refused.append((q.d, f"corrector: residual {res:.3g} m after {it} iterations"))
        return None
    w, d = xc[:n] * scale, xc[n] * scale
    t = new.tangent(w, d, t_old)
    if t[-1] * q.t_d < 0:
        curve.refused.append((q.d, f"a fold between the grids (dd/ds {q.t_d:.3g} -> "
                                   f"{t[-1]:.3g})"))
        return None
    if not near_fold and _hessian_stable(problem, w, d) != q.stable:
        curve.refused.append((q.d, "stability differs on the new grid"))
        return None
    new.register()
    return new, CurvePoint(d, w, t, q.stable, it, res, new.seg)


def _locate_fold(tr, p, step, index):
    """The fold between point p and the point one ``step`` further: root of t_d(s) on
    corrected points (t_d changes sign across it), located to 1e-12 of the step."""
    n, scale = tr.n, tr.scale
    x = np.concatenate([p.w, [p.d]]) / scale
    known = {0.0: (p.t_d, p.w, p.d)}

    def t_d(s):
        if s not in known:
            xc, _, _, ok = tr.correct(x + s * p.t, p.t)
            if not ok:
                raise _OffCurve
            w, d = xc[:n] * scale, xc[n] * scale
            known[s] = (tr.tangent(w, d, p.t)[-1], w, d)
        return known[s][0]
    try:
        s = bracketed_root(t_d, 0.0, step, xtol=1e-12 * step)
    except _OffCurve:   # the corrector failed inside the step: the best point found so far
        s = min(known, key=lambda k: abs(known[k][0]))
    _, w, d = known[s]
    return Fold(index, d, w, s)


class _OffCurve(Exception):
    """The corrector did not converge at a requested arclength offset."""
