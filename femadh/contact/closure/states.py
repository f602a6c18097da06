"""Closure states: packaging an iterate as a State, its stability and tangent, and the solve
at one separation."""
import math

import numpy as np
from scipy import linalg

from ..state import State
from ..stability import is_positive_definite
from . import hertz
from .newton import _lu_sign, _newton_contact, _newton_free
from .system import ClosureSystem


def _annulus_fraction_inside(edges, r_c):
    """Fraction of each annulus's area inside r < r_c."""
    e2 = edges**2
    inside = np.clip(r_c * r_c - e2[:-1], 0.0, None)
    return np.minimum(inside / (e2[1:] - e2[:-1]), 1.0)


def _contact_state(cs, res, tol):
    """Package a converged (or failed) contact iterate as a State (see module docstring)."""
    problem = cs.problem
    d, w, r_c, ev = res.d, res.w, res.r_c, res.ev
    g = problem.grid
    frac = _annulus_fraction_inside(g.edges, r_c)
    h = ev.h.copy()
    p_eff = {}
    for name, eff in problem.effects.items():        # law at sigma inside, at h_k outside
        p_k = eff.pressure(h)
        p_eff[name] = frac * eff.pressure(np.array([cs.sigma]))[0] + (1 - frac) * p_k
    if cs.p_asperity:                                # eq (20): constant over r < r_c
        p_eff["asperity_adhesion"] = cs.p_asperity * frac
    p_c = hertz.annulus_force(g.edges, r_c, problem.sphere.radius,
                              problem.operator.e_star if hasattr(problem.operator, "e_star")
                              else cs.infl.e_star) / g.areas
    active = g.nodes <= r_c
    st = State(d, w, h, p_eff, p_c, active, r_c, res.n_iter, ev.residual, res.ok, False)
    st.diagnostics["mode"] = "contact"
    st.diagnostics["edge_residual_m"] = abs(ev.G)
    st.diagnostics["eq10_residual_free_m"] = float(np.max(np.abs(ev.F))) if ev.F.size else 0.0
    st.diagnostics["eq10_violation_inside_m"] = (float(np.max(np.abs(w[:ev.m] - ev.w10[:ev.m])))
                                                 if ev.m else 0.0)
    if not res.ok:
        st.diagnostics["failure"] = res.reason
        return st
    _stability_and_tangent(cs, st, ev, res.last)
    return st


def _stability_and_tangent(cs, st, ev, last=None):
    """det sign of the joint Jacobian (the stability rule), Schur complement, w-block sign,
    and the tangent dx/dd (predictor; dr_c/dd is the branch slope).

    ``last`` = (LU, evaluation) of the final Newton step's Jacobian: reused when it has the
    converged state's structure (same clamped nodes and cut annulus). That iterate is within
    the Newton step of the state (the step that took the residual to <= tol, ~1e-9 of the
    displacements), so the determinant's sign can differ from the state's only that close to
    a fold, well inside the fold resolution of the continuation; otherwise a fresh LU.
    """
    if last is not None and (last[1].m, last[1].j) == (ev.m, ev.j):
        lu, ev = last
        J = None
    else:
        J = cs.add_jacobian(ev).jacobian("r_c")
        lu = linalg.lu_factor(J, check_finite=False)
    det_sign = _lu_sign(lu)
    st.stable = bool(det_sign < 0)
    st.diagnostics["det_sign"] = det_sign
    # (J^-1)_nn = det A / det J = 1/s: the Schur complement s (reduced dG/dr_c) and, with the
    # sign of det J, the sign of the w-block's determinant, from the same factorisation
    e_n = np.zeros(ev.F.size + 1)
    e_n[-1] = 1.0
    inv_nn = float(linalg.lu_solve(lu, e_n, check_finite=False)[-1])
    st.diagnostics["schur_dG_drc"] = 1.0 / inv_nn if inv_nn != 0 else math.inf
    st.diagnostics["w_block_det_sign"] = float(det_sign * np.sign(inv_nn))
    t = -linalg.lu_solve(lu, np.append(ev.f_d, ev.g_d), check_finite=False)
    dw = np.ones(cs.n)              # clamped nodes follow the sphere: w = b - sigma
    dw[ev.m:] = t[:-1]
    st.diagnostics["drc_dd"] = float(t[-1])
    st.diagnostics["dw_dd"] = dw


def _free_state(cs, res):
    problem = cs.problem
    d, w = res.d, res.w
    h, P, F = res.ev
    n = cs.n
    p_eff = {name: e.pressure(h) for name, e in problem.effects.items()}
    if cs.p_asperity:
        p_eff["asperity_adhesion"] = np.zeros(n)
    resid = float(np.max(np.abs(F)))
    st = State(d, w, h, p_eff, np.zeros(n), np.zeros(n, bool), 0.0, res.n_iter, resid,
               res.ok, False)
    st.diagnostics["mode"] = "free"
    st.diagnostics["eq10_violation_inside_m"] = 0.0
    st.diagnostics["edge_residual_m"] = 0.0
    if not res.ok:
        st.diagnostics["failure"] = res.reason
        return st
    # a true energy exists without contact: stable = positive definite Hessian (the gap laws
    # the closure carries; eq 20 acts only over the contact)
    H = problem.S_sym.copy()
    H[np.diag_indices_from(H)] += problem.areas * cs.dlaw(h)
    st.stable = is_positive_definite(H)
    st.diagnostics["min_gap_minus_sigma_m"] = float(np.min(h) - cs.sigma)
    # tangent dw/dd = (I + C P')^-1 C P' from the last iterate's LU (within tol of the state)
    dP = cs.dlaw(h)
    if res.last is not None:
        st.diagnostics["dw_dd"] = linalg.lu_solve(res.last, cs.C @ dP, check_finite=False)
    else:
        J = cs.C * dP[None, :]
        J[np.diag_indices_from(J)] += 1.0
        st.diagnostics["dw_dd"] = linalg.solve(J, cs.C @ dP, check_finite=False)
    st.diagnostics["drc_dd"] = 0.0
    return st


def _outer_crossing(nodes, h, sigma):
    """Outermost radius where the piecewise-linear gap h is below sigma, or 0."""
    below = np.flatnonzero(h < sigma)
    if below.size == 0:
        return 0.0
    k = int(below[-1])
    if k == nodes.size - 1:
        return float(nodes[-1])
    t = (sigma - h[k]) / (h[k + 1] - h[k])
    return float(nodes[k] + t * (nodes[k + 1] - nodes[k]))


def solve_closure_state(problem, d, w0, *, tol, max_iter=40, r_c0=None, system=None):
    """Paper 1's Hertz closure at separation d (m), Newton from displacements w0 (m).

    Parameters
    ----------
    problem : ContactProblem
        With an asperity gap sigma (eq 8); gap laws (eq 3 LJ, ...) in ``effects``; an
        sigma-gap's ``adhesion`` (eq 20) acts as a constant pressure over r < r_c.
    d : float
        Separation of the sphere tip from the undeformed mean plane (m).
    w0 : ndarray
        Starting displacements at the nodes (m, up positive).
    tol : float
        Residual tolerance (m) on max|w - w10| (free nodes) + |edge residual|.
    max_iter : int
        Newton iterations per solve (each with at most MAX_BACKTRACK halvings).
    r_c0 : float, optional
        Starting contact radius (m); None or 0 starts without contact and switches to the
        closure if the free surface reaches h < sigma (r_c0 then from the crossing).

    Returns
    -------
    State
        ``converged`` tells whether the tolerance was met; ``stable`` follows the rule of the
        module docstring; ``diagnostics`` carries ``mode`` ("contact"/"free"),
        ``eq10_violation_inside_m``, ``edge_residual_m``, ``det_sign``, ``drc_dd`` and, when
        not converged, ``failure``. Never raises for non-convergence.

    Raises
    ------
    ConvergenceError
        At once on any non-finite pressure, displacement, residual or Newton step, naming d,
        the quantity and the node and iteration.
    """
    cs = system or ClosureSystem(problem)
    w0 = np.asarray(w0, float)
    sigma = cs.sigma
    tried_free = False
    if not r_c0:
        tried_free = True
        res = _newton_free(cs, d, w0, tol=tol, max_iter=max_iter)
        h = d + cs.shape - res.w
        if res.ok and np.min(h) >= sigma:
            return _free_state(cs, res)
        r_c0 = _outer_crossing(cs.nodes, h, sigma) or _outer_crossing(cs.nodes, d + cs.shape - w0,
                                                                       sigma)
        if r_c0 <= cs.r_floor:
            if not res.ok:
                return _free_state(cs, res)
            r_c0 = 0.5 * cs.nodes[1]
        w0 = res.w if np.all(h > 0) else w0
    r_c0 = min(max(float(r_c0), 2 * cs.r_floor), 0.999 * cs.r_max)
    res = _newton_contact(cs, d, w0, r_c0, border="r_c", tol=tol, max_iter=max_iter)
    if res.ok:
        return _contact_state(cs, res, tol)
    if res.closing and not tried_free:
        # the contact closes at this d: the free surface is the candidate (if it stays >= sigma)
        free = _newton_free(cs, d, res.w, tol=tol, max_iter=max_iter)
        if free.ok and np.min(d + cs.shape - free.w) >= sigma:
            return _free_state(cs, free)
    return _contact_state(cs, res, tol)
