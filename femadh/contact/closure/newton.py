"""Newton with backtracking for the closure: unknowns (w_free, r_c), or (w_free, d) at fixed
r_c for the landing scan; and for the free surface (no contact), eq (6)."""
from dataclasses import dataclass

import numpy as np
from scipy import linalg

from ...interrupt import check as safe_point
from .system import _finite_or_raise

#: backtracking halvings of one Newton step before the iteration gives up
MAX_BACKTRACK = 12
#: below this multiple of the tolerance the last factorisation is reused (one chord step)
CHORD_FINISH = 1e4
#: Armijo constant of the line search on ||(F, G)||_2
ARMIJO = 1e-4
#: largest fraction of a free node's gap one Newton step may close (keeps h > 0 for LJ)
MAX_GAP_CLOSURE = 0.8
#: largest fraction of r_c one Newton step may remove (r_c stays positive)
MAX_RC_SHRINK = 0.5


@dataclass
class _Result:
    ok: bool
    d: float
    w: np.ndarray
    r_c: float
    ev: object
    n_iter: int
    reason: str = ""
    closing: bool = False
    last: tuple = None   # (lu, evaluation) of the last Newton iterate's Jacobian (border r_c)


def _lu_sign(lu_piv):
    lu, piv = lu_piv
    swaps = int(np.sum(piv != np.arange(piv.size)))
    return float(np.prod(np.sign(np.diag(lu)))) * (-1.0) ** (swaps % 2)


def _step_cap(h_free, dh):
    """Largest alpha <= 1 with no free gap closing by more than MAX_GAP_CLOSURE of itself."""
    closing = dh < 0
    if not np.any(closing):
        return 1.0
    return float(min(1.0, np.min(MAX_GAP_CLOSURE * h_free[closing] / -dh[closing])))


def _newton_contact(cs, d, w, r_c, *, border, tol, max_iter):
    """Newton with backtracking for the closure; unknowns (w_free, r_c) or, at fixed r_c,
    (w_free, d) (``border="d"``: the r_c-parametrised branch, used by the landing scan)."""
    w = cs.clamp(w, d, r_c)
    # a guess with free nodes below the asperity gap (h < sigma; h <= 0 would have no meaning
    # for LJ) starts from h = sigma there, the clamp's own level: the line search then only
    # visits h > 0
    m0, _ = cs.split(r_c)
    b = d + cs.shape
    w[m0:] = np.minimum(w[m0:], b[m0:] - cs.sigma)
    ev = cs.evaluate(d, w, r_c, it=1)
    last = None
    for it in range(1, max_iter + 1):
        safe_point()            # a signal stops the run between Newton iterations
        if ev.residual <= tol:
            return _Result(True, d, w, r_c, ev, it, last=last)
        # Newton (fresh factorisation) until the residual is within CHORD_FINISH of the
        # tolerance; there the last factorisation finishes the job (a chord step cuts the
        # residual ~500x, enough, and saves the LU). Chord steps from farther out were tried:
        # they needed more evaluations, each as dear as the LU at N = 200, and saved nothing.
        trial = None
        if (last is not None and ev.residual <= CHORD_FINISH * tol
                and (last[1].m, last[1].j) == (ev.m, ev.j)):
            dx = -linalg.lu_solve(last[0], np.append(ev.F, ev.G), check_finite=False)
            _finite_or_raise(dx, "chord step", d, lambda k: (
                f"unknown {k} of {dx.size} (border {border}), Newton iteration {it}"))
            trial = _line_search(cs, d, w, r_c, ev, dx, border, it, 1)
        if trial is None:
            J = cs.add_jacobian(ev).jacobian(border)
            try:
                lu = linalg.lu_factor(J, check_finite=False)
            except (linalg.LinAlgError, ValueError):
                return _Result(False, d, w, r_c, ev, it, "singular Jacobian")
            last = (lu, ev) if border == "r_c" else None
            dx = -linalg.lu_solve(lu, np.append(ev.F, ev.G), check_finite=False)
            _finite_or_raise(dx, "Newton step", d, lambda k: (
                f"unknown {k} of {dx.size} (border {border}), Newton iteration {it}"))
            trial = _line_search(cs, d, w, r_c, ev, dx, border, it, MAX_BACKTRACK)
        if trial == "closing":
            return _Result(False, d, w, r_c, ev, it, "contact closing (r_c -> 0)", closing=True)
        if trial is None:
            return _Result(False, d, w, r_c, ev, it, "line search found no decrease")
        d, w, r_c, ev = trial
    ok = ev.residual <= tol
    return _Result(ok, d, w, r_c, ev, max_iter, "" if ok else
                   f"no convergence in {max_iter} iterations")


def _line_search(cs, d, w, r_c, ev, dx, border, it, tries):
    """Backtracking on ||(F, G)||_2 (Armijo) from the step dx; the gap cap keeps h > 0 and
    r_c > 0. Returns (d, w, r_c, evaluation) of the accepted point, "closing" when r_c would
    drop below the floor (contact closing), or None."""
    m = ev.m
    dw, dq = dx[:-1], float(dx[-1])
    dh = (dq - dw) if border == "d" else -dw
    alpha = _step_cap(ev.h[m:], dh)
    if border == "r_c" and dq < 0:
        alpha = min(alpha, MAX_RC_SHRINK * r_c / -dq)
    phi0 = ev.norm
    for _ in range(tries):
        d_t = d + alpha * dq if border == "d" else d
        r_t = r_c + alpha * dq if border == "r_c" else r_c
        if r_t < cs.r_floor:
            return "closing"
        if r_t < cs.r_max:
            w_t = w.copy()
            w_t[m:] += alpha * dw
            m_t, _ = cs.split(r_t)
            w_t[:m_t] = d_t + cs.shape[:m_t] - cs.sigma       # the clamp
            if np.all(d_t + cs.shape[m_t:] - w_t[m_t:] > 0):
                ev_t = cs.evaluate(d_t, w_t, r_t, it=it)
                if ev_t.norm <= (1 - ARMIJO * alpha) * phi0:
                    return d_t, w_t, r_t, ev_t
        alpha *= 0.5
    return None


def _newton_free(cs, d, w, *, tol, max_iter):
    """Newton with backtracking for the free surface (no contact), eq (6). The result's
    ``last`` holds the LU of the final iterate's Jacobian (reused for the tangent)."""
    w = np.array(w, float)
    h, P, F = cs.evaluate_free(d, w, it=1)
    last = None
    for it in range(1, max_iter + 1):
        safe_point()            # a signal stops the run between Newton iterations
        if float(np.max(np.abs(F))) <= tol:
            return _Result(True, d, w, 0.0, (h, P, F), it, last=last)
        dP = cs.dlaw(h)
        _finite_or_raise(dP, "gap-law stiffness dP/dh (Pa/m)", d,
                         lambda k: f"node {k}, Newton iteration {it}")
        J = cs.C * dP[None, :]
        J[np.diag_indices_from(J)] += 1.0
        try:
            last = linalg.lu_factor(J, check_finite=False)
        except (linalg.LinAlgError, ValueError):
            return _Result(False, d, w, 0.0, (h, P, F), it, "singular Jacobian")
        dw = -linalg.lu_solve(last, F, check_finite=False)
        _finite_or_raise(dw, "Newton step", d, lambda k: f"node {k}, Newton iteration {it}")
        alpha = _step_cap(h, -dw)
        phi0 = float(np.linalg.norm(F))
        for _ in range(MAX_BACKTRACK):
            w_t = w + alpha * dw
            if np.all(d + cs.shape - w_t > 0):
                h_t, P_t, F_t = cs.evaluate_free(d, w_t, it=it)
                if np.linalg.norm(F_t) <= (1 - ARMIJO * alpha) * phi0:
                    break
            alpha *= 0.5
        else:
            return _Result(False, d, w, 0.0, (h, P, F), it, "line search found no decrease")
        w, h, P, F = w_t, h_t, P_t, F_t
    ok = float(np.max(np.abs(F))) <= tol
    return _Result(ok, d, w, 0.0, (h, P, F), max_iter, "" if ok else
                   f"no convergence in {max_iter} iterations", last=last)
