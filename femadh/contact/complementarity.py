"""The sigma-gap as a complementarity condition (paper 1 eq 8), solved by semismooth Newton.

Complementarity (eq 8 as h >= sigma, p_c >= 0, (h - sigma) p_c = 0) is solved as a primal-dual
active-set (semismooth) Newton method on K w = P(h) - p_c. On the active set A the gap is fixed,
w_A = b_A - sigma, and p_c,A follows from the equation; on the inactive set I, p_c = 0 and

    (K_II + diag(P'(h_I))) dw_I = -(K w - P(h))_I,

a system of the size of the *free* surface only, so deep contacts get cheaper. The active set is
updated by  i in A  <=>  p_c,i + c (sigma - h_i) > 0, the semismooth Newton step of the
min-complementarity function. Convergence is declared on the residual of the original equation
w - C (P - p_c) (m) with an unchanged active set.

The linear systems. While the contact is a disk (nodes 0..m-1) with more than KRYLOV_MIN_FREE
free nodes, each Newton step solves diag(area)(K + diag P')_II dw = -area F_I by GMRES,
preconditioned by a Cholesky factor of the energy Hessian sym(S) + diag(area P') taken from a
margin inside the contact edge (:class:`~femadh.contact.linalg.TrailingCholesky`): the factor
of every trailing block is a leading part of it, so one factorisation serves the contact edge
as it moves node by node, for many states, and the Krylov iteration makes each step a Newton
step of the exact Jacobian (quadratic convergence) however stale the preconditioner (the
collocation Jacobian is not symmetric: 1.4 % of its norm on the Fig 4 grid). Elsewhere (any
other set, a small system, a Hessian that is not positive definite at an iterate off the
stable branch, eq 20's adhesion on the contact set) a trailing LU of the collocation Jacobian
takes chord steps (:class:`~femadh.contact.linalg.TrailingLU`), refactorised when the residual
stops falling by CHORD_RATE.

The stagnation exit (``stall_iter``, opt-in) ends a solve that has not halved its residual
for STALL_ITER iterations: a continuation step across a fold, where no equilibrium is near
the prediction, is then halved after ~10 iterations instead of 40.

Stability of a converged state: :mod:`femadh.contact.stability` (the energy Hessian's inertia).
"""
import math
import weakref

import numpy as np

from ..interrupt import check as safe_point
# (the LU through femadh.contact.linalg's direct LAPACK calls, the bits of scipy's lu_factor
# and lu_solve without their wrappers; read as linalg.lu_factor at the call, so that a test
# counting factorisations patches one name for both the corrector's and TrailingLU's)
from . import linalg
from .linalg import TrailingCholesky, TrailingLU, disk_size, gmres
from .stability import is_stable, refuted_positive_definite
from .state import State
from .subgrid import add_jacobian, apply_jacobian, jacobian_row_sums

#: a chord step (reused factorisation) must cut the residual at least by this factor
CHORD_RATE = 0.05
#: above this many nodes a refactorisation (O(N^3)) costs more than many chord steps (O(N^2)):
#: a chord step there need only cut the residual by CHORD_RATE_LARGE (N = 1600: 35 -> 10
#: factorisations, 8.5 -> 6.9 s for the Fig 3 sweep; at N = 200 the strict rate is faster)
LARGE_N, CHORD_RATE_LARGE = 600, 0.15
#: largest fraction of the current gap one Newton step may close (keeps h > 0 for LJ)
MAX_GAP_CLOSURE = 0.8
#: stagnation exit: a solve whose residual has not fallen below STALL_FACTOR of its last
#: progress mark for STALL_ITER iterations (while its contact disk does not move steadily
#: one way) gives up: there is no equilibrium near the prediction (a step across a fold).
#: Measured on the Fig 4 scene (285 nodes): converging solves mark progress every 1-3
#: iterations (slowest: the x0.7 linear descent while the edge moves node by node, and the
#: disk then moves one way); the 15 solves across a fold that ran to max_iter = 40 hovered
#: within a factor 2 of 1e-13 or cycled their contact edge back and forth from iteration 3 on
STALL_ITER, STALL_FACTOR = 8, 0.5


def _damping(h, dh_closing):
    """Step length in (0, 1] so that no gap closes by more than MAX_GAP_CLOSURE of itself."""
    closing = dh_closing > 0
    if not closing.any():       # (the array's own reductions: np.any's dispatch costs more)
        return 1.0
    return float(min(1.0, (MAX_GAP_CLOSURE * h[closing] / dh_closing[closing]).min()))


def _effect_pressures(problem, h, A=None):
    """Each law's pressure at gaps h; with the eq 20 adhesion on the contact set (A), its
    P_LJa on the contact nodes as "asperity_adhesion"."""
    out = problem.effect_pressures(h)
    adh = problem.gap.adhesion if problem.gap is not None else 0.0
    if adh and A is not None:
        out["asperity_adhesion"] = np.where(A, adh, 0.0)
    return out


def _residual(problem, w, p_net):
    """max |w - C p_net| (m): the residual of eq (6)/(10)."""
    return float(np.abs(w - problem.C @ p_net).max())


#: extra nodes factorised inside the contact edge so a shrinking contact stays covered
DISK_MARGIN_FRACTION = 0.05
#: Newton steps on a disk-shaped active set by preconditioned GMRES (False: the LU path only).
#: Not with eq 20's adhesion on the contact set: a contact node then holds a tension up to
#: P_LJa, so a node at the edge is stable both in and out of contact and the set a corrector
#: reaches depends on its iterates (the Fig 8 scene's approach: the Krylov steps reached
#: states one node apart from the LU path's, r_c at zero force 2 % off, about its estimated
#: error); there the established LU path keeps the states it always found
KRYLOV = True
#: relative residual of the linear Newton system GMRES reaches: an inexact Newton step whose
#: error is 1e-6 of the step (quadratic convergence holds down to the tolerance: from a
#: predictor residual of ~1e-12 m the next step's 1e-18 m is below the scenes' 1e-19 m... the
#: step after it)
GMRES_RTOL = 1e-6
#: ... on disks with more free nodes than this: a smaller LU costs less than the Python of a
#: few Krylov iterations (measured, cpu time of the sweeps: Fig 8's N = 100 member 0.20 s all
#: Krylov, 0.15 s with this floor; Fig 4's 142-node member 0.67 -> 0.60 s; its 285 nodes
#: 1.47 s either way, against 1.71 s without Krylov)
KRYLOV_MIN_FREE = 150
#: relative residual GMRES reaches on the first Newton step at an active set (the solve's
#: first iterate, and each iterate after the set changed): an inexact Newton step. Its linear
#: error, 1e-4 of the step, is below the error Newton's own quadratic term leaves: the
#: residual there is ~1e-12-1e-10 m on displacements of ~1e-9 m (relative 1e-3-1e-1, whose
#: square is 1e-6-1e-2 of the step), so the step converges as fast; the later iterates at an
#: unchanged set solve to GMRES_RTOL. Most such steps are left at once: a contact unzipping
#: node by node releases one node per iteration in a retract. Measured on the Fig 4 scene at
#: accuracy 1e-3, its 493-node retract: Krylov iterations 4065 -> 2764, Newton iterations
#: 780 -> 663 (its fold search near the pull-off: one trial converged on another contact
#: set, two solves fewer; every grid state the same within 4e-22 m); every bundled scene's
#: headline numbers move by < 5e-7 of their estimated errors (validation/results/corrector.md)
GMRES_RTOL_NEW_SET = 1e-4
#: the Krylov products K_II v of the corrector's Newton steps in single precision (a float32
#: copy of K, :func:`_krylov_product`): the products read K whole, ~1/2 of the Krylov
#: iteration's time on the grids of the accuracy goals (K_II v at 867 nodes 330 us in double,
#: 150 us in single; 493 nodes 43 and 23 us), and single precision halves the bytes read.
#: Only GMRES's operator moves: the product's relative error, 1.1e-7 on a random vector and
#: 1.6e-6 on a contact state's smooth w (K's rows nearly cancel on it), leaves a Newton step
#: within 4.4e-7 of the double one's (the Fig 4 disk, tests/test_pace.py): still an inexact
#: Newton step of the exact Jacobian to ~GMRES_RTOL. The residual of eq (6)/(10) that
#: convergence is declared on, K w and the tangent stay in double. Measured
#: (validation/results/pace.md): Fig 3 at accuracy 1e-4 Newton iterations 467 -> 469, Krylov
#: 1760 -> 1805; Fig 4 at 1e-3 2476 -> 2476, 10 309 -> 10 350; every bundled scene's headline
#: within 1e-6 of its estimated error (most within 1e-9; five scenes bit-identical)
KRYLOV_SINGLE = True
#: the float32 copies of K, by problem (:func:`_single_k`)
_SINGLE = weakref.WeakKeyDictionary()
#: an iteration whose new active set only releases nodes carries its gaps, pressures and
#: K w to the next (False: recomputed from w, the same bits - tests/test_corrector.py)
CARRY_RELEASES = True


def solve_complementarity(problem, d, w0, *, tol, max_iter, active0=None, factor=None,
                          stall_iter=None, stats=None):
    """Equilibrium at separation d (m) from displacements w0 (m): semismooth Newton on the
    sigma-gap complementarity problem (without a gap, Newton on eq 6).

    Returns a :class:`State` whose ``converged`` flag tells whether ``residual <= tol`` was
    reached within ``max_iter`` iterations; never raises for non-convergence (the continuation
    decides what to do). ``active0`` is the predicted active set.

    ``factor`` = (lu, inactive mask) of an earlier Jacobian: while the active set equals that
    mask the factorisation is reused (chord steps), and refreshed only when the residual stops
    falling by CHORD_RATE per step. The LJ stiffness P'(h) is a small, slowly varying diagonal
    next to K, so chord steps converge almost as fast as Newton steps at a fraction of the cost.

    ``stall_iter``: iterations without progress after which the solve gives up (the
    continuation's trial steps pass STALL_ITER; None, the default: run to ``max_iter``, for a
    decision that must not be cut short - a fold, a landing, a state of the estimate). A
    stagnated state says so in ``diagnostics["stagnated"]`` (iterations, residual, best
    residual); converged states carry no diagnostics. ``stats`` (dict, optional) accumulates
    the work done: "solves", "iterations", "factorisations" and "stagnated" (solves that
    gave up); with a "history" list in it, each iteration appends (residual (m), active
    nodes, active set unchanged, the active set itself as ``A.tobytes()`` - two sets of one
    size told apart, :func:`femadh.contact.snap.cycling`).
    """
    K, b = problem.K, problem.contour(d)
    sigma = problem.sigma
    adhesion = problem.gap.adhesion if problem.gap is not None else 0.0
    n = b.size
    chord_rate = CHORD_RATE_LARGE if n > LARGE_N else CHORD_RATE
    w = np.array(w0, dtype=float)
    if sigma is None:
        A = np.zeros(n, bool)
    elif active0 is not None:
        A = active0.copy()
    else:
        A = b - w < sigma
    seen = set()
    pre = factor if isinstance(factor, TrailingCholesky) else None
    if isinstance(factor, TrailingLU):
        lu, lu_I = factor, None
    elif pre is not None:
        lu, lu_I = None, None
    else:
        lu, lu_I = factor if factor is not None else (None, None)
    fresh = False
    res, res_prev, it = math.inf, math.inf, 0
    n_factor, res_it = 0, math.inf
    mark, it_mark, m_trend, m_last = math.inf, 0, 0, int(A.sum())
    # the active set's bytes: two boolean sets are equal exactly when their bytes are (0 or
    # 1 each), which the cycle test needs anyway - one comparison of bytes per iteration
    # in place of np.array_equal's three or four
    A_key = A.tobytes()
    stagnated = None
    # (h, P, K w) after the last step: the next iteration's own when its active set is the
    # same or a part of it - only releases (w on the set was put at b - sigma when the set
    # was entered and the step moves the free nodes alone, so w, h and the products are those
    # bits: a contact unzipping node by node at its edge, one release per iteration, skips
    # a product with K and a pressure evaluation per iteration)
    carried = None
    for it in range(1, max_iter + 1):
        # a signal (or the time limit) stops the run here, between iterations: nothing of
        # this state is on disk yet (femadh.interrupt)
        safe_point()
        I = ~A
        if carried is not None:
            h, P, Kw = carried
        else:
            if sigma is not None:
                w[A] = b[A] - sigma
            h = b - w
        if (h[I] <= 0).any():
            break  # the guess put the surfaces through each other: hopeless, report failure
        if carried is None:
            P = problem.pressure(h)
            Kw = K @ w
        F_I = Kw[I] - P[I]
        m = disk_size(A)
        dw = None
        if m is not None and KRYLOV and not adhesion and n - m > KRYLOV_MIN_FREE:
            # a disk: a Newton step solved by GMRES on the exact Jacobian, preconditioned by
            # a Cholesky of the energy Hessian that covers every disk from its margin on
            dw, pre, nf = _krylov_step(problem, h, A, m, F_I, pre,
                                       GMRES_RTOL_NEW_SET if res == math.inf else GMRES_RTOL)
            n_factor += nf
            if dw is not None:
                fresh = "krylov"
        if dw is None:
            dw, lu, lu_I, fresh, res_prev, nf = _lu_step(problem, h, A, I, m, F_I, lu, lu_I,
                                                         fresh, res, res_prev, tol, chord_rate)
            n_factor += nf
        alpha = _damping(h[I], dw)
        w[I] += alpha * dw
        h = b - w
        P = problem.pressure(h)
        pc = np.zeros(n)
        carried = None
        if sigma is not None:
            Kw = K @ w
            pc[A] = P[A] - Kw[A]
            # a contact node stays while its asperities push (lambda = pc + P_LJa > 0: with
            # eq 20 on the contact set it holds a net tension up to P_LJa) ...
            new_A = (A & (pc + adhesion > 0)) | (I & (h < sigma))
        else:
            new_A = A
        res = _residual(problem, w, P - pc)
        key = new_A.tobytes()
        same = key == A_key
        if stats is not None and "history" in stats:
            stats["history"].append((res, int(A.sum()), same,
                                     A.tobytes()))
        if same and res <= tol and alpha == 1.0:
            factor = (pre if fresh == "krylov" else lu if isinstance(lu, TrailingLU)
                      else (lu, lu_I))
            _count(stats, it, n_factor, False)
            return _finish(problem, d, w, h, pc, A, it, res, factor, fresh)
        res_it = res
        new_key = key
        if key in seen and not same:
            # The active set cycles (non-convex LJ near the contact edge): accept only the
            # additions/removals adjacent to the current contact boundary to break the cycle.
            new_A = _restrict_change(A, new_A)
            new_key = new_A.tobytes()
            same = new_key == A_key
        seen.add(key)
        if sigma is not None and (same or
                                  CARRY_RELEASES and not np.any(new_A & I)):
            carried = (h, P, Kw)
        if not same:
            # a new active set: its first residual is not comparable with the last one, so
            # the next step is not a stall (a trailing LU that covers the new disk is reused
            # rather than refactorised: the contact edge moves node by node along a sweep)
            res, res_prev = math.inf, math.inf
        A, A_key = new_A, new_key
        # progress: the residual halves against its mark, or the contact disk keeps moving
        # one way (an edge advancing node by node at a flat residual)
        m_new = int(A.sum())
        step_dir = (m_new > m_last) - (m_new < m_last)
        steady = step_dir != 0 and step_dir == m_trend
        m_trend, m_last = (step_dir or m_trend), m_new
        if res_it < STALL_FACTOR * mark or steady:
            mark, it_mark = min(res_it, mark), it
        elif stall_iter is not None and it - it_mark >= stall_iter:
            stagnated = {"d_m": d, "iterations": it, "residual_m": res_it,
                         "best_residual_m": mark, "since_iteration": it_mark}
            break
    h = b - w
    pc = np.zeros(n)
    if sigma is not None and np.all(h[~A] > 0):
        pc[A] = problem.pressure(h)[A] - (K @ w)[A]
    _count(stats, it, n_factor, stagnated is not None)
    st = State(d, w, h, _effect_pressures(problem, np.maximum(h, 1e-300), A),
               _contact_pressure(problem, pc, A), A,
               _area_radius(problem, A), it, res_it, False, False, None)
    if stagnated is not None:
        st.diagnostics["stagnated"] = stagnated
    return st


def _krylov_step(problem, h, A, m, F_I, pre, rtol=GMRES_RTOL):
    """A Newton step dw on the free nodes m..n-1 of a disk contact: GMRES on the area-scaled
    Jacobian diag(area)(K + diag(P'(h)))_II, preconditioned by ``pre`` (a
    :class:`TrailingCholesky` of the energy Hessian), refreshed at h when it does not cover
    the disk or GMRES does not reach ``rtol`` (its relative residual: GMRES_RTOL, or
    GMRES_RTOL_NEW_SET on the first step at an active set) within its Krylov dimension.

    Returns (dw or None, preconditioner, factorisations); None when the Hessian at h is not
    positive definite on the free nodes (an iterate off the stable branch): the LU path
    takes the step."""
    n = h.size
    D = problem.law_jacobian(h)     # a vector; a tridiagonal matrix with a sub-grid law
    a = problem.areas[m:]
    fr = slice(m, None)
    product = _krylov_product(problem, m)

    if D.ndim == 1:
        D_I = D[fr]     # apply_jacobian's own product, its slice taken once per step

        def apply_a(v):
            return a * (product(v) + D_I * v)
    else:
        def apply_a(v):
            return a * (product(v) + apply_jacobian(D, fr, v))

    rhs = -a * F_I
    n_factor = 0
    # a refresh deferred at an earlier iterate (:func:`deferred_refresh`) is factorised by
    # covers(m) where its answer needs the factor: that Cholesky is this step's work (not
    # counted before: over a whole Fig 4 run at accuracy 1e-3 stats["factorisations"] said
    # 699 of the 793 factorisations its solves made, the 94 missing all such)
    late = isinstance(pre, TrailingCholesky) and pre.deferred
    covered = isinstance(pre, TrailingCholesky) and pre.covers(m)
    n_factor += int(late and not pre.deferred)
    for attempt in range(2):
        if attempt or not covered:
            # held nodes of the margin enter with D = 0 (they are fixed; when released the
            # Krylov iteration corrects their stiffness)
            m0 = max(0, m - max(4, int(DISK_MARGIN_FRACTION * n)))
            if refuted_positive_definite(problem, D, m):
                # the refreshed factor would cover no block from m (the Hessian at h is not
                # positive definite on the free nodes): made only if a smaller free set
                # asks for it later and is not refuted the same way, as it would have been
                # made here
                return None, deferred_refresh(problem, D, A, m0, m), n_factor
            pre = TrailingCholesky(problem.S_sym, problem.areas, _held_zero(D, A), m0)
            n_factor += 1
            if not pre.covers(m):
                return None, pre, n_factor
        dw, _, ok = gmres(apply_a, lambda r: pre.solve(m, r), rhs, rtol)
        if ok:
            return dw, pre, n_factor
    return None, pre, n_factor


def _krylov_product(problem, m):
    """v -> K[m:, m:] v for the Krylov iteration of a Newton step: in single precision with
    KRYLOV_SINGLE (the product's float32 copy of K kept per problem, :func:`_single_k`),
    else K's own double product."""
    if not KRYLOV_SINGLE:
        K_II = problem.K[m:, m:]
        return K_II.__matmul__
    K_II = _single_k(problem)[m:, m:]
    single = np.float32

    def product(v):
        return (K_II @ v.astype(single)).astype(float)
    return product


def _single_k(problem):
    """The float32 copy of ``problem.K``, made once per problem (and again if its K is
    replaced): 4 bytes a coefficient beside K's 8."""
    held = _SINGLE.get(problem)
    if held is None or held[0] is not problem.K:
        held = (problem.K, np.asarray(problem.K, dtype=np.float32))
        _SINGLE[problem] = held
    return held[1]


def deferred_refresh(problem, D, A, m0, m):
    """The Krylov preconditioner's refresh at an iterate whose Hessian on the free nodes
    m..n-1 is refuted positive definite (:func:`refuted_positive_definite`; D the law
    Jacobian at the iterate, A its contact set): a :class:`TrailingCholesky` of the same
    arrays from m0 whose factorisation waits until a smaller free set asks for it and is
    not refuted in turn."""
    n = D.shape[0]
    return TrailingCholesky(problem.S_sym, problem.areas, _held_zero(D, A), m0, not_pd=n - m,
                            refutes=lambda k: refuted_positive_definite(problem, D, n - k))


def _lu_step(problem, h, A, I, m, F_I, lu, lu_I, fresh, res, res_prev, tol, chord_rate):
    """A chord or Newton step dw on the free nodes from an LU of the collocation Jacobian
    K_II + diag(P'(h_I)): a trailing LU of the disk (reused while it covers the disk and the
    residual falls by ``chord_rate`` per step), or of the free block of any other set - the
    corrector as it was before the Krylov steps, kept as it was: on a lattice-trapped grid
    (a law softening beyond a node's stiffness) the states reached depend on the iterates,
    and these keep the ones it always reached. (Measured and not landed: a trailing LU that
    covers its own block whatever its pivoting, with the held margin nodes at D = 0, halves
    the LU count of Fig 4's approach, but on the 1 %-smoothed eq 20 slider at N = 100 it
    reaches other lattice states: 7 jumps instead of 4.)
    Returns (dw, lu, lu_I, fresh, res_prev, factorisations)."""
    K, n = problem.K, h.size
    n_factor = 0
    # near the tolerance the residual approaches round-off and no step cuts it by
    # CHORD_RATE; there a chord step only has to keep making progress
    stalled = res > (chord_rate if res > 100 * tol else 0.7) * res_prev
    if m is not None:
        if not (isinstance(lu, TrailingLU) and lu.covers(m)) or stalled:
            m0 = max(0, m - max(4, int(DISK_MARGIN_FRACTION * n)))
            cand = TrailingLU(K, problem.law_jacobian(h), m0, problem.areas)
            n_factor += 1
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
        if isinstance(lu, TrailingLU) or _other_set(I, lu_I) or lu is None or stalled:
            idx = I.nonzero()[0]     # (np.flatnonzero of a 1-D mask, without its dispatch)
            # the free block in LAPACK's (Fortran) order, factorised in place: its rows
            # gathered (each a contiguous copy), then its columns, laid out in Fortran order -
            # the same values and layout as K.T's fancy-indexed block transposed, at a third
            # of its cost (0.37 against 1.2 ms for 393 of 493 nodes)
            M = np.asfortranarray(K[idx][:, idx])
            add_jacobian(M, problem.law_jacobian(h), idx)
            lu, lu_I, fresh = linalg.lu_factor(M, overwrite_a=True), I, True
            n_factor += 1
            res_prev = math.inf
        else:
            res_prev = res
        dw = -linalg.lu_solve(lu, F_I)
    return dw, lu, lu_I, fresh, res_prev, n_factor


def _other_set(I, lu_I):
    """not np.array_equal(I, lu_I) for the free-node masks (lu_I a mask of the same nodes, or
    None), without its conversions."""
    return lu_I is None or lu_I.shape != I.shape or bool((I != lu_I).any())


def _count(stats, iterations, factorisations, stagnated):
    """Add one solve's work to ``stats`` (a dict, or None: not counted)."""
    if stats is None:
        return
    stats["solves"] = stats.get("solves", 0) + 1
    stats["iterations"] = stats.get("iterations", 0) + iterations
    stats["factorisations"] = stats.get("factorisations", 0) + factorisations
    stats["stagnated"] = stats.get("stagnated", 0) + int(stagnated)


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
    return State(d, w, h, _effect_pressures(problem, h, A), _contact_pressure(problem, pc, A),
                 A.copy(), _area_radius(problem, A), it, res, True, is_stable(problem, h, ~A),
                 factor)


def _held_zero(D, A):
    """The law Jacobian with the held (contact) nodes' rows and columns zeroed: they enter
    the preconditioner with their stiffness alone."""
    if D.ndim == 1:
        return np.where(A, 0.0, D)
    out = D.copy()
    out[A] = 0.0
    out[:, A] = 0.0
    return out


def _contact_pressure(problem, pc, A):
    """The asperities' elastic (repulsive) pressure lambda >= 0 on the contact nodes: the net
    contact traction pc plus the eq 20 adhesion they carry (pc alone without it)."""
    adh = problem.gap.adhesion if problem.gap is not None else 0.0
    return pc + adh * A if adh else pc


def tangent(problem, state):
    """dw/dd at a converged complementarity state, with its active set frozen (m/m).

    From K w = P(b - w) - p_c with db/dd = 1: on A, dw/dd = 1; on I,
    (K_II + D_I) t_I = D_I - K_IA 1. Reuses the corrector's factorisation.
    """
    A = state.active
    I = ~A
    t = np.ones(state.w.size)
    D = problem.law_jacobian(state.h)
    # with a sub-grid law J_II 1 (a free node's pressure also moves with its free
    # neighbours' gaps; the held nodes' gaps stay at sigma)
    m = disk_size(A)
    # K_IA 1: on a disk the block K[m:, :m], copied by slicing (contiguous rows: the same
    # array, so the same sums, as the fancy-indexed copy, at a tenth of its cost)
    K_IA = (np.ascontiguousarray(problem.K[m:, :m]) if m is not None
            else problem.K[np.ix_(I, A)])
    rhs = jacobian_row_sums(D, I) - K_IA.sum(axis=1)
    if isinstance(state.lu, TrailingCholesky) and m is not None and state.lu.covers(m):
        a, K_II = problem.areas[m:], problem.K[m:, m:]
        t_I, _, ok = gmres(lambda v: a * (K_II @ v + apply_jacobian(D, slice(m, None), v)),
                           lambda r: state.lu.solve(m, r), a * rhs, GMRES_RTOL)
        if not ok:
            return np.zeros(state.w.size)  # no converged solve: zeroth order
        t[I] = t_I
        return t
    if isinstance(state.lu, TrailingCholesky):
        return np.zeros(state.w.size)
    if isinstance(state.lu, TrailingLU) and m is not None and state.lu.covers(m):
        t[I] = state.lu.solve(m, rhs)
        return t
    if isinstance(state.lu, TrailingLU) or state.lu is None:
        return np.zeros(state.w.size)  # no factorisation of this set at hand: zeroth order
    lu, lu_I = state.lu
    if lu_I is None or not np.array_equal(lu_I, I):
        return np.zeros(state.w.size)  # no factorisation of this set at hand: zeroth order
    t[I] = linalg.lu_solve(lu, rhs)
    return t
