"""Equilibrium at one separation d: semismooth Newton for the complementarity model and a
bordered Newton method for the paper's Hertz closure.

Complementarity (eq 8 as h >= sigma, p_c >= 0, (h - sigma) p_c = 0) is solved as a primal-dual
active-set (semismooth) Newton method on K w = P(h) - p_c. On the active set A the gap is fixed,
w_A = b_A - sigma, and p_c,A follows from the equation; on the inactive set I, p_c = 0 and

    (K_II + diag(P'(h_I))) dw_I = -(K w - P(h))_I,

a system of the size of the *free* surface only, so deep contacts get cheaper. The active set is
updated by  i in A  <=>  p_c,i + c (sigma - h_i) > 0, the semismooth Newton step of the
min-complementarity function. Convergence is declared on the residual of the original equation
w - C (P - p_c) (m) with an unchanged active set.

Stability: a state is a strict local minimum of the energy (elastic + interaction) on the free
set iff the symmetric Hessian sym(S)_II + diag(area_I P'(h_I)) is positive definite; we test it
with a Cholesky factorisation. The Hertz closure has no energy; there the sign of the bordered
Jacobian's determinant (positive on stable branches, flipping at folds) stands in for it.
"""
import math

import numpy as np
from scipy import linalg, optimize

from ..reference.hertz import hertz_annulus_force, hertz_annulus_force_drc
from .problem import State
from .stability import is_stable

#: evaluations of the closure condition g(r_c) allowed per solve (bracketing + Brent)
CLOSURE_MAX_EVALS = 60
#: a chord step (reused factorisation) must cut the residual at least by this factor
CHORD_RATE = 0.05
#: above this many nodes a refactorisation (O(N^3)) costs more than many chord steps (O(N^2)):
#: a chord step there need only cut the residual by CHORD_RATE_LARGE (N = 1600: 35 -> 10
#: factorisations, 8.5 -> 6.9 s for the Fig 3 sweep; at N = 200 the strict rate is faster)
LARGE_N, CHORD_RATE_LARGE = 600, 0.15
#: largest fraction of the current gap one Newton step may close (keeps h > 0 for LJ)
MAX_GAP_CLOSURE = 0.8


def _damping(h, dh_closing):
    """Step length in (0, 1] so that no gap closes by more than MAX_GAP_CLOSURE of itself."""
    closing = dh_closing > 0
    if not np.any(closing):
        return 1.0
    return float(min(1.0, np.min(MAX_GAP_CLOSURE * h[closing] / dh_closing[closing])))


def _effect_pressures(problem, h):
    return {name: eff.pressure(h) for name, eff in problem.effects.items()}


def _residual(problem, w, p_net):
    """max |w - C p_net| (m): the residual of eq (6)/(10)."""
    return float(np.max(np.abs(w - problem.C @ p_net)))


def solve_state(problem, d, w0, *, tol, max_iter=50, active0=None, r_c0=None, factor=None):
    """Equilibrium of the surface at separation d (m), starting from displacements w0 (m).

    Dispatches on ``problem.contact_model``. Returns a :class:`State` whose ``converged`` flag
    tells whether ``residual <= tol`` was reached within ``max_iter`` iterations; never raises
    for non-convergence (the continuation decides what to do).
    """
    if problem.contact_model == "hertz-closure":
        return _solve_hertz_closure(problem, d, w0, tol=tol, max_iter=max_iter, r_c0=r_c0)
    return _solve_complementarity(problem, d, w0, tol=tol, max_iter=max_iter, active0=active0,
                                  factor=factor)


class TrailingLU:
    """One LU that solves every trailing block (K + D)[m:, m:] for m >= m0.

    When the contact set is a disk (nodes 0..m-1), the free-node Jacobian is the trailing block
    from m. Factorised in reversed node order, every trailing block is a *leading* block, and
    the LU of a leading block is the leading part of the full LU as long as partial pivoting
    made no row swap before it (checked: ``k_valid``). So moving the contact edge costs a
    triangular solve, not a new factorisation.
    """

    def __init__(self, K, D, m0, scale=None):
        n = K.shape[0]
        # reversed trailing block, a copy (the reversed slice is cheaper than fancy indexing)
        M = np.array(K[m0:, m0:][::-1, ::-1])
        M[np.diag_indices_from(M)] += D[m0:][::-1]
        # rows scaled by the annulus areas: diag(area) K is nearly symmetric (the energy
        # Hessian), for which partial pivoting rarely swaps rows - so one factorisation keeps
        # covering every trailing block
        self.scale = None if scale is None else np.asarray(scale, float)
        if self.scale is not None:
            M *= self.scale[m0:][::-1, None]
        self.n, self.m0 = n, m0
        self.lu, self.piv = linalg.lu_factor(M, check_finite=False)
        swaps = np.flatnonzero(self.piv != np.arange(n - m0))
        self.k_valid = int(swaps[0]) if swaps.size else n - m0
        self._block = (None, None)

    def covers(self, m):
        return m >= self.m0 and self.n - m <= self.k_valid

    def _lu_block(self, m):
        k = self.n - m
        if self._block[0] != k:
            lu = self.lu if k == self.lu.shape[0] else np.ascontiguousarray(self.lu[:k, :k])
            self._block = (k, (lu, self.piv[:k]))
        return self._block[1]

    def solve(self, m, rhs):
        """x with (K + D)[m:, m:] x = rhs (rhs in natural node order m..n-1)."""
        if m >= self.n:
            return np.zeros(0)
        if not self.covers(m):  # a pivot from outside the block: LAPACK would read past it
            raise ValueError(f"trailing block from node {m} is not covered (m0 = {self.m0}, "
                             f"valid leading size {self.k_valid})")
        if self.scale is not None:
            rhs = rhs * self.scale[m:]
        return linalg.lu_solve(self._lu_block(m), rhs[::-1], check_finite=False)[::-1]


def _disk_size(A):
    """m if the active set is exactly the nodes 0..m-1, else None."""
    m = int(A.sum())
    return m if A[:m].all() else None


#: extra nodes factorised inside the contact edge so a shrinking contact stays covered
DISK_MARGIN_FRACTION = 0.05


def _solve_complementarity(problem, d, w0, *, tol, max_iter, active0, constrained=True,
                           factor=None, load=None):
    """Semismooth Newton; with ``constrained=False`` the gap constraint is ignored (eq 6).

    ``load`` is an optional fixed repulsive pressure (Pa) on the annuli (the Hertz closure's
    P_el of eq 9), carried in ``p_contact`` of the result.

    ``factor`` = (lu, inactive mask) of an earlier Jacobian: while the active set equals that
    mask the factorisation is reused (chord steps), and refreshed only when the residual stops
    falling by CHORD_RATE per step. The LJ stiffness P'(h) is a small, slowly varying diagonal
    next to K, so chord steps converge almost as fast as Newton steps at a fraction of the cost.
    """
    K, b = problem.K, problem.contour(d)
    sigma = problem.sigma if constrained else None
    n = b.size
    chord_rate = CHORD_RATE_LARGE if n > LARGE_N else CHORD_RATE
    load = np.zeros(n) if load is None else load
    w = np.array(w0, dtype=float)
    if sigma is None:
        A = np.zeros(n, bool)
    elif active0 is not None:
        A = active0.copy()
    else:
        A = b - w < sigma
    seen = set()
    if isinstance(factor, TrailingLU):
        lu, lu_I = factor, None
    else:
        lu, lu_I = factor if factor is not None else (None, None)
    fresh = False
    res, res_prev, it = math.inf, math.inf, 0
    for it in range(1, max_iter + 1):
        if sigma is not None:
            w[A] = b[A] - sigma
        I = ~A
        h = b - w
        if np.any(h[I] <= 0):
            break  # the guess put the surfaces through each other: hopeless, report failure
        P = problem.pressure(h) - load
        F_I = (K @ w)[I] - P[I]
        m = _disk_size(A)
        # near the tolerance the residual approaches round-off and no step cuts it by
        # CHORD_RATE; there a chord step only has to keep making progress
        stalled = res > (chord_rate if res > 100 * tol else 0.7) * res_prev
        if m is not None:
            if not (isinstance(lu, TrailingLU) and lu.covers(m)) or stalled:
                m0 = max(0, m - max(4, int(DISK_MARGIN_FRACTION * n)))
                cand = TrailingLU(K, problem.dpressure(h), m0, problem.areas)
                if cand.covers(m):
                    lu, lu_I, fresh = cand, None, True
                    res_prev = math.inf
                else:  # pivoting swapped rows inside the block: use the general path
                    m = None
            else:
                res_prev = res
        if m is not None:
            dw = -lu.solve(m, F_I)
        else:
            if isinstance(lu, TrailingLU) or not np.array_equal(I, lu_I) or lu is None \
                    or stalled:
                idx = np.flatnonzero(I)
                M = K[idx[:, None], idx]
                M[np.diag_indices_from(M)] += problem.dpressure(h[I])
                lu, lu_I, fresh = linalg.lu_factor(M, check_finite=False), I, True
                res_prev = math.inf
            else:
                res_prev = res
            dw = -linalg.lu_solve(lu, F_I, check_finite=False)
        alpha = _damping(h[I], dw)
        w[I] += alpha * dw
        h = b - w
        P = problem.pressure(h) - load
        pc = np.zeros(n)
        if sigma is not None:
            pc[A] = P[A] - (K @ w)[A]
            new_A = (A & (pc > 0)) | (I & (h < sigma))
        else:
            new_A = A
        res = _residual(problem, w, P - pc)
        if np.array_equal(new_A, A) and res <= tol and alpha == 1.0:
            factor = lu if isinstance(lu, TrailingLU) else (lu, lu_I)
            return _finish(problem, d, w, h, pc + load, A, it, res, factor, fresh)
        key = new_A.tobytes()
        if key in seen and not np.array_equal(new_A, A):
            # The active set cycles (non-convex LJ near the contact edge): accept only the
            # additions/removals adjacent to the current contact boundary to break the cycle.
            new_A = _restrict_change(A, new_A)
        seen.add(key)
        if not np.array_equal(new_A, A):
            res = math.inf
        A = new_A
    h = b - w
    pc = np.zeros(n)
    if sigma is not None and np.all(h[~A] > 0):
        pc[A] = problem.pressure(h)[A] - load[A] - (K @ w)[A]
    return State(d, w, h, _effect_pressures(problem, np.maximum(h, 1e-300)), pc + load, A,
                 _area_radius(problem, A), it, res, False, False, None)


def _restrict_change(A, new_A):
    """Change only the outermost changing node, a slow but non-cycling active-set update."""
    diff = np.flatnonzero(A != new_A)
    out = A.copy()
    k = diff[-1]
    out[k] = new_A[k]
    return out


def _area_radius(problem, A):
    """Contact radius (m) of an active set: sqrt(active area / pi)."""
    return math.sqrt(float(problem.areas[A].sum()) / math.pi)


def _finish(problem, d, w, h, pc, A, it, res, factor, fresh=False):
    """Package a converged state; its stability is the inertia of the energy Hessian on the
    free nodes (:func:`femadh.contact.stability.is_stable`), never read off the Newton
    factorisation (that one is of the collocation Jacobian, whose pivot signs do not give
    the Hessian's inertia)."""
    return State(d, w, h, _effect_pressures(problem, h), pc, A.copy(),
                 _area_radius(problem, A), it, res, True, is_stable(problem, h, ~A), factor)


def hessian_is_positive_definite(problem, state):
    """Stability of a state: Cholesky of the free-node energy Hessian (see stability.py)."""
    return is_stable(problem, state.h, ~state.active)


def tangent(problem, state):
    """dw/dd at a converged complementarity state, with its active set frozen (m/m).

    From K w = P(b - w) - p_c with db/dd = 1: on A, dw/dd = 1; on I,
    (K_II + D_I) t_I = D_I - K_IA 1. Reuses the corrector's factorisation.
    """
    A = state.active
    I = ~A
    t = np.ones(state.w.size)
    D = problem.dpressure(state.h)
    rhs = D[I] - problem.K[np.ix_(I, A)].sum(axis=1)
    m = _disk_size(A)
    if isinstance(state.lu, TrailingLU) and m is not None and state.lu.covers(m):
        t[I] = state.lu.solve(m, rhs)
        return t
    if isinstance(state.lu, TrailingLU) or state.lu is None:
        return np.zeros(state.w.size)  # no factorisation of this set at hand: zeroth order
    lu, lu_I = state.lu
    if lu_I is None or not np.array_equal(lu_I, I):
        return np.zeros(state.w.size)  # no factorisation of this set at hand: zeroth order
    t[I] = linalg.lu_solve(lu, rhs, check_finite=False)
    return t


# --------------------------------------------------------------------------- Hertz closure

def _hertz_pressure(problem, r_c):
    """Annulus averages (Pa) of the Hertz pressure of eq (9) with contact radius r_c, and d/dr_c."""
    e = problem.grid.edges
    R, E = problem.sphere.radius, problem.operator.e_star
    return (hertz_annulus_force(e, r_c, R, E) / problem.areas,
            hertz_annulus_force_drc(e, r_c, R, E) / problem.areas)


def _closure_solve(problem, d, r_c, w0, factor, *, tol, max_iter):
    """Paper 1's closure at a fixed contact radius r_c (eqs 8-10 and the Fig 2 flowchart).

    Inside r <= r_c the gap is held at sigma (w = b - sigma, as the paper's iteration sets it),
    so P_LJ = P_LJ(sigma) there; outside, w solves eq (10) w = C (P_LJ(h) - P_el) with the
    Hertz pressure P_el of eq (9). Newton on the outside nodes:
    (I + C_II diag(P'(h_I))) dw_I = -(w - C p)_I, the factorisation reused while it works.

    Returns (w, p_net, w10, residual, n_iter, factor, ok) with w10 = C p_net the displacement
    eq (10) gives everywhere (it differs from w inside the contact).
    """
    nodes, C = problem.grid.nodes, problem.C
    b = problem.contour(d)
    A = nodes <= r_c
    I = ~A
    pel, _ = _hertz_pressure(problem, r_c)
    w = np.array(w0, float)
    w[A] = b[A] - problem.sigma
    lu, lu_I = factor if factor is not None else (None, None)
    res, res_prev = math.inf, math.inf
    for it in range(1, max_iter + 1):
        h = b - w
        if np.any(h <= 0):
            break
        p = problem.pressure(h) - pel
        R_I = (w - C @ p)[I]
        res = float(np.max(np.abs(R_I))) if R_I.size else 0.0
        if res <= tol:
            return w, p, C @ p, res, it, (lu, lu_I), True
        if lu is None or not np.array_equal(lu_I, I) or res > CHORD_RATE * res_prev:
            idx = np.flatnonzero(I)
            J = C[idx[:, None], idx] * problem.dpressure(h[I])[None, :]
            J[np.diag_indices_from(J)] += 1.0
            lu, lu_I = linalg.lu_factor(J, check_finite=False), I
            res_prev = math.inf
        else:
            res_prev = res
        dw = -linalg.lu_solve(lu, R_I, check_finite=False)
        w[I] += _damping(h[I], dw) * dw
    p = problem.pressure(np.maximum(b - w, 1e-300)) - pel
    return w, p, C @ p, res, max_iter, (lu, lu_I), False


def _solve_hertz_closure(problem, d, w0, *, tol, max_iter, r_c0):
    """Paper 1's closure: contact radius r_c is the root of g(r_c) = h10(r_c) - sigma, where h10
    is the gap eq (10) gives just outside the clamped contact (continuity of the deformed
    surface at r_c, the paper's w(r_c) = b(r_c) - sigma).

    g has kinks where r_c crosses nodes and annulus edges, which make a joint Newton iteration in
    (w, r_c) cycle (as the paper reports for its own iteration); r_c is therefore found by
    bracketed Brent iteration to machine precision.
    """
    sigma, nodes = problem.sigma, problem.grid.nodes
    free = _solve_complementarity(problem, d, w0, tol=tol, max_iter=max_iter, active0=None,
                                  constrained=False)
    if free.converged and np.min(free.h) >= sigma:
        free.r_c = 0.0
        return free
    cache = {"w": free.w if free.converged else np.array(w0, float), "factor": None,
             "n_iter": 0, "last": None}

    def g(r_c):
        cache["evals"] = cache.get("evals", 0) + 1
        if cache["evals"] > CLOSURE_MAX_EVALS:
            raise _InnerFailure(r_c, math.nan, cache["n_iter"], "the closure's contact radius "
                                f"was not found in {CLOSURE_MAX_EVALS} evaluations")
        out = _closure_solve(problem, d, r_c, cache["w"], cache["factor"], tol=tol,
                             max_iter=max_iter)
        w, p, w10, res, it, factor, ok = out
        cache["n_iter"] += it
        if not ok:
            # Too small a contact: the free surface beyond r_c is pulled through h = sigma and
            # eq (10) has no solution near it. That is the g < 0 side of the root.
            cache["last"] = None
            return -sigma
        cache["w"], cache["factor"], cache["last"] = w, factor, (r_c, out)
        return float(problem.sphere.contour(r_c, d) - np.interp(r_c, nodes, w10)) - sigma

    r_max = float(nodes[-1])
    r_min = 1e-6 * nodes[1]
    try:
        # Bracket the root from the best guess outward: the previous r_c, else the radius where
        # the starting surface reaches sigma. (Starting from r_c -> 0 would mean solving the
        # nearly free LJ problem, which past the free jump-in has no solution near the guess.)
        guess = r_c0 or _outer_crossing(nodes, problem.contour(d) - cache["w"],
                                        sigma * (1 + 1e-9)) or nodes[1]
        guess = min(max(guess, r_min), r_max)
        lo = hi = guess
        if g(guess) < 0:
            while True:
                hi = min(hi * 1.25, r_max)
                if g(hi) >= 0:
                    break
                if hi >= r_max:
                    raise _InnerFailure(hi, math.nan, cache["n_iter"],
                                        "contact radius reached the analysis radius")
                lo = hi
        else:
            while True:
                lo = lo / 1.25
                if lo < r_min:
                    raise _InnerFailure(lo, math.nan, cache["n_iter"], "no closure root: eq "
                                        "(10) leaves h >= sigma for any contact radius")
                if g(lo) < 0:
                    break
                hi = lo
        try:
            r_c = optimize.brentq(g, lo, hi, xtol=1e-13 * hi, rtol=4 * np.finfo(float).eps,
                                  maxiter=200)
        except ValueError:
            # g re-evaluated at the bracket ends changed sign: the closure's inner problem has
            # more than one solution there (the model is ill-posed, see validation/README.md)
            raise _InnerFailure(hi, math.nan, cache["n_iter"], "the closure condition is not "
                                "unique near its root") from None
        if cache["last"] is None or cache["last"][0] != r_c:
            g(r_c)
        if cache["last"] is None or abs(g(r_c)) > 1e-6 * sigma:
            raise _InnerFailure(r_c, math.nan, cache["n_iter"], "the closure root sits where "
                                "eq (10) has no solution just below it")
    except _InnerFailure as exc:
        w = cache["w"]
        h = problem.contour(d) - w
        n = nodes.size
        return State(d, w, h, _effect_pressures(problem, np.maximum(h, 1e-300)), np.zeros(n),
                     nodes <= exc.r_c, exc.r_c, exc.n_iter, exc.residual, False, False)
    w, p, w10, res, _, factor, _ = cache["last"][1]
    h = problem.contour(d) - w
    pel, _ = _hertz_pressure(problem, r_c)
    A = nodes <= r_c
    lu = factor[0]
    sign = np.prod(np.sign(np.diag(lu[0]))) * (-1) ** (np.sum(lu[1] != np.arange(lu[1].size)) % 2)
    st = State(d, w, h, _effect_pressures(problem, h), pel, A, r_c, cache["n_iter"], res, True,
               bool(sign > 0))
    # eq (10) holds outside only: how far the clamped interior is from it (m)
    st.diagnostics["eq10_violation_inside_m"] = float(np.max(np.abs(w - w10)[A])) if A.any() else 0.0
    return st


class _InnerFailure(Exception):
    def __init__(self, r_c, residual, n_iter, reason="eq (10) did not converge"):
        super().__init__(reason)
        self.r_c, self.residual, self.n_iter = r_c, residual, n_iter


def _outer_crossing(nodes, h, sigma):
    """Outermost radius where the piecewise-linear gap h crosses sigma from below, or 0."""
    below = np.flatnonzero(h < sigma)
    if below.size == 0:
        return 0.0
    k = below[-1]
    if k == nodes.size - 1:
        return float(nodes[-1])
    t = (sigma - h[k]) / (h[k + 1] - h[k])
    return float(nodes[k] + t * (nodes[k + 1] - nodes[k]))
