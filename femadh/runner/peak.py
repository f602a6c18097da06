"""Fresh states between a branch's grid states, and the peak search that uses them.

A headline number read between two grid states (the largest adhesion; an instrument's
reading; an estimate member's peak near the fine run's) is solved as a fresh equilibrium
from the displacements interpolated between the bracketing states, and kept only if it
stayed on that branch. Used by the error estimate (:mod:`femadh.runner.estimates`), its
reduced members (:mod:`femadh.runner.members`) and the instrument
(:mod:`femadh.runner.instrument`).
"""
import math

import numpy as np
from scipy import optimize


def state_between(problem, a, b, d, scene, reuse=False, start=None):
    """A fresh equilibrium at separation d between two states a and b of one branch, solved
    from the displacements interpolated between them, or None unless it converged, is stable
    and stayed on that branch (every gap within a quarter of the interpolation's). With
    ``reuse`` (an estimate's member), the nearer state's factorisation (if it has one) serves the
    corrector's chord steps, as in a sweep's step, on a grid of at least
    MEMBER_FACTOR_MIN_NODES nodes (:func:`reuse_factor`; on fewer the corrector factorises
    its own).

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
    if (reuse or start is not None) and getattr(near, "lu", None) is not None and \
            not (reuse and not reuse_factor(problem)):
        kw["factor"] = near.lu
    if problem.contact_model == "hertz-closure":
        kw["r_c0"] = near.r_c or None
    elif problem.sigma is not None:
        kw["active0"] = near.active | (problem.contour(d) - w_start < problem.sigma)
    st = solve_state(problem, d, w_start, tol=scene.tolerance, max_iter=scene.max_iter, **kw)
    if not (st.converged and st.stable) or off_branch(problem, d, st.w, w0):
        return None
    return st


#: an estimate member's fresh state (``reuse``) starts its corrector with the factorisation
#: of a state nearby only on a grid of at least this many nodes; on fewer, its corrector
#: factorises its own Jacobian. A factorisation inherited from a state a fraction of a grid
#: step away (the grid state, or a fresh state that solved with it: the chord steps keep it
#: while the residual falls by the chord rate) makes the corrector's steps chord steps, each
#: a full evaluation of the laws (the slider meniscus scene's sub-grid meniscus quadrature),
#: where a factorisation of a member's few dozen nodes costs less than one of them:
#: measured on the accuracy table's adaptive rows (estimate_cost.md, session 9), the
#: members' Newton iterations fell 26-33 % on the 29-128-node members (Fig 3 at 1e-2, 3e-3
#: and 1e-3, the slider at 1e-2 and 1e-3); with own factorisations on Fig 4's 201-420-node
#: members too, not one iteration fewer (267 and 482 over the whole run at 3e-3 and 1e-3,
#: as with this threshold), where a factorisation costs more. (The fine run's own peak
#: search keeps its chord steps: its headline is not moved.)
MEMBER_FACTOR_MIN_NODES = 150


def reuse_factor(problem):
    """Whether an estimate member's state on ``problem`` starts its corrector with a nearby
    state's factorisation (its grid has at least MEMBER_FACTOR_MIN_NODES nodes)."""
    return problem.grid.n >= MEMBER_FACTOR_MIN_NODES


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


class WindowMiss(Exception):
    """A windowed peak search stopped: its best state so far lies at the window's edge."""


def peak_adhesion(problem, prev, best, nxt, scene, within=None, reuse=False, record=None,
                  edge_stop=None):
    """The largest F_ex of the curve between the grid states around its best grid state
    ``best``: a bounded search in d on fresh states, each solved from the displacements
    interpolated between the bracketing grid states and accepted only if it stays on that
    branch (within a quarter of every gap of the interpolation). The states may be
    :class:`~femadh.runner.sink.Committed` records (d, w, active, r_c, f_ex) as the files
    hold them. A fold bounds the bracket: the landing that starts a piece of the branch is
    its own previous neighbour, the last state before a fold its own next one
    (:func:`pieces`). ``within`` = (lo, hi) narrows the search to that part of the bracket (an
    estimate's member near the fine run's peak: fewer fresh states, the same absolute
    tolerance in d); ``reuse``: see :func:`state_between`. ``record``: a list the fresh
    states are appended to as (d, F or None, state or None). ``edge_stop`` (a fraction, with
    ``within``): :class:`WindowMiss` is raised as soon as the best fresh state so far lies
    within that fraction of the window's width of its edge (the optimum lies beyond the
    window: the search would only walk on to its edge). Returns (F, d, half-width of the
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
            if record is not None:
                record.append((d, None, None))
            return -f_best
        found[d] = state_forces(problem, st)[2]
        fresh.append(st)
        if record is not None:
            record.append((d, found[d], st))
        if edge_stop is not None and within is not None:
            top = max(found, key=found.get)
            if found[top] > f_best and min(top - lo, hi - top) <= edge_stop * (hi - lo):
                raise WindowMiss
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
    right at a committed state). The sink records them as the states arrive, by the rule of
    its peak bookkeeping (:meth:`femadh.runner.sink.Sink._piece`), and a resumed run's
    replay records them again."""
    return [(list(states), starts, ends)
            for states, starts, ends in getattr(sink, "curve_pieces", {}).get(branch, [])]


#: fresh states a :func:`kink_peak` may solve (the bounded search's maxiter)
KINK_MAX_EVALS = 40


def kink_peak(problem, prev, best, nxt, scene, known=(), window=None, reuse=False,
              f_of=None):
    """The largest F_ex between the grid states ``prev``, ``best``, ``nxt`` of one piece of a
    branch, to the same tolerance in d as :func:`peak_adhesion` (a final bracket of at most
    PEAK_XTOL_FRACTION of the grid bracket on each side of the best state), by a search that
    models the curve as it is on a discrete contact: smooth between the separations where a
    node joins or leaves the contact, with a kink at each (tests/test_kink_peak.py: the slider
    meniscus scene's members, F_ex(d) one kink at the maximum, slopes +1e4 and -2.7e4 N/m on
    either side, each side's slope changing 1 % in 2e-3 nm).

    Each step proposes the maximum of a model of the samples around the best one: the
    vertex of the parabola through the best sample and its neighbours where that parabola
    predicts the next samples out (a smooth maximum, :func:`_smooth_here`), else the point
    where the secants on either side meet (a kink, :func:`_kink_proposal`), each the other's
    fallback, else the midpoint of the wider side; a proposal within xatol / 2 of the best
    sample is moved to that distance on its side, so that once the model has found the
    maximum two states straddle it and close the bracket. A bounded Brent search spends its
    evaluations narrowing a golden-section bracket on such a curve (~15-19 fresh states per
    search; this search on the analytic kink of tests/test_kink_peak.py 14 from a cold
    start, on a parabola 4).

    ``known``: [(d, F or None, state or None)] solved already (a windowed search's). With
    ``window`` = (lo, hi), a window around the fine run's peak that missed (its best state
    at its edge): its ends are solved, and each side of the bracket outside it is searched
    where the curve rises away from the window or holds a state above the window's end there
    (both sides where the window holds a valley between two kinks); then the search refines
    around the best state found anywhere, inside the window or out. Fresh states as
    :func:`state_between` (``reuse``; warm starts from the nearest fresh state as
    :func:`peak_adhesion`); a state that is not found counts
    as no larger than the best and bounds the bracket. ``f_of``: F_ex of a grid state
    (default its ``f_ex``, else :func:`~femadh.contact.forces.state_forces`). Returns
    (F, d, xatol) as
    :func:`peak_adhesion`."""
    from ..contact.forces import state_forces

    def f_grid(s):
        if f_of is not None:
            return float(f_of(s))
        return float(s.f_ex if hasattr(s, "f_ex") else state_forces(problem, s)[2])

    lo, hi = sorted((prev.d, nxt.d))
    xatol = PEAK_XTOL_FRACTION * (hi - lo)
    f_best = f_grid(best)
    if not hi > lo:
        return f_best, float(best.d), xatol
    # samples {d: F} (None: no state there); the bracket's ends are the grid states (a
    # fold's last state is its own next neighbour: its side only)
    pts = {float(best.d): f_best}
    for s in (prev, nxt):
        if s.d != best.d:
            pts[float(s.d)] = f_grid(s)
    fresh = []
    for d, f, st in known:
        if lo <= d <= hi and d not in pts:
            pts[float(d)] = None if f is None else float(f)
            if st is not None:
                fresh.append(st)

    def solve(d):
        a, b = (prev, best) if nxt.d == best.d or (d - best.d) * (prev.d - best.d) > 0 \
            else (best, nxt)
        st = state_between(problem, a, b, d, scene, reuse, _warm(fresh, a, b, d))
        if st is None:
            pts[d] = None
            return
        fresh.append(st)
        pts[d] = float(state_forces(problem, st)[2])

    evals = [0]

    def refine(lo, hi):
        """The loop on the samples in [lo, hi]: the d of the best one at the end."""
        while evals[0] < KINK_MAX_EVALS:
            inside = sorted(x for x in pts if lo <= x <= hi)
            ds = [x for x in inside if pts[x] is not None]
            fs = [pts[x] for x in ds]
            i = max(range(len(ds)), key=lambda j: (fs[j], -abs(ds[j] - best.d)))
            b = ds[i]
            # the bracket around the best sample: its nearest samples either side (a failed
            # state counts as one no larger than the best: it bounds the bracket too)
            k = inside.index(b)
            a = inside[k - 1] if k > 0 else b
            c = inside[k + 1] if k + 1 < len(inside) else b
            if c - a <= xatol:
                return b
            # a smooth maximum where the parabola through the best sample and its
            # neighbours predicts the next samples out (the secants of a concave curve
            # also meet above it, but away from its maximum), else a kink
            if _smooth_here(ds, fs, i):
                x = _vertex_proposal(ds, fs, i, a, c)
                if x is None:
                    x = _kink_proposal(ds, fs, i, a, c, xatol)
            else:
                x = _kink_proposal(ds, fs, i, a, c, xatol)
                if x is None:
                    x = _vertex_proposal(ds, fs, i, a, c)
            if x is None:
                x = 0.5 * (a + b) if b - a > c - b else 0.5 * (b + c)
            # not closer to the best sample than xatol / 2 (the straddle that closes the
            # bracket), nor beyond the bracket
            if abs(x - b) < xatol / 2:
                x = b + math.copysign(xatol / 2, x - b if x != b else (c - b) - (b - a))
            if not a < x < c or x in pts:
                x = 0.5 * (a + b) if b - a > c - b else 0.5 * (b + c)
            if x in pts or not a < x < c:
                return b
            solve(x)
            evals[0] += 1
        return max((x for x in pts if lo <= x <= hi and pts[x] is not None),
                   key=lambda x: pts[x])

    if window is None:
        got = refine(lo, hi)
        return float(pts[got]), float(got), xatol
    # the bracket outside a window that missed: each side where the curve rises away from
    # the window (its end above the window's nearest state inside) or holds a state above
    # that end - both where the window holds a valley between two kinks (the slider
    # meniscus scene's 161-nm member at 1e-3: kinks 0.076 nm apart, the window between)
    w_lo, w_hi = max(lo, window[0]), min(hi, window[1])
    for d in (w_lo, w_hi):
        if d not in pts and evals[0] < KINK_MAX_EVALS:
            solve(d)
            evals[0] += 1
    for end, (s_lo, s_hi) in ((w_lo, (lo, w_lo)), (w_hi, (w_hi, hi))):
        if pts.get(end) is None or not s_hi > s_lo:
            continue
        inner = [x for x in pts if w_lo < x < w_hi and pts[x] is not None]
        near = min(inner, key=lambda x: abs(x - end), default=None)
        outer = [pts[x] for x in pts if s_lo <= x <= s_hi and x != end and pts[x] is not None]
        if (near is not None and pts[end] >= pts[near]) or any(f >= pts[end] for f in outer):
            refine(s_lo, s_hi)
    # then around the best state found anywhere, to the tolerance in d: a maximum inside
    # the window near its edge (the windowed search stopped there before it closed its
    # bracket) is refined as one outside it (the best sample instead fell short of the
    # analytic kink's maximum by up to 82 xatol at 0-20 % of the window inside its edge,
    # tests/test_kink_peak.py)
    got = refine(lo, hi)
    return float(pts[got]), float(got), xatol


def _kink_proposal(ds, fs, i, a, c, xatol):
    """The kink next to the best sample ds[i], or None: near a kinked maximum the curve is
    the lower of the two pieces' lines, F = min(L_in, L_out). For the kink between ds[i] and
    its neighbour on one side, L_in is the secant through ds[i] and its neighbour on the
    other side (the best sample's piece), L_out the secant through the neighbour on that side
    and the next one beyond it; its kink is where they meet. A meeting point beyond the two
    samples (by more than xatol / 2: the lines drawn through samples on other pieces) is no
    kink between them; one inside is moved to at least xatol / 2 from either sample (once
    both states straddling it are that close the bracket is closed). Of the two sides, the
    higher kink."""
    best = None
    for side in (-1, 1):
        j0, j1, j2 = i - side, i + side, i + 2 * side
        if not (0 <= j0 < len(ds) and 0 <= j1 < len(ds) and 0 <= j2 < len(ds)):
            continue
        s_in = (fs[i] - fs[j0]) / (ds[i] - ds[j0])
        s_out = (fs[j2] - fs[j1]) / (ds[j2] - ds[j1])
        if s_in == s_out:
            continue
        # F = fs[i] + s_in (x - ds[i]) = fs[j1] + s_out (x - ds[j1])
        x = (fs[j1] - fs[i] + s_in * ds[i] - s_out * ds[j1]) / (s_in - s_out)
        lo, hi = sorted((ds[i], ds[j1]))
        if not (a <= lo and hi <= c and hi - lo > xatol) or \
                not lo - xatol / 2 <= x <= hi + xatol / 2:
            continue
        x = min(max(x, lo + xatol / 2), hi - xatol / 2)
        f = min(fs[i] + s_in * (x - ds[i]), fs[j1] + s_out * (x - ds[j1]))
        if best is None or f > best[1]:
            best = (x, f)
    return None if best is None else best[0]


#: a parabola through three samples that predicts the next sample out on each side to this
#: fraction of the samples' rise to the best one is read as a smooth maximum
SMOOTH_FIT = 0.1


def _smooth_here(ds, fs, i):
    """Whether the parabola through the best sample ds[i] and its neighbours predicts the
    next sample out on either side (where there is one) to SMOOTH_FIT of the rise from the
    lowest of the five to the best: a smooth maximum. A kink between the samples bends
    the curve at one point, which no parabola through three of them follows."""
    if not (0 < i < len(ds) - 1):
        return False
    (x0, x1, x2), (f0, f1, f2) = ds[i - 1:i + 2], fs[i - 1:i + 2]

    def parabola(x):
        return (f0 * (x - x1) * (x - x2) / ((x0 - x1) * (x0 - x2))
                + f1 * (x - x0) * (x - x2) / ((x1 - x0) * (x1 - x2))
                + f2 * (x - x0) * (x - x1) / ((x2 - x0) * (x2 - x1)))
    outer = [j for j in (i - 2, i + 2) if 0 <= j < len(ds)]
    if not outer:
        return False
    rise = fs[i] - min(fs[j] for j in range(max(i - 2, 0), min(i + 3, len(ds))))
    return all(abs(parabola(ds[j]) - fs[j]) <= SMOOTH_FIT * rise for j in outer)


def _vertex_proposal(ds, fs, i, a, c):
    """The vertex of the parabola through the best sample and its neighbours where it is a
    maximum inside (a, c), else None."""
    if not (0 < i < len(ds) - 1):
        return None
    (x0, x1, x2), (f0, f1, f2) = ds[i - 1:i + 2], fs[i - 1:i + 2]
    s01, s12 = (f1 - f0) / (x1 - x0), (f2 - f1) / (x2 - x1)
    curv = (s12 - s01) / (x2 - x0)          # half the second derivative
    if not curv < 0:
        return None
    # F = f0 + s01 (x - x0) + curv (x - x0)(x - x1): dF/dx = 0
    x = 0.5 * (x0 + x1) - s01 / (2 * curv)
    return x if a < x < c else None
