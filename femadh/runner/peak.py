"""Fresh states between a branch's grid states, and the peak search that uses them.

A headline number read between two grid states (the largest adhesion; an instrument's
reading; an estimate member's peak near the fine run's) is solved as a fresh equilibrium
from the displacements interpolated between the bracketing states, and kept only if it
stayed on that branch. Used by the error estimate (:mod:`femadh.runner.estimates`), its
reduced members (:mod:`femadh.runner.members`) and the instrument
(:mod:`femadh.runner.instrument`).
"""
import numpy as np
from scipy import optimize


def state_between(problem, a, b, d, scene, reuse=False, start=None):
    """A fresh equilibrium at separation d between two states a and b of one branch, solved
    from the displacements interpolated between them, or None unless it converged, is stable
    and stayed on that branch (every gap within a quarter of the interpolation's). With
    ``reuse``, the nearer state's factorisation (if it has one) serves the corrector's chord
    steps, as in a sweep's step (an estimate's member: a third of the fresh factorisations).

    ``start`` = (state, slope): Newton starts from a fresh state of the same branch nearer
    to d instead, w = state.w + slope (d - state.d) (slope: dw/dd, m/m), with its contact
    set and factorisation (:func:`peak_adhesion`'s later evaluations, a few hundredths of a
    grid step apart); the branch test is still against the interpolation."""
    from ..contact import solve_state

    t = (d - a.d) / (b.d - a.d)
    w0, near = (1 - t) * a.w + t * b.w, a if abs(d - a.d) < abs(d - b.d) else b
    w_start = w0
    kw = {}
    if start is not None:
        near, slope = start
        w_start = near.w + slope * (d - near.d)
        if problem.sigma is not None:
            w_start = np.minimum(w_start, problem.contour(d) - problem.sigma)
    if (reuse or start is not None) and getattr(near, "lu", None) is not None:
        kw["factor"] = near.lu
    if problem.contact_model == "hertz-closure":
        kw["r_c0"] = near.r_c or None
    elif problem.sigma is not None:
        kw["active0"] = near.active | (problem.contour(d) - w_start < problem.sigma)
    st = solve_state(problem, d, w_start, tol=scene.tolerance, max_iter=scene.max_iter, **kw)
    if not (st.converged and st.stable) or off_branch(problem, d, st.w, w0):
        return None
    return st


def off_branch(problem, d, w, w0):
    """True when the surface w (m) at separation d (m) moved from w0 by more than a quarter
    of a gap w0 left anywhere: another branch than w0's, not the same one nearby."""
    return bool(np.any(np.abs(w - w0) > 0.25 * np.maximum(problem.contour(d) - w0, 0) + 1e-15))


#: the bounded search's tolerance in d as a fraction of the grid bracket (the half-width of
#: its final bracket, the d resolution part of d_at_max_adhesion's estimate). Measured with
#: 1e-3 (~5 fewer fresh states per search): F_ex(d) has kinks where a node joins the contact,
#: the peak moved by 2e-7 of the force on Fig 3 at 1e-4, a member's windowed search differed
#: from its whole bracket's by 2e-5 of the force (tests/test_estimate_members.py, 1e-5
#: allowed) and the layered FE run's estimate grew to 7.6 x its error: kept at 1e-4
PEAK_XTOL_FRACTION = 1e-4


def peak_adhesion(problem, prev, best, nxt, scene, within=None, reuse=False):
    """The largest F_ex of the curve between the grid states around its best grid state
    ``best``: a bounded search in d on fresh states, each solved from the displacements
    interpolated between the bracketing grid states and accepted only if it stays on that
    branch (within a quarter of every gap of the interpolation). The states may be
    :class:`~femadh.runner.sink.Committed` records (d, w, active, r_c, f_ex) as the files
    hold them. A fold bounds the bracket: the landing that starts a piece of the branch is
    its own previous neighbour, the last state before a fold its own next one
    (:func:`pieces`). ``within`` = (lo, hi) narrows the search to that part of the bracket (an
    estimate's member near the fine run's peak: fewer fresh states, the same absolute
    tolerance in d); ``reuse``: see :func:`state_between`. Returns (F, d, half-width of the
    final d bracket)."""
    from ..contact.forces import state_forces

    f_best = best.f_ex if hasattr(best, "f_ex") else state_forces(problem, best)[2]
    lo, hi = sorted((prev.d, nxt.d))
    xatol = PEAK_XTOL_FRACTION * (hi - lo)
    if within is not None:
        lo, hi = max(lo, within[0]), min(hi, within[1])
    if not hi > lo:
        # a piece of one state (a landing that folds again at once): nothing between
        return float(f_best), float(best.d), xatol
    found, fresh = {}, []

    def neg(d):
        # (a fold's last state is its own next neighbour: only the side before it)
        a, b = (prev, best) if nxt.d == best.d or (d - best.d) * (prev.d - best.d) > 0 \
            else (best, nxt)
        st = state_between(problem, a, b, d, scene, reuse, _warm(fresh, a, b, d))
        if st is None:
            return -f_best
        found[d] = state_forces(problem, st)[2]
        fresh.append(st)
        return -found[d]
    optimize.minimize_scalar(neg, bounds=(lo, hi), method="bounded",
                             options={"xatol": xatol, "maxiter": 40})
    F, d = max([(f_best, best.d)] + [(v, x) for x, v in found.items()])
    return float(F), float(d), xatol


#: fresh states a peak search starts Newton from once it has them (False: every evaluation
#: from the interpolation between the grid states, as before)
WARM_PEAK = True


def _warm(fresh, a, b, d):
    """(state, slope) to start the fresh state at d from, or None: the search's fresh state
    nearest to d between a and b (the same piece of the branch), with the slope dw/dd of the
    secant through it and the next nearest there (or through the grid states a and b). The
    bounded search's later evaluations lie ever closer to earlier ones (Fig 3 at 1e-4: 48
    fresh states, 7.8 Newton iterations each from the interpolation between grid states
    0.2 nm apart)."""
    if not WARM_PEAK:
        return None
    lo, hi = sorted((a.d, b.d))
    inside = sorted((s for s in fresh if lo <= s.d <= hi), key=lambda s: abs(s.d - d))
    if not inside:
        return None
    near = inside[0]
    other = next((s for s in inside[1:] if s.d != near.d), None)
    if other is None or abs(other.d - near.d) < 1e-6 * abs(b.d - a.d):
        return near, (b.w - a.w) / (b.d - a.d)
    return near, (other.w - near.w) / (other.d - near.d)


def pieces(sink, branch):
    """The committed states and fold states of ``branch`` split into the pieces the folds
    leave, in the order of the sweep: [(states, starts at a landing, ends at a fold)].

    A piece holds its landing (the fold's state after the snap), the branch's committed
    states up to the next fold and that fold's last state; a state at the separation of the
    one before it is that state and is left out (a landing on a grid separation, a fold
    right at a committed state), as the sink's peak bookkeeping does
    (:meth:`femadh.runner.sink.Sink._element`)."""
    states = sink.committed.get(branch, [])
    folds = list(getattr(sink, "pieces", {}).get(branch, []))
    out, cur, starts = [], [], False
    for i in range(len(states) + 1):
        while folds and folds[0][0] == i:
            _, before, after = folds.pop(0)
            if not (cur and cur[-1].d == before.d):
                cur.append(before)
            out.append((cur, starts, True))
            cur, starts = [after], True
        if i < len(states) and not (cur and cur[-1].d == states[i].d):
            cur.append(states[i])
    out.append((cur, starts, False))
    return out
