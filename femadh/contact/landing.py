"""Where the surface lands after a fold: descent of the total energy (a quasi-static surface
slides downhill into the basin it rolls into), polished by Newton."""
import numpy as np
from scipy import linalg as sla

from ..interrupt import check as safe_point
from .complementarity import MAX_GAP_CLOSURE, STALL_ITER, solve_complementarity
from .subgrid import add_jacobian
from .linalg import (cho_factor, cho_factor_single, cho_solve, cho_solve_single, lu_factor,
                     lu_solve, pcg)

#: descent steps in a row that lower the energy by no more than its round-off after which the
#: descent has settled in its basin (Newton polishes from there). Measured on the Fig 4 scene
#: (632 nodes, the jump-in at d = 1.1098 nm): the basin's minimum is reached in 22 steps (the
#: gradient from 1 to 8e-10 of its start), after which no step lowers the energy by more than
#: 2 ulps of it, and the descent used to spin at round-off up to its cap of 400 steps (723
#: Cholesky factorisations, 6 s: a quarter of the run at accuracy 1e-3)
ROUNDOFF_STEPS = 3
#: the energy's round-off: this many ulps of the magnitudes of its elastic and interaction parts
ROUNDOFF_ULPS = 64
#: a trial step whose energy rises by no more than its round-off counts towards
#: ROUNDOFF_STEPS as a flat step does (the descent stays where it is and raises its damping).
#: Measured on the Fig 4 scene at accuracy 1e-3 (validation/results/fig4solve.md): after
#: the descent had settled, its damping was raised x4 from 1e-8 up to 20 times in a row on
#: rises of 0-28 ulps of the energy's magnitudes (its round-off is taken at 64): the energy
#: could not tell those points apart. Counting them: the descents' Cholesky factorisations
#: 315 -> 243 on its 279-node run, 312 -> 278 on the 595-node one
ROUNDOFF_REJECTS = True
#: pseudo-time steps the relaxation of the collocation equations may take (:func:`_relax`).
#: Measured on the 2-mm slider at sigma = 0.3 nm, p/psat = 0.05 (253 nodes, 26 nm band
#: spacing): the drift past the vanished equilibrium of the descent's contact set took 60
#: steps, the convergence on the next set 55 more (43 steps in all with the damping below).
#: Started far from a landing, from held equilibria on disks of 85, 86, 88, 92 and 100
#: nodes, it lands on the same 84-node state in 22, 36, 67, 116 and 191 steps
RELAX_STEPS = 400
#: pseudo-time damping mu (relative to the diagonal of S) while the residual is at its
#: largest on the current contact set, and its floor. On a set, mu follows the residual's
#: progress from that largest value, mu = RELAX_MU0 min(1, r / r_set) (switched evolution
#: relaxation referred to the set's running largest residual r_set), never above RELAX_MU0.
#: Why not mu_k+1 = mu_k r_k / r_k-1 clamped to [1e-14, 1e6] (the rule before): a node
#: released from a converged state (1.6e-25 m) raised the residual to 1.70e-12 m and mu to
#: its ceiling, after which each step moved the surface by ~1e-6 of a Newton step,
#: r_k / r_k-1 stayed 1 and mu never came down (the 85-100-node disks of test_landing_relax's
#: corner case: 400 steps, no state). A residual that rises on a set is the drift past a
#: vanished equilibrium the relaxation is there to make, not a divergence (a closing step is
#: bounded by MAX_GAP_CLOSURE of the gap; an opening one is not: measured <= 7.6e-11 m)
RELAX_MU0, RELAX_MU_MIN = 1.0, 1e-14
#: where none of the neighbouring edges (EDGE_SHIFTS, below) polishes a landing, the edges
#: farther out, EDGE_SHIFTS' largest + 1 up to this many nodes (both ways, nearest first;
#: the first distance that gives a stable state is kept). Measured on the 2-mm slider at
#: sigma = 0.3 nm, p/psat = 0.05 (512 nodes, 1.71-nm follow band, the retract's micro-fold
#: at d = 1.76836 nm, 157 contact nodes before it, validation/results/sigma03_pulloff.md):
#: the descent settled on 156 nodes and Newton cycled at a residual of 2.3e-16 m from every
#: disk of 153-159 nodes (the landing failed and ended the run); from 151 nodes (the
#: descent's - 5) it converged in 6 iterations on a stable state of 155 nodes, from 149 and
#: 150 on others farther off. An empty EDGE_SHIFTS turns this scan off with the neighbouring
#: edges
EDGE_SCAN = 8
#: and where none of those polishes either, the separated state (:func:`_separated`)
SEPARATED = True
#: contact edges next to the descent's (nodes added or released at the edge of a disk-shaped
#: contact set, in this order) from which the corrector polishes a landing that neither the
#: descent's own set nor the relaxation polished. Measured on the sigma = 0.3 nm slider (507
#: nodes, 13 nm band spacing), the fourth fold of its approach: the descent settled on 150
#: contact nodes, where the collocation form's root has vanished; the relaxation drifted
#: past that ghost for its 400 steps (residual ~1e-15 m); from 151 nodes Newton converged in
#: 6 iterations on a stable state
EDGE_SHIFTS = (1, -1, 2, -2)
#: a single node's snap (a contact unzipping node by node, issue 21) landed first by the
#: corrector from the last state's surface with its contact disk moved by this many nodes the
#: way the edge goes (:func:`land_next_node`), before the energy descent. Measured on the
#: sigma = 0.3 nm slider's flat retract (issue 21, sigma03_follow.md): from the disk two nodes
#: smaller Newton reached the descent's own landing in 5-8 iterations at 7 of 9 micro-folds
#: whose descent and relaxation took 8.7-18 s, from one node smaller it ran to its budget;
#: on the sigma = 0.489 nm slider (validation/results/snap_cost.md) two nodes smaller
#: converged in 5-6 iterations (re-adding one), one smaller stalled after 9
NEXT_NODE_SHIFTS = (2, 1)
#: corrector iterations each of those starts may take (the converged ones took 2-8)
NEXT_NODE_ITER = 12
#: a smooth law's landing whose polish fails (no sigma-gap: no contact set, relaxation or
#: separated state above) is polished from the descent's minimum with its contact edge moved
#: by EDGE_SHIFTS nodes, then farther out up to EDGE_SCAN (:func:`_smooth_edges`). Measured on
#: the 100-node GW slider of tests/test_topography.py (softening 6.3x a node's stiffness,
#: the approach's landing at d = 1.05762 nm) with the Green operator's far field by the AGM
#: (its last bits moved, validation/results/landrobust.md): the descent settled on 35 contact
#: nodes (an energy minimum, stable), the collocation form's residual there 7e-13 m; Newton
#: hovered at 1e-13 m for ~60 iterations and then diverged to 5e-8 m (the run failed), the
#: pseudo-time relaxation ran its 400 steps without settling; with main's operator Newton
#: wandered 75 iterations onto the state with node 35 snapped in (36 contact nodes). False:
#: such a landing fails as before
SMOOTH_EDGES = True
#: points of the straight path from the descent's start to a candidate landing at which the
#: energy must fall monotonically (no barrier: the descent's surface can slide there)
PATH_SAMPLES = 16
#: free nodes from which the descent's damped steps are solved by conjugate gradients in
#: double precision preconditioned by a single-precision Cholesky factor (:class:`_Damped`)
#: instead of the double factorisation. Measured on one core (AMD EPYC, median of 7): the
#: double factorisation and solve against the single one and 3 iterations 0.33 / 0.22 ms at
#: 300 nodes, 2.0 / 1.3 ms at 600, 98 / 57 ms at 2500; at 100 nodes 0.02 / 0.04 ms (the
#: iterations' Python overhead). Only in the descent that stops once settled at round-off:
#: the whole descent, run on a lattice-trapped grid and as the retry after a polish that
#: failed, keeps the double factorisation bit for bit, because there the states reached
#: depend on the iterates (on the 100-node GW slider of tests/test_landing_smooth_edges.py
#: the single path, forced, polished the landing that the double path's descent leaves
#: stalled)
SINGLE_MIN_NODES = 300
#: the iterations' relative residual |r| / |grad| (2-norms): the double solve's own accuracy
#: (measured on the Fig 4 scene's descents at 1396 nodes: the steps agree with the double
#: factorisation's to 1e-15 - 3e-12 relative, as two double solves of these systems do)
SINGLE_RTOL = 1e-13
#: iterations a step may take from a fresh single factor (measured 3-5, SINGLE_RTOL met)
#: before the trial falls back to the double factorisation (which then also decides whether
#: the damped Hessian is positive definite)
SINGLE_ITER = 10
#: iterations a trial may take from the factor kept from an earlier trial (another damping,
#: the Hessian of an earlier step on the same free nodes or on more of them) before a fresh
#: factor is made: one per REUSE_NODES free nodes, at least REUSE_MIN. Each costs a product
#: with the Hessian and two single triangular solves; a single factorisation of k nodes
#: costs ~k/45 of them (measured on one core: 16 at 600 nodes, 32 at 1500, 52 at 2800), so
#: a kept factor that does not converge costs at most about half a factorisation. Measured
#: on the Fig 4 scene's descents (1396 nodes): 4-10 iterations from the last step's factor
#: once the damping is below 1e-4, 15-27 above 1e-3 (where a factor's damping, 3x the
#: trial's, still dominates the Hessian's softer modes)
REUSE_NODES, REUSE_MIN = 100, 4


class _Damped:
    """The damped Newton systems (H + lam diag(s)) dw = rhs of the descent's steps (H the
    energy Hessian on the step's free nodes, N/m; s the diagonal of sym(S) on them), solved
    by conjugate gradients in double precision (:func:`femadh.contact.linalg.pcg`)
    preconditioned by a single-precision Cholesky factor.

    Why: the double factorisation of each trial was most of the descent (measured on the Fig
    4 scene at accuracy 1e-4: 346 factorisations of ~1770 free nodes, 15 of the descents'
    24 s). Single precision (LAPACK spotrf) takes half the time, and a few double
    iterations make its solution the double system's (the residual to SINGLE_RTOL); between
    steps only the law's diagonal and the damping move (the elastic block sym(S) is the same
    while the free nodes are), so a factor kept from an earlier trial preconditions the next
    ones in a few iterations. The step stays the damped Newton step of the double system,
    and its energy is checked in double as before.

    Each trial first tries the kept factor (REUSE_NODES, REUSE_MIN): if an iteration meets a
    direction of non-positive curvature (p . A p <= 0 in double), the damped Hessian is not
    positive definite - the trial is refused as the double factorisation's failure refused it
    (:meth:`solve` returns NOT_PD: raise the damping), without a factorisation; a breakdown
    of the preconditioner or a NaN proves nothing and goes on to a fresh factor. Else a fresh
    single factor of the trial's matrix is made: its failure (LAPACK's info: not positive
    definite, or only beyond single precision's ~1e7 condition) and its iterations'
    (SINGLE_ITER) failure - a direction of non-positive curvature, a breakdown, the budget
    spent - return None: the caller decides with the double factorisation as before. A step
    is returned only where the iterations met SINGLE_RTOL with positive curvature on every
    direction (the Hessian positive definite on the Krylov space that resolves the gradient
    to SINGLE_RTOL) and it is a descent direction, grad . dw < 0.

    The factor is kept in reversed node order: where the free nodes are the trailing block
    m..n-1 (a disk-shaped contact), each smaller trailing block is a leading block of it,
    whose factor is the leading part of the factor (as
    :class:`femadh.contact.linalg.TrailingCholesky`'s), so a
    contact that grows by a node keeps its preconditioner.
    """

    NOT_PD = "not positive definite"

    def __init__(self, s):
        self.s_all = s          # the diagonal of sym(S) on every node (N/m)
        self.kept = None        # (factor, free mask, m or None) in reversed node order
        self._block = None      # (k, the factor's leading k x k block, contiguous)
        self.H = None

    def step(self, H, free):
        """A new step: its Hessian H on the nodes ``free`` (mask)."""
        # C order: H.T is BLAS's Fortran order (its lower triangle is H's upper one)
        self.H = np.ascontiguousarray(H, dtype=float)
        self.free = free
        m = free.size - int(np.count_nonzero(free))
        self.m = m if free[m:].all() else None
        self.s = self.s_all[free]

    def _covered(self):
        """The leading block of the kept factor (reversed order) that is this step's free
        block, or None."""
        if self.kept is None:
            return None
        u, free, m = self.kept
        k = self.H.shape[0]
        if np.array_equal(free, self.free):
            return u
        if m is None or self.m is None or self.m < m:
            return None
        if self._block is None or self._block[0] != k:
            self._block = (k, np.asfortranarray(u[:k, :k]))
        return self._block[1]

    def solve(self, lam, rhs):
        """dw (m) with (H + lam diag(s)) dw = rhs on this step's free nodes; NOT_PD (the
        matrix is not positive definite: raise the damping) or None (decide with the double
        factorisation)."""
        from scipy.linalg import blas

        H, damp = self.H, lam * self.s
        rev = rhs[::-1]

        def apply_a(v):
            # (reversed order; H's upper triangle: the one the double factorisation reads)
            return (blas.dsymv(1.0, H.T, v[::-1], lower=1) + damp * v[::-1])[::-1]

        def solved(u, budget):
            x, _, status = pcg(apply_a, lambda r: cho_solve_single(u, r), rev, SINGLE_RTOL,
                               budget)
            # a descent direction: grad . dw = -rhs . dw < 0
            ok = status == "converged" and rev @ x > 0 and np.all(np.isfinite(x))
            return (x[::-1] if ok else None), status

        u = self._covered()
        if u is not None:
            x, status = solved(u, max(REUSE_MIN, H.shape[0] // REUSE_NODES))
            if x is not None:
                return x
            if status == "curvature":
                return self.NOT_PD
        try:
            u = cho_factor_single(H[::-1, ::-1], (np.diagonal(H) + damp)[::-1])
        except FloatingPointError:
            return None         # (beyond single precision's range, or not a number)
        if u is None:
            # spotrf failed: not positive definite, or merely beyond single precision's
            # ~1e7 condition (a soft mode below ~1e-7 of the stiffest): the double
            # factorisation decides, as it did before this path
            return None
        self.kept, self._block = (u, self.free, self.m), None
        x, _ = solved(u, SINGLE_ITER)
        return x


def _double_step(H, damp, g):
    """The damped step -(H + diag(damp))^-1 g by the double Cholesky factorisation, or
    _Damped.NOT_PD where the matrix is not positive definite."""
    # a copy in LAPACK's (Fortran) order, factorised in place: the wrapper would otherwise
    # copy a C-ordered M once more for every trial damping
    M = np.array(H, order="F")
    M[np.diag_indices_from(M)] += damp
    try:
        c = cho_factor(M, overwrite_a=True)
    except sla.LinAlgError:
        return _Damped.NOT_PD
    return -cho_solve(c, g)


def _roundoff(problem, w, e):
    """Round-off (J) of the total energy ``e`` at w: ROUNDOFF_ULPS ulps of the magnitudes
    of its elastic and interaction parts."""
    elastic = 0.5 * w @ (problem.S_sym @ w)
    return ROUNDOFF_ULPS * np.finfo(float).eps * (abs(elastic) + abs(e - elastic))


def _lm_descent(problem, d, w, h_floor, *, max_iter=400, roundoff=True):
    """Levenberg-Marquardt descent of the total energy from w (projected onto h >= h_floor).

    Steps solve (H + lam diag(H_el)) dw = -grad with H the symmetric energy Hessian; lam grows
    until the energy decreases and shrinks after each success, so the iteration slides
    downhill like an overdamped surface and ends in the basin it rolls into (the physical
    landing after a fold). Returns the final w and whether the gradient was driven to ~0 or
    (``roundoff``) the energy stopped falling beyond its round-off for ROUNDOFF_STEPS steps
    (settled: no descent step can tell a lower point of the basin from this one; the Newton
    polish can) - a trial rejected for a rise within that round-off counts as such a step
    (ROUNDOFF_REJECTS), the descent staying at its lowest point.
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
    damped = _Damped(scale_diag)
    for _ in range(max_iter):
        safe_point()            # a signal stops the run between descent steps
        at_bound = (w >= upper - 1e-18) & (g < 0)   # pushing further into h < floor
        free = ~at_bound
        if float(np.max(np.abs(g[free]), initial=0.0)) <= 1e-10 * g0:
            return w, True
        H = problem.energy_hessian(b - w, free)
        # (the whole descent - a lattice-trapped grid, the retry after a failed polish -
        # keeps the double factorisation, bit for bit: there the landing depends on the
        # iterates, SINGLE_MIN_NODES)
        single = roundoff and H.shape[0] >= SINGLE_MIN_NODES
        if single:
            damped.step(H, free)
        while True:
            step = damped.solve(lam, -g[free]) if single else None
            if step is None:
                step = _double_step(H, lam * scale_diag[free], g[free])
            if step is _Damped.NOT_PD:
                lam *= 4
                if lam > 1e12:
                    return w, False
                continue
            dw = np.zeros_like(w)
            dw[free] = step
            w_new = np.minimum(w + dw, upper)
            e_new = problem.energy(w_new, d)
            if np.isfinite(e_new) and e_new <= e:
                break
            if roundoff and ROUNDOFF_REJECTS and np.isfinite(e_new) and \
                    e_new - e <= _roundoff(problem, w_new, e_new):
                # a rise within the energy's round-off: this trial's point cannot be told
                # from w any more than a flat step's - it counts towards settling (w stays)
                flat += 1
                if flat >= ROUNDOFF_STEPS:
                    return w, True
            lam *= 4
            if lam > 1e12:
                return w, False
        flat = flat + 1 if e - e_new <= _roundoff(problem, w_new, e_new) else 0
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
    then the Newton corrector of the problem's contact model polishes the state; where that
    polish ends off a stable equilibrium (a sigma-gap contact), the collocation equations
    are relaxed in pseudo-time from the descent's minimum (:func:`_relax`) and polished again;
    a smooth law's (no sigma-gap) is polished from the contact edges next to the descent's
    (:func:`_smooth_edges`).

    The descent stops once settled at round-off (ROUNDOFF_STEPS) - except on a lattice-trapped
    grid (a law softening beyond a node's stiffness), where the polish is fragile and the
    states reached depend on the iterates: there, and whenever the polish from a settled
    descent does not reach a stable state, the whole descent to its cap is run as before
    (measured: a GW slider on 100 nodes, softening 6.3x a node's stiffness, whose polish from
    the settled descent diverged to a residual of 2.5e-3 m and from the whole descent
    converged in 75 iterations).
    """
    trapped = problem.surface_force_stiffness()[0] >= 1.0
    st, descent = _land(problem, d, w_start, tol=tol, max_iter=max_iter,
                        roundoff=not trapped)
    if not trapped and not (st.converged and st.stable):
        st, descent = _land(problem, d, w_start, tol=tol, max_iter=max_iter, roundoff=False)
    if not (st.converged and st.stable) and problem.sigma is not None:
        # the descent's minimum (of the symmetric energy) has no equilibrium of the
        # collocation equations K w = P - p_c near it on its contact set (Newton cycles about
        # a vanished root): relax those equations in pseudo-time from it instead (the last
        # resort: every landing that polished before is untouched)
        st = _relaxed(problem, d, st, descent, tol=tol, max_iter=max_iter)
    elif not (st.converged and st.stable) and SMOOTH_EDGES:
        # a smooth law (no sigma-gap): the same vanished root at a lattice-trapped contact
        # edge, the polish cycling about it (:func:`_smooth_edges`)
        near = _smooth_edges(problem, d, w_start, descent[0], tol=tol, max_iter=max_iter)
        if near is not None:
            near.n_iter += st.n_iter
            st = near
    return st


def _land(problem, d, w_start, *, tol, max_iter, roundoff):
    """:func:`land` with the descent's round-off stop on or off; returns the polished State
    and the descent's minimum (w, contact set) it started from."""
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
    return st, (w, active)


def _relaxed(problem, d, st, descent, *, tol, max_iter):
    """The landing from the descent's minimum ``descent`` = (w, contact set) whose polish
    ``st`` failed: the collocation equations relaxed in pseudo-time from it (:func:`_relax`:
    the overdamped surface under the forces the corrector balances, so it lands where the
    descent's surface would roll), else - a relaxation that drifts past a ghost beyond its
    step cap - the corrector from the contact edges next to it or farther out
    (:func:`_next_edges`), and last (SEPARATED) the separated state of a pull-off
    (:func:`_separated`); ``st`` itself if none ends on a converged, stable state."""
    w, active = descent
    wr, ar, n_relax = _relax(problem, d, w, active, tol=tol)
    if wr is not None:
        out = solve_complementarity(problem, d, wr, tol=tol, max_iter=max_iter, active0=ar)
        out.n_iter += st.n_iter + n_relax
        if out.converged and out.stable:
            return out
    near = _next_edges(problem, d, w, active, tol=tol, max_iter=max_iter)
    if near is None and SEPARATED:
        near = _separated(problem, d, w, tol=tol, max_iter=max_iter)
    if near is not None:
        near.n_iter += st.n_iter + n_relax
        return near
    return st


def _separated(problem, d, w, *, tol, max_iter):
    """The separated state at d (m): the corrector from the undeformed surface with no
    node in contact, if it converges on a stable state with no node in contact and of lower
    total energy than the descent's minimum ``w`` (the surface there sits in a basin of the
    energy that the collocation equations do not have, and rolls on downhill); else None.

    Why: at a displacement-controlled pull-off the contact branch ends and the surface jumps
    clear of the floor. Measured on the 2-mm slider at sigma = 0.3 nm, p/psat = 0.95 (372
    nodes, 3.67-nm follow band, the retract's fold at d = 2.24238 nm, 215 contact nodes,
    validation/results/sigma03_pulloff.md): the descent settled on 215 contact nodes
    (energy -4.55688e-12 J), the corrector cycled at residuals ~1e-14 m from every disk of
    203-217 nodes, and from the free surface it converged in 4 iterations on the stable
    separated state (h0 = 1.536 nm, energy -4.58148e-12 J)."""
    free = np.zeros(w.size, bool)
    st = solve_complementarity(problem, d, np.zeros(w.size), tol=tol, max_iter=max_iter,
                               active0=free)
    if st.converged and st.stable and not st.active.any() and \
            problem.energy(st.w, d) < problem.energy(w, d):
        return st
    return None


def _smooth_contact(problem, h):
    """The contact set of a smooth law's state at gaps h (m): the nodes on the repulsive
    side of the law's attraction peak, dP/dh > 0 (the sigma-gap's contact set's analogue)."""
    J = problem.law_jacobian(h)
    return (np.diag(J) if np.ndim(J) == 2 else np.asarray(J)) > 0


def _least_energy(problem, d, starts, bound, *, tol, max_iter):
    """Of the corrector's converged, stable states from ``starts`` ((w0 (m), active0 or
    None) each), the one of least total energy below ``bound`` (J); None if none."""
    best, e_best = None, bound
    for w0, active0 in starts:
        st = solve_complementarity(problem, d, w0, tol=tol, max_iter=max_iter, active0=active0)
        if st.converged and st.stable:
            e = problem.energy(st.w, d)
            if e < e_best:
                best, e_best = st, e
    return best


def _smooth_edges(problem, d, w_start, w, *, tol, max_iter):
    """The stable equilibrium, of total energy below the descent's start ``w_start``'s, that
    Newton reaches from the descent's minimum ``w`` (m) of a smooth law with its disk-shaped
    contact set (:func:`_smooth_contact`) moved by the fewest nodes: by 1, then 2 (EDGE_SHIFTS'
    sizes, both ways; of two at one distance the one of least energy), then farther up to
    EDGE_SCAN; None if none does (each Newton polish capped at ``max_iter``) or the contact is
    not a disk.

    A node joining the contact starts at the gap of the contact's last node, a node leaving
    it at the gap of the first free node. Why: as in :func:`_next_edges` - at a contact edge
    whose law softens beyond a node's stiffness the collocation form's equilibrium on the
    descent's edge can have vanished while the energy's minimum remains; the equilibria on
    the neighbouring edges are where the corrector lands."""
    from .linalg import disk_size

    b, n = problem.contour(d), w.size
    h = b - w
    m = disk_size(_smooth_contact(problem, h))
    if not m:
        return None
    e_start = problem.energy(w_start, d)

    def start(k):
        w0 = np.array(w, float)
        if k > 0:
            w0[m:m + k] = b[m:m + k] - h[m - 1]
        else:
            w0[m + k:m] = b[m + k:m] - h[m]
        return w0, None

    def least(shifts):
        return _least_energy(problem, d, (start(k) for k in shifts if 0 < m + k < n),
                             e_start, tol=tol, max_iter=max_iter)
    # nearest edges first (the surface sits at the descent's minimum: the landing is the
    # state next to it, not the deepest one the corrector can reach)
    far = max((abs(x) for x in EDGE_SHIFTS), default=0)
    for k in range(1, max(far, EDGE_SCAN) + 1 if EDGE_SHIFTS else 1):
        best = least([x for x in EDGE_SHIFTS if abs(x) == k] if k <= far else [k, -k])
        if best is not None:
            return best
    return None


def _next_edges(problem, d, w, active, *, tol, max_iter):
    """The stable equilibrium of least total energy that the corrector reaches from the
    descent's minimum w with its disk-shaped contact set moved by one or two nodes at its
    edge (EDGE_SHIFTS); where none converges on a stable state, the nearest edges farther out
    (up to EDGE_SCAN nodes, both ways) that give one; None (no such state, or a contact set
    that is not a disk).

    The energy descent and the corrector solve two forms of one discretisation (the
    symmetric energy and the collocation equations, :func:`_relax`); at an edge node
    softening about as fast as its own stiffness their contact edges can differ by a node,
    and the collocation form's equilibrium on the descent's edge may not exist. The states
    on the neighbouring edges are where it does; of those the corrector reaches, the landing
    is the one of least energy (the descent's own merit)."""
    from .linalg import disk_size

    m = disk_size(active) if active is not None and active.any() else None
    if m is None:
        return None
    b, n = problem.contour(d), w.size

    def start(k):
        A = np.zeros(n, bool)
        A[:m + k] = True
        w0 = np.array(w, float)
        w0[A] = b[A] - problem.sigma
        return w0, A

    def least(shifts):
        return _least_energy(problem, d, (start(k) for k in shifts if 0 < m + k < n),
                             np.inf, tol=tol, max_iter=max_iter)
    best = least(EDGE_SHIFTS)
    if best is None and EDGE_SHIFTS:
        # the collocation form's equilibria may have vanished on several edges about the
        # descent's (EDGE_SCAN): the nearest edges farther out on which one exists
        for k in range(max(abs(x) for x in EDGE_SHIFTS) + 1, EDGE_SCAN + 1):
            best = least((k, -k))
            if best is not None:
                break
    return best


def land_next_node(problem, d, state, sign, *, tol, stats=None, stall_iter=STALL_ITER):
    """The landing of a single node's snap at separation d (m) found by the corrector alone,
    or None (then the energy descent, :func:`land`, decides).

    ``state`` is the last stable state before the fold (its contact set a disk); ``sign`` is
    +1 where the contact edge advances (nodes join), -1 where it recedes. For k in
    NEXT_NODE_SHIFTS the corrector starts from ``state.w`` with the disk moved by k nodes that
    way (NEXT_NODE_ITER iterations, stagnation exit); the first converged state is the
    candidate. It is taken only if it is the descent's landing as far as a cheap test can
    tell: stable (the Hessian's inertia on its free nodes, like every state), its contact set
    a disk whose edge moved by 1 or 2 nodes the way the edge goes, its total energy no
    higher than at the descent's start (``state.w`` at d, projected onto the floor h >= sigma:
    the descent never climbs), and that energy falling monotonically along the straight path
    from the start to it at PATH_SAMPLES points (no barrier between them that would send the
    descent into another basin). The caller still classifies it as a lattice snap (the energy
    it released, :func:`femadh.contact.stepping.lattice_snap`) before it is used, and keeps it
    only where the branch goes on from it (``snap.next_node_holds``). ``stats``: the
    corrector's work counters (as :func:`solve_complementarity`'s), added to;
    ``stall_iter``: its stagnation exit (the stepping's own, None: none)."""
    from .linalg import disk_size

    if problem.sigma is None or not np.any(state.active):
        return None
    m = disk_size(state.active)
    if m is None:
        return None
    b, n = problem.contour(d), state.w.size
    start = np.minimum(state.w, b - problem.sigma)
    e_start = problem.energy(start, d)
    for k in NEXT_NODE_SHIFTS:
        mk = m + sign * k
        if not 0 < mk < n:
            continue
        A = np.zeros(n, bool)
        A[:mk] = True
        w0 = np.array(state.w, float)
        w0[A] = b[A] - problem.sigma
        st = solve_complementarity(problem, d, w0, tol=tol, max_iter=NEXT_NODE_ITER,
                                   active0=A, stall_iter=stall_iter, stats=stats)
        if not st.converged:
            continue
        m_new = disk_size(st.active)
        if not (st.stable and m_new is not None and 1 <= (m_new - m) * sign <= 2):
            return None
        if not _downhill(problem, d, start, e_start, st.w):
            return None
        return st
    return None


def _downhill(problem, d, start, e_start, w_end):
    """True if the total energy falls monotonically (beyond its round-off) from ``start``
    (energy ``e_start``, J) to ``w_end`` along the straight path between them, sampled at
    PATH_SAMPLES points."""
    e_prev = e_start
    for t in np.linspace(0.0, 1.0, PATH_SAMPLES + 1)[1:]:
        w = start + t * (w_end - start)
        e = problem.energy(w, d)
        if not np.isfinite(e) or e > e_prev + _roundoff(problem, w, e):
            return False
        e_prev = e
    return True


def _relax(problem, d, w, active, *, tol, max_steps=None):
    """Pseudo-transient continuation of the collocation equations F = K w - P(h) = 0 (Pa)
    with the gap bound h >= sigma, from w (m) and its contact set ``active``.

    Why: the descent minimises the total energy, whose gradient is sym(S) w - area P with
    S = diag(area) K; the corrector solves the collocation form K w = P - p_c, whose
    Jacobian is not symmetric (1.4 % of its norm on the Fig 4 grid). The two equilibria
    differ by a discretisation error, and near a node that softens about as fast as its
    own stiffness (a contact edge at the lattice-trapping limit) the collocation form can
    have lost the equilibrium on the descent's contact set that the energy still has: the
    Newton polish then cycles about the vanished root (measured on the 2-mm slider at
    sigma = 0.3 nm, 253 nodes: 200 iterations at a residual of 7e-14 m, the edge node's gap
    oscillating 84-91 pm above sigma). Here the surface follows the overdamped dynamics of
    the collocation forces themselves, implicit Euler steps

        (diag(area) J_II + mu diag(S)_II) dw_I = -area_I F_I,   J = K + dP/dh,

    with the pseudo-time step 1/mu following the residual's progress on the current contact
    set (switched evolution relaxation referred to the largest residual seen on the set,
    mu = RELAX_MU0 min(1, r / r_set): 1/RELAX_MU0 while the surface drifts, growing to Newton's
    as it converges) and the contact set updated
    each step as in the corrector (a node joins at h < sigma, leaves when its contact
    pressure turns tensile). It passes the vanished root and settles on the set whose
    equilibrium exists.

    Returns (w, active, steps) once the residual max |area F / diag(S)| (m) on the free
    nodes is at most ``tol`` with an unchanged contact set; (None, None, steps) after
    RELAX_STEPS (or ``max_steps``) steps."""
    b, sigma = problem.contour(d), problem.sigma
    K, a = problem.K, problem.areas
    sdiag = np.diag(problem.S_sym)
    adhesion = problem.gap.adhesion if problem.gap is not None else 0.0
    w, A = np.array(w, float), np.array(active, bool)
    r_set, A_set = None, None
    steps = RELAX_STEPS if max_steps is None else max_steps
    for step in range(1, steps + 1):
        safe_point()            # a signal stops the run between relaxation steps
        w[A] = b[A] - sigma
        h = b - w
        F = K @ w - problem.pressure(h)
        idx = np.flatnonzero(~A)
        r = float(np.max(np.abs(a[idx] * F[idx]) / sdiag[idx])) if idx.size else 0.0
        if not np.isfinite(r):
            return None, None, step
        if A_set is None or not np.array_equal(A, A_set):
            r_set, A_set = r, A.copy()  # a new contact set: its residual is the reference
        # referred to the largest residual seen on the set, not its first: a set entered at
        # a small residual that then rises (the drift) would otherwise keep mu at RELAX_MU0
        # until r fell below that first value again (measured on test_landing_relax's corner
        # case: from held 88-100-node disks 572-1073 steps to the 84-node landing, 67-191
        # with the running largest; the descent's own relaxation 43 steps either way)
        r_set = max(r_set, r)
        mu = RELAX_MU0 * min(1.0, r / r_set) if r_set > 0 else RELAX_MU0
        mu = max(RELAX_MU_MIN, mu)
        M = K[np.ix_(idx, idx)]
        add_jacobian(M, problem.law_jacobian(h), idx)
        M = a[idx, None] * M
        M[np.diag_indices_from(M)] += mu * sdiag[idx]
        try:
            dw = -lu_solve(lu_factor(M), a[idx] * F[idx])
        except (ValueError, sla.LinAlgError):
            return None, None, step
        if not np.all(np.isfinite(dw)):
            # lu_factor only warns on an exactly singular matrix: the step is then not
            # finite, and the relaxation gives up (the next fallback is tried) instead of
            # carrying it into the law
            return None, None, step
        closing = dw > 0
        alpha = 1.0
        if np.any(closing):     # no gap closes by more than MAX_GAP_CLOSURE of itself
            alpha = min(1.0, float(np.min(MAX_GAP_CLOSURE * h[idx][closing]
                                          / dw[closing])))
        w[idx] += alpha * dw
        h = b - w
        # a contact node stays while its asperities push (p_c = P - K w, plus eq 20's
        # adhesion P_LJa on the contact set, > 0), as in the corrector
        pc = problem.pressure(h) - K @ w
        new_A = (A & (pc + adhesion > 0)) | (~A & (h < sigma))
        if r <= tol and np.array_equal(new_A, A):
            return w, A, step
        A = new_A
    return None, None, steps
