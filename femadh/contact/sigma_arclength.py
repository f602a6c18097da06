"""Pseudo-arclength continuation of the sigma-gap complementarity problem through its folds.

With the sigma-gap (paper 1 eq 8 as h >= sigma, p_c >= 0, (h - sigma) p_c = 0) the equilibria
of K w = P(h) - p_c, h = b(d) - w, form a *piecewise* smooth curve in (w, d): on each piece the
active set A (nodes held at h = sigma) is fixed, w_A = b_A(d) - sigma, and the free nodes I obey
the smooth equations

    F_I(w_I, d) = (K w)_I - P(h_I) = 0          (paper 1 eqs 5-8),

whose Jacobian is [K_II + diag(P'_I),  K_IA 1 - P'_I] (dh/dd = 1). A piece ends where a
constraint of the complementarity becomes active (an *event*): a free gap reaching sigma
(h_j - sigma = 0, node j joins A) or an asperity pressure vanishing (lambda_j = p_c,j + P_LJa
= P(sigma) + P_LJa - (K w)_j = 0, node j leaves A). Both are *linear* in (w_I, d), so the event
state is found by Newton on the piece's equations bordered by that linear condition, exactly
(no bisection). The curve goes on along the neighbouring piece (A +- j) in the one direction
that keeps the complementarity: the new multiplier lambda_j grows (activation) or the new gap
h_j - sigma opens (release); the piece whose tangent reverses d there is a *corner fold*, the
discrete contact's jump-out (each node of the JKR-side unstable branch is one piece).

Inside a piece the curve is followed with Keller's bordered system, as for smooth laws
(:mod:`femadh.contact.arclength`): the border row is the pseudo-arclength condition
t . (x - x_pred) = 0 in the scaled norm omega |dw|^2 + dd^2 (omega = 1/N over *all* nodes, the
active ones moving with d), and a smooth fold (jump-in of the free surface) is located as the
root of dd/ds by Brent's method. Each bordered system (size n_I + 1) is factorised directly:
it stays regular through folds where the reduced Jacobian alone turns singular.

The result is an :class:`~femadh.contact.curve.EquilibriumCurve` whose segments
(``curve.tracers``) are the pieces: an event state is stored twice, as the last point of the
old piece and the first of the new one (a zero-length seam, the same equilibrium on two active
sets), so that the curve's walk, branch, point_at and maximize work unchanged. Stability of
each point: the inertia of the energy Hessian on its free nodes
(:func:`femadh.contact.stability.is_stable`), as the stepping solver decides it.
"""
import math
import time

import numpy as np
from scipy.linalg import lapack

from ..errors import ConvergenceError
from ..interrupt import check as safe_point
from .curve import CurvePoint, EquilibriumCurve, Fold, bracketed_root
from .linalg import disk_size
from .stability import is_stable
from .state import State

#: Newton iterations allowed per corrector
MAX_ITER = 25
#: largest fraction of its gap above sigma... of itself one corrector step may close (the
#: LJ repulsion below sigma is never met: the gap is bounded by sigma, but the free surface
#: must not be pushed through it in one step)
GAP_CLOSURE = 0.5
#: the predictor may change no free gap by more than this fraction of itself
MAX_GAP_CHANGE = 0.3
#: the step length is tuned so that the corrector moves no gap by more than about this
#: fraction of itself away from the prediction (as in arclength.py)
TARGET_CORRECTION = 0.05
#: consecutive unit tangents on one piece must be within acos(MIN_TANGENT_COS) = 30 degrees
MIN_TANGENT_COS = math.cos(math.radians(30.0))
#: smallest step length relative to the first one before the trace gives up
MIN_STEP_FRACTION = 1e-7
#: corrector attempts for one new point before the trace gives up (a fold needs a dozen)
MAX_ATTEMPTS_PER_POINT = 40
#: events at one and the same state in a row (several nodes at their constraint at once);
#: more means the active set cycles
MAX_EVENTS_AT_ONE_STATE = 8
#: the energy Hessian's inertia is computed at every this many points and next to every
#: fold; between, stability is carried by fold parity (it changes exactly where d turns
#: back, smoothly or at an event: measured on the Fig 3/4 scenes at every point, 14 of 14
#: changes at folds, none elsewhere); a computed value always overrides the carried one
HESSIAN_EVERY = 8
#: a constraint counts as met when violated by less than this many times the tolerance
#: (gap: tol in m; multiplier: tol times the mean diagonal stiffness, Pa)
SLACK = 10.0


class _Piece:
    """The smooth piece of the curve with active set ``active``: corrector and tangent.

    Provides what :class:`EquilibriumCurve` asks of a segment's tracer: ``problem``,
    ``scale``, ``omega`` and ``correct(x_pred, t)`` (x = (w, d) / scale, all nodes).
    Matrices are built per solve (not stored: a curve has hundreds of pieces).
    """

    def __init__(self, problem, active, scale, tol, curve):
        problem.require_collocated("the sigma-gap arclength tracer")
        self.problem, self.scale, self.tol, self.curve = problem, scale, tol, curve
        self.active = np.asarray(active, bool).copy()
        self.I = np.flatnonzero(~self.active)
        self.A = np.flatnonzero(self.active)
        self.n = problem.grid.n
        self.omega = 1.0 / self.n
        self.sigma = problem.sigma
        # border rows scaled like a row of K (Pa/m): a well balanced bordered matrix
        self.kappa = float(np.mean(np.diag(problem.K)))
        adh = problem.gap.adhesion if problem.gap is not None else 0.0
        # lambda_j = P(sigma) + P_LJa - (K w)_j on a contact node (Pa)
        self.lam0 = float(problem.pressure(np.array([self.sigma]))[0]) + adh
        self.seg = None
        # the active set of a sphere-flat contact is a disk, nodes 0..m-1: the free blocks
        # of K and C are then slices (views), not copies (m None: general index arrays)
        m = disk_size(self.active)
        self.free = slice(m, None) if m is not None else self.I
        self._KIA1 = None
        self.lu = None          # (lu, piv, w, d): the last bordered factorisation

    def register(self):
        self.seg = len(self.curve.tracers)
        self.curve.tracers.append(self)
        return self

    # -- state algebra -------------------------------------------------------------------
    def full_w(self, w_I, d):
        """All nodes' w (m) from the free ones and d: w_A = b_A(d) - sigma (eq 8 held)."""
        w = np.empty(self.n)
        w[self.I] = w_I
        w[self.A] = self.problem.contour(d)[self.A] - self.sigma
        return w

    def multipliers(self, w):
        """lambda = p_c + P_LJa (Pa) on the active nodes (>= 0 where they hold)."""
        return self.lam0 - self.problem.K[self.A] @ w

    def _rows(self, M):
        """Rows of the free nodes of a matrix (a view for a disk active set)."""
        return M[self.free]

    def _jacobian(self, h):
        """[K_II + diag(D_I) | K_IA 1 - D_I] (Pa/m), D = P'(h)."""
        K, I, f = self.problem.K, self.I, self.free
        D = self.problem.dpressure(h[f])
        if self._KIA1 is None:
            self._KIA1 = K[np.ix_(I, self.A)].sum(axis=1)
        J = np.empty((I.size, I.size + 1))
        J[:, :-1] = K[f, f] if isinstance(f, slice) else K[np.ix_(I, I)]
        J[np.arange(I.size), np.arange(I.size)] += D
        J[:, -1] = self._KIA1 - D
        return J

    def _plane_row(self, t):
        """The pseudo-arclength row in (w_I, d) (scaled by kappa): omega t_w.dw + t_d dd with
        dw_A = dd (the active nodes move with the sphere)."""
        row = np.empty(self.I.size + 1)
        row[:-1] = self.kappa * self.omega * t[:-1][self.I]
        row[-1] = self.kappa * (self.omega * t[:-1][self.A].sum() + t[-1])
        return row

    def residual(self, w, d):
        """max |w - C (P - p_c)| (m), the residual of eq (6)/(10): C applied to the free
        nodes' imbalance (p_c on A absorbs theirs)."""
        h = self.problem.contour(d) - w
        F = self._rows(self.problem.K) @ w - self.problem.pressure(h[self.free])
        return float(np.max(np.abs(self.problem.C[:, self.free] @ F))) if self.I.size else 0.0

    # -- Newton on the bordered system ----------------------------------------------------
    def _newton(self, w, d, border):
        """Newton from (w, d) on F_I = 0 and one linear condition border(w, d) = (row, value)
        (row in (w_I, d), value the condition's current value in the row's units).

        Returns (w, d, iterations, residual m, converged)."""
        problem, I, f = self.problem, self.I, self.free
        self.curve.n_solves += 1
        self.lu = None
        res_first = math.inf
        res = math.inf
        for it in range(1, MAX_ITER + 1):
            safe_point()        # a signal stops the trace between corrector iterations
            h = problem.contour(d) - w
            if np.any(h[f] <= 0):
                return w, d, it, math.inf, False
            P_I = problem.pressure(h[f])
            F = self._rows(problem.K) @ w - P_I
            row, value = border(w, d)
            res = float(np.max(np.abs(problem.C[:, f] @ F))) if I.size else 0.0
            if not math.isfinite(res):
                raise ConvergenceError("sigma-gap arclength corrector: non-finite residual",
                                       d=d, residual=res, n_iter=it)
            if res <= self.tol and abs(value) <= 1e-10 * self.kappa * self.scale:
                return w, d, it, res, True
            if it == 1:
                res_first = max(res, self.tol)
            elif res > 4 * res_first or (it >= 10 and res > 1e-3 * res_first):
                return w, d, it, res, False        # diverging or crawling: shorter step
            M = np.empty((I.size + 1, I.size + 1))
            M[:-1] = self._jacobian(h)
            M[-1] = row
            lu, piv, info = lapack.dgetrf(M, overwrite_a=True)
            self.curve.n_factor += 1
            if info > 0:
                return w, d, it, res, False
            self.lu = (lu, piv)
            dx = -lapack.dgetrs(lu, piv, np.r_[F, value])[0]
            dw_I, dd = dx[:-1], dx[-1]
            closing = dw_I - dd                    # a free gap's decrease
            alpha = 1.0
            if np.any(closing > 0):
                hI = h[f] - self.sigma
                c = closing > 0
                alpha = min(1.0, float(np.min(GAP_CLOSURE * np.maximum(hI[c], 0.0)
                                              / closing[c]))) if np.all(hI[c] > 0) else 1.0
                alpha = max(alpha, 1e-3)
            d = d + alpha * dd
            w = self.full_w(w[I] + alpha * dw_I, d)
        return w, d, MAX_ITER, res, False

    def correct(self, x_pred, t):
        """Point on this piece on the hyperplane through x_pred normal to t (scaled units).
        Returns (x, iterations, residual, ok), x = (w, d) / scale."""
        s = self.scale
        w0, d0 = x_pred[:-1] * s, x_pred[-1] * s
        row = self._plane_row(t)

        def plane(w, d):
            val = self.kappa * (self.omega * (t[:-1] @ (w - w0)) + t[-1] * (d - d0))
            return row, val
        w, d, it, res, ok = self._newton(self.full_w(w0[self.I], d0), d0, plane)
        return np.r_[w, d] / s, it, res, ok

    def correct_event(self, w0, d0, event):
        """The state of this piece where ``event`` = (kind, j) holds: kind "gap" (free node j
        at h_j = sigma), "lambda" (contact node j with lambda_j = 0) or "d" (d = j)."""
        kind, j = event
        n_I = self.I.size
        if kind == "gap":
            k = int(np.searchsorted(self.I, j))
            row = np.zeros(n_I + 1)
            row[k], row[-1] = -self.kappa, self.kappa

            def cond(w, d):
                return row, self.kappa * (self.problem.contour(d)[j] - w[j] - self.sigma)
        elif kind == "lambda":
            K = self.problem.K
            row = np.r_[-K[j, self.I], -K[j, self.A].sum()]

            def cond(w, d):
                return row, self.lam0 - K[j] @ w
        else:
            row = np.zeros(n_I + 1)
            row[-1] = self.kappa

            def cond(w, d):
                return row, self.kappa * (d - j)
        return self._newton(self.full_w(w0[self.I], d0), d0, cond)

    def tangent(self, w, d, t_ref, reuse=False):
        """Unit tangent (scaled; dw_A/ds = dd/ds) of this piece at (w, d), with t . t_ref > 0
        in the arclength norm.

        The tangent spans the null space of the piece's Jacobian [J_w | J_d]; any border row
        not orthogonal to it makes the bordered matrix regular, so with ``reuse`` the
        factorisation of the corrector's last Newton iteration (its own border row, at the
        previous iterate: an O(last Newton step) error, ~1e-12 relative) serves."""
        rhs = np.zeros(self.I.size + 1)
        rhs[-1] = self.kappa
        if reuse and self.lu is not None:
            x = lapack.dgetrs(*self.lu, rhs)[0]
        else:
            h = self.problem.contour(d) - w
            M = np.empty((self.I.size + 1, self.I.size + 1))
            M[:-1] = self._jacobian(h)
            M[-1] = self._plane_row(t_ref)
            lu, piv, info = lapack.dgetrf(M, overwrite_a=True)
            self.curve.n_factor += 1
            if info > 0:
                raise ConvergenceError("sigma-gap arclength: the bordered Jacobian is "
                                       "singular", d=d, residual=math.nan, n_iter=0)
            x = lapack.dgetrs(lu, piv, rhs)[0]
        t = np.empty(self.n + 1)
        t[self.I], t[self.A], t[-1] = x[:-1], x[-1], x[-1]
        norm = math.sqrt(self.omega * (t[:-1] @ t[:-1]) + t[-1] ** 2)
        if not (norm > 0 and math.isfinite(norm)):
            raise ConvergenceError("sigma-gap arclength: no finite tangent", d=d,
                                   residual=math.nan, n_iter=0)
        if self.omega * (t[:-1] @ t_ref[:-1]) + t[-1] * t_ref[-1] < 0:
            norm = -norm
        return t / norm

    def stable(self, w, d):
        """Energy minimum on the free nodes (the Hessian's inertia, as the stepping solver)."""
        return is_stable(self.problem, self.problem.contour(d) - w, ~self.active)

    # -- constraint values along the piece ------------------------------------------------
    def constraints(self, w, d):
        """(free gaps above sigma (m), multipliers (Pa)) of a state on this piece."""
        h = self.problem.contour(d) - w
        return h[self.free] - self.sigma, self.multipliers(w)

    def rates(self, t):
        """d/ds of :meth:`constraints` along the scaled tangent t (m and Pa per unit s)."""
        s = self.scale
        return ((t[-1] - t[:-1][self.free]) * s,
                -(self.problem.K[self.A] @ t[:-1]) * s)


def curve_state(problem, d, w, stable):
    """A :class:`State` for a point of a sigma-gap curve: the active set is the nodes held at
    h = sigma (to rounding), p_c from the equation on them, the residual of eq (10)."""
    h = problem.contour(d) - w
    sigma = problem.sigma
    A = np.abs(h - sigma) <= 1e-9 * sigma
    adh = problem.gap.adhesion if problem.gap is not None else 0.0
    P = problem.pressure(h)
    pc = np.zeros(w.size)
    pc[A] = P[A] - problem.K[A] @ w
    res = float(np.max(np.abs(w - problem.C @ (P - pc))))
    p_eff = {k: e.pressure(h) for k, e in problem.effects.items()}
    if adh:
        p_eff["asperity_adhesion"] = np.where(A, adh, 0.0)
    r_c = math.sqrt(float(problem.areas[A].sum()) / math.pi)
    return State(d, w, h, p_eff, pc + adh * A if adh else pc, A, r_c, 0, res, True, stable)


def trace_sigma_curve(problem, d_start, d_end, *, tol, scale, ds, ds_max=None, w_start=None,
                      max_points=20000, on_point=None, progress=None):
    """Follow the sigma-gap equilibrium curve from d_start until it passes d_end (m).

    Parameters
    ----------
    problem : ContactProblem
        With the complementarity sigma-gap (``problem.sigma`` set, eq 8).
    d_start, d_end : float
        Separations (m): the curve starts from the stable state solved at d_start and ends
        with a point exactly at d_end.
    tol : float
        Residual of eq (10) every point meets (m).
    scale : float
        Length (m) of one unit of arclength (the sweep step, or z0).
    ds, ds_max : float
        First and largest step length (units of ``scale``; ds_max default 20 ds).
    on_point : callable(int, CurvePoint), optional
        Called with each point as it is accepted (streams it; may raise to stop).
    progress : callable(float), optional
        Called with the fraction of |d_end - d_start| covered.

    Returns
    -------
    EquilibriumCurve
        Points in arclength order (an event state twice: end of one piece, start of the
        next), folds (smooth ones located by Brent on dd/ds; corner folds at the event
        state, ``s_offset`` 0), ``tracers`` the pieces.

    Raises
    ------
    ConvergenceError
        Naming the separation, residual and iterations, if the step collapses, a point needs
        more than MAX_ATTEMPTS_PER_POINT correctors, the active set cycles at one state, or
        the curve needs more than ``max_points`` points; the partial curve is ``.curve``.
    """
    from .complementarity import solve_complementarity

    if problem.sigma is None or problem.contact_model not in (None, "complementarity"):
        raise ValueError("sigma-gap arclength continuation needs the complementarity "
                         "sigma-gap (paper 1 eq 8)")
    if problem.gap.adhesion:
        # a node reaching sigma joins the contact with lambda = P_LJa > 0, feasible both
        # ways along the new piece: the equilibria branch at every activation (approach and
        # retract part), a network no single curve represents
        raise ValueError("sigma-gap arclength continuation: eq 20 adhesion on the contact "
                         "set makes the equilibria branch at every contact node (not traced)")
    t0 = time.perf_counter()
    n = problem.grid.n
    ds_max = 20 * ds if ds_max is None else ds_max
    direction = math.copysign(1.0, d_end - d_start)
    curve = EquilibriumCurve()
    w0 = np.zeros(n) if w_start is None else np.asarray(w_start, float)
    st = solve_complementarity(problem, d_start, w0, tol=tol, max_iter=60)
    curve.n_solves += 1
    if not st.converged:
        raise ConvergenceError("sigma-gap arclength start: Newton did not converge",
                               d=d_start, residual=st.residual, n_iter=st.n_iter)
    pc = _Piece(problem, st.active, scale, tol, curve).register()
    t_init = np.zeros(n + 1)
    t_init[-1] = direction
    t = pc.tangent(st.w, d_start, t_init)
    pts = curve.points
    slack_lam = SLACK * tol * pc.kappa

    def fail(msg, d, res, it):
        exc = ConvergenceError(msg, d=d, residual=res, n_iter=it)
        exc.curve = curve
        curve.wall_time = time.perf_counter() - t0
        return exc

    def add(point):
        if len(pts) >= max_points:
            raise fail(f"sigma-gap arclength continuation needed more than {max_points} "
                       "points", point.d, point.residual, point.n_iter)
        pts.append(point)
        if on_point:
            on_point(len(pts) - 1, point)

    add(CurvePoint(d_start, st.w.copy(), t, st.stable, st.n_iter, st.residual, pc.seg))
    step, ds_min = ds, ds * MIN_STEP_FRACTION
    ceiling = math.inf
    attempts, events_here = 0, 0
    after_fold = True          # the first points' stability is computed
    while True:
        p = pts[-1]
        x = np.r_[p.w, p.d] / scale
        gaps, lams = pc.constraints(p.w, p.d)
        r_gap, r_lam = pc.rates(p.t)
        # the predictor moves no free gap by more than MAX_GAP_CHANGE of itself above 0
        hI = gaps + pc.sigma
        fast = np.abs(r_gap) > 0
        if np.any(fast):
            step = min(step, float(np.min(MAX_GAP_CHANGE * hI[fast] / np.abs(r_gap[fast]))))
        step = max(step, ds_min)
        # the first constraint the tangent reaches, and the end of the sweep
        event, s_event = None, math.inf
        for kind, values, rates, nodes in (("gap", gaps, r_gap, pc.I),
                                           ("lambda", lams, r_lam, pc.A)):
            k, s = _first_zero(values, rates)
            if s < s_event:
                event, s_event = (kind, int(nodes[k])), s
        if p.t_d * direction > 0 and (d_end - p.d) * direction >= 0:
            s = (d_end - p.d) / (p.t_d * scale)
            if s < s_event:
                event, s_event = ("d", d_end), s
        attempts += 1
        if attempts > MAX_ATTEMPTS_PER_POINT:
            raise fail(f"sigma-gap arclength continuation stalled after d = {p.d * 1e9:.6g} "
                       f"nm ({len(pts)} points): {attempts - 1} correctors for one point",
                       p.d, p.residual, p.n_iter)
        if event is not None and s_event <= step:
            # the step ends at the event: solve for the event state on this piece
            x_pred = x + s_event * p.t
            w, d, it, res, ok = pc.correct_event(x_pred[:-1] * scale, x_pred[-1] * scale,
                                                 event)
            s_used = s_event
        else:
            event = None
            x_pred = x + step * p.t
            xc, it, res, ok = pc.correct(x_pred, p.t)
            w, d = xc[:-1] * scale, xc[-1] * scale
            s_used = step
        why = None
        if not ok:
            why = f"the corrector did not converge (residual {res:.3g} m, {it} iterations)"
            ceiling = 0.8 * step
        else:
            t_new = pc.tangent(w, d, p.t, reuse=True)
            dx = np.r_[w, d] / scale - x
            ahead = pc.omega * (p.t[:-1] @ dx[:-1]) + p.t[-1] * dx[-1]
            gaps_c, lams_c = pc.constraints(w, d)
            viol_gap = gaps_c < -SLACK * tol
            viol_lam = lams_c < -slack_lam
            if event is not None:
                # the event's own constraint holds with equality there
                if event[0] == "gap":
                    viol_gap[np.searchsorted(pc.I, event[1])] = False
                elif event[0] == "lambda":
                    viol_lam[np.searchsorted(pc.A, event[1])] = False
            weights_ok = (pc.omega * (t_new[:-1] @ p.t[:-1]) + t_new[-1] * p.t[-1]
                          >= MIN_TANGENT_COS)
            h_c = problem.contour(d) - w
            h_p = problem.contour(x_pred[-1] * scale) - x_pred[:-1] * scale
            corr = float(np.max(np.abs(h_c - h_p)[pc.I] / h_c[pc.I])) if pc.I.size else 0.0
            if np.any(viol_gap) or np.any(viol_lam):
                why = (f"{int(viol_gap.sum())} gaps below sigma and {int(viol_lam.sum())} "
                       "negative contact pressures at the corrected point (an event the "
                       "tangent did not foresee)")
            elif ahead < -1e-12 * max(s_used, 1e-300):
                why = "the corrected point lies behind the last one"
            elif s_used > 0 and not weights_ok:
                why = "the tangent turned by more than 30 degrees"
            elif s_used > 0 and corr > 4 * TARGET_CORRECTION:
                why = f"the corrector moved a gap by {corr:.2g} of itself"
            elif s_used > 0 and (d - p.d) * p.t_d < 0 and p.t_d * t_new[-1] > 0:
                why = "two folds inside one step"
        if why is not None:
            if step <= ds_min * 1.0001:
                raise fail(f"sigma-gap arclength continuation stalled after d = "
                           f"{p.d * 1e9:.6g} nm ({len(pts)} points): {why} at the smallest "
                           "step", d, res, it)
            # an event nearer than the step is retried as a regular step shorter than it
            step = 0.5 * min(step, s_used) if s_used > 0 else 0.5 * step
            continue
        attempts = 0
        event_lu = pc.lu        # (before a fold search refactorises with other borders)
        folded = p.t_d * t_new[-1] < 0
        stable = p.stable != folded
        if folded or after_fold or len(pts) % HESSIAN_EVERY == 0:
            stable = pc.stable(w, d)
        after_fold = folded
        if folded:
            fold = _locate_fold(pc, p, s_used, len(pts) - 1)
            fold.seg = pc.seg
            curve.folds.append(fold)
        q = CurvePoint(d, w, t_new, stable, it, res, pc.seg)
        add(q)
        if progress:
            progress(min(1.0, (d - d_start) / (d_end - d_start)))
        if event is None:
            step = min(ds_max, ceiling, step * min(2.0, max(0.5, math.sqrt(
                TARGET_CORRECTION / max(corr, 1e-12)))))
            ceiling *= 1.05
            events_here = 0
            continue
        if event[0] == "d":
            break
        # a corner: the neighbouring piece, oriented so that the complementarity holds
        events_here = events_here + 1 if s_used == 0.0 else 1
        if events_here > MAX_EVENTS_AT_ONE_STATE:
            raise fail(f"sigma-gap arclength: the active set cycles at d = {d * 1e9:.6g} nm "
                       f"({events_here} events at one state)", d, res, it)
        kind, j = event
        active = pc.active.copy()
        active[j] = kind == "gap"
        new = _Piece(problem, active, scale, tol, curve)
        if kind == "gap" and event_lu is not None:
            # the event corrector's bordered matrix [J; h_j = sigma] already is the new
            # piece's: [J; g_j] x = e_j leaves equation j (now carried by p_c,j) free and
            # ties w_j to d, so x is the new tangent (no factorisation)
            e = np.zeros(pc.I.size + 1)
            e[np.searchsorted(pc.I, j)] = pc.kappa
            x2 = lapack.dgetrs(*event_lu, e)[0]
            t2 = np.empty(n + 1)
            t2[pc.I], t2[pc.A], t2[-1] = x2[:-1], x2[-1], x2[-1]
            t2 /= math.sqrt(new.omega * (t2[:-1] @ t2[:-1]) + t2[-1] ** 2)
        else:
            t2 = new.tangent(w, d, q.t)
        if kind == "gap":        # node j now held: its multiplier must grow
            grow = -(problem.K[j] @ t2[:-1])
        else:                    # node j released: its gap must open
            grow = t2[-1] - t2[j]
        if grow < 0:
            t2 = -t2
        new.register()
        corner_fold = q.t_d * t2[-1] < 0
        stable = q.stable != corner_fold
        if corner_fold or after_fold:
            stable = new.stable(w, d)
        after_fold = corner_fold
        r = CurvePoint(d, w, t2, stable, it, res, new.seg)
        if corner_fold:
            # a corner fold: d turns back at the event state (the discrete jump-out)
            curve.folds.append(Fold(len(pts) - 1, d, w.copy(), 0.0, pc.seg))
        pc = new
        add(r)
    curve.wall_time = time.perf_counter() - t0
    return curve


def _locate_fold(pc, p, step, index):
    """A smooth fold of piece pc between point p and one ``step`` further: the root of
    dd/ds on corrected points (Brent, to 1e-12 of the step)."""
    scale = pc.scale
    x = np.r_[p.w, p.d] / scale
    known = {0.0: (p.t_d, p.w, p.d)}

    def t_d(s):
        if s not in known:
            xc, it, res, ok = pc.correct(x + s * p.t, p.t)
            if not ok:
                raise _OffCurve
            w, d = xc[:-1] * scale, xc[-1] * scale
            known[s] = (pc.tangent(w, d, p.t)[-1], w, d)
        return known[s][0]
    try:
        s = bracketed_root(t_d, 0.0, step, xtol=1e-12 * step)
    except _OffCurve:
        s = min(known, key=lambda k: abs(known[k][0]))
    _, w, d = known[s]
    return Fold(index, d, w, s)


class _OffCurve(Exception):
    """The corrector did not converge at a requested arclength offset."""


def path_w_at(curve, direction, d):
    """Displacements w (m) of the displacement-controlled path (``direction`` "approach" or
    "retract", :meth:`EquilibriumCurve.walk`) at separation d (m), recomputed on the curve
    between the two stable run points that bracket d; None if no run interval brackets d
    (d between a landing and the next run point, or beyond the curve)."""
    pts = curve.points
    for kind, i, j in curve.walk(direction):
        if kind == "land" and j[1] is None and not curve._seam(i) \
                and (pts[i].d - d) * (pts[i + 1].d - d) < 0:
            return curve.point_at(i, d, j)    # beyond a landing, before the next run point
        if kind != "run":
            continue
        lo, hi = min(i, j), max(i, j)
        for k in range(lo, hi + 1):
            if pts[k].d == d:
                return pts[k].w
        for a in range(lo, hi):
            if curve._seam(a) or pts[a].d == pts[a + 1].d:
                continue
            if (pts[a].d - d) * (pts[a + 1].d - d) < 0:
                return curve.point_at(a, d)
    return None


def _first_zero(values, rates):
    """(index, arclength) of the first of ``values`` (kept >= 0) that falls to zero along the
    tangent at ``rates`` (linear), or (None, inf) if none falls."""
    falling = rates < 0
    if not np.any(falling):
        return None, math.inf
    s = np.where(falling, -np.maximum(values, 0.0) / np.where(falling, rates, 1.0), np.inf)
    k = int(np.argmin(s))
    return k, float(s[k])
