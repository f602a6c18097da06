"""Where the surface lands after a fold: descent of the total energy (a quasi-static surface
slides downhill into the basin it rolls into), polished by Newton."""
import numpy as np
from scipy import linalg as sla

from ..interrupt import check as safe_point
from .complementarity import solve_complementarity

#: descent steps in a row that lower the energy by no more than its round-off after which the
#: descent has settled in its basin (Newton polishes from there). Measured on the Fig 4 scene
#: (632 nodes, the jump-in at d = 1.1098 nm): the basin's minimum is reached in 22 steps (the
#: gradient from 1 to 8e-10 of its start), after which no step lowers the energy by more than
#: 2 ulps of it, and the descent used to spin at round-off up to its cap of 400 steps (723
#: Cholesky factorisations, 6 s: a quarter of the run at accuracy 1e-3)
ROUNDOFF_STEPS = 3
#: the energy's round-off: this many ulps of the magnitudes of its elastic and interaction parts
ROUNDOFF_ULPS = 64


def _lm_descent(problem, d, w, h_floor, *, max_iter=400, roundoff=True):
    """Levenberg-Marquardt descent of the total energy from w (projected onto h >= h_floor).

    Steps solve (H + lam diag(H_el)) dw = -grad with H the symmetric energy Hessian; lam grows
    until the energy decreases and shrinks after each success, so the iteration slides
    downhill like an overdamped surface and ends in the basin it rolls into (the physical
    landing after a fold). Returns the final w and whether the gradient was driven to ~0 or
    (``roundoff``) the energy stopped falling beyond its round-off for ROUNDOFF_STEPS steps
    (settled: no descent step can tell a lower point of the basin from this one; the Newton
    polish can).
    """
    b = problem.contour(d)
    upper = b - h_floor
    w = np.minimum(np.array(w, float), upper)
    scale_diag = np.diag(problem.S_sym).copy()
    lam = 1.0
    e = problem.energy(w, d)
    g = problem.energy_gradient(w, d)
    g0 = float(np.max(np.abs(g))) + 1e-300
    flat = 0            # steps in a row that lowered the energy by no more than its round-off
    for _ in range(max_iter):
        safe_point()            # a signal stops the run between descent steps
        at_bound = (w >= upper - 1e-18) & (g < 0)   # pushing further into h < floor
        free = ~at_bound
        if float(np.max(np.abs(g[free]), initial=0.0)) <= 1e-10 * g0:
            return w, True
        H = problem.energy_hessian(b - w, free)
        while True:
            M = H.copy()
            M[np.diag_indices_from(M)] += lam * scale_diag[free]
            try:
                c = sla.cho_factor(M, check_finite=False)
            except sla.LinAlgError:
                lam *= 4
                if lam > 1e12:
                    return w, False
                continue
            dw = np.zeros_like(w)
            dw[free] = -sla.cho_solve(c, g[free], check_finite=False)
            w_new = np.minimum(w + dw, upper)
            e_new = problem.energy(w_new, d)
            if np.isfinite(e_new) and e_new <= e:
                break
            lam *= 4
            if lam > 1e12:
                return w, False
        elastic = 0.5 * w_new @ (problem.S_sym @ w_new)
        noise = ROUNDOFF_ULPS * np.finfo(float).eps * (abs(elastic) + abs(e_new - elastic))
        flat = flat + 1 if e - e_new <= noise else 0
        w, e = w_new, e_new
        if roundoff and flat >= ROUNDOFF_STEPS:
            return w, True
        g = problem.energy_gradient(w, d)
        lam = max(lam / 3, 1e-8)
    return w, False


def land(problem, d, w_start, *, tol, max_iter):
    """Equilibrium reached by energy descent from w_start at separation d (a jump's landing).

    Levenberg-Marquardt descent of elastic + interaction energy under the bound h >= sigma (or
    h >= 0.5 z0 for a smooth sphere, never active at a minimum: the LJ repulsion is far steeper),
    then the Newton corrector of the problem's contact model polishes the state.

    The descent stops once settled at round-off (ROUNDOFF_STEPS) - except on a lattice-trapped
    grid (a law softening beyond a node's stiffness), where the polish is fragile and the
    states reached depend on the iterates: there, and whenever the polish from a settled
    descent does not reach a stable state, the whole descent to its cap is run as before
    (measured: a GW slider on 100 nodes, softening 6.3x a node's stiffness, whose polish from
    the settled descent diverged to a residual of 2.5e-3 m and from the whole descent
    converged in 75 iterations).
    """
    trapped = problem.surface_force_stiffness()[0] >= 1.0
    st = _land(problem, d, w_start, tol=tol, max_iter=max_iter, roundoff=not trapped)
    if not trapped and not (st.converged and st.stable):
        st = _land(problem, d, w_start, tol=tol, max_iter=max_iter, roundoff=False)
    return st


def _land(problem, d, w_start, *, tol, max_iter, roundoff):
    """:func:`land` with the descent's round-off stop on or off."""
    b = problem.contour(d)
    if problem.sigma is not None:
        h_floor = problem.sigma
    else:
        z0s = [getattr(e, "z0", None) for e in problem.effects.values()]
        h_floor = 0.5 * min(z for z in z0s if z) if any(z0s) else 1e-12
    w, _ = _lm_descent(problem, d, w_start, h_floor, roundoff=roundoff)
    active = (b - w) <= h_floor * (1 + 1e-9) if problem.sigma is not None else None
    st = solve_complementarity(problem, d, w, tol=tol, max_iter=max_iter, active0=active)
    if not st.converged:
        # far from the old branch the polish can start slowly (stiff LJ repulsion, pivoted
        # factorisations): give it a larger budget from where it got to
        st2 = solve_complementarity(problem, d, st.w, tol=tol, max_iter=4 * max_iter,
                                    active0=st.active)
        st2.n_iter += st.n_iter
        st = st2
    return st
