"""The sigma-gap contact branch traced in its edge radius, on a grid that moves with the edge.

The sigma-gap (complementarity) twin of :mod:`femadh.contact.edge_branch`. On a fixed grid
the retract of a sigma-gap contact unzips node by node: each release of a contact node is a
micro-fold of the discrete curve d -> state (bracketed, bisected and landed by the stepping
solver; ~500 of them on the sigma = 0.3 nm points of the stiction map). Here the grid is
scaled with the contact radius, r_i = lambda r_i^0 with lambda = c / r_k^0, so that the
contact edge sits on node k at every state, and the branch is a smooth function of c: no
node is ever crossed. The half-space operator of the scaled grid is C = lambda C^0,
K = K^0 / lambda (Johnson 1985 eq 3.41: the compliance is homogeneous of degree one in
length), one Green operator for the whole branch.

The collocation problem the runner solves on a grid (paper 1 eqs 6, 8):

    K w = P(h) - p_c,   h = d + shape(r) - w,   h >= sigma, p_c >= 0, (h - sigma) p_c = 0.

A state of this branch at edge radius c = r_k: nodes 0..k held at h = sigma (their
displacements w_i = d + shape_i - sigma follow from d), nodes k+1..n-1 free, and

    rows i < k :  p_c,i = P_i(h) - (K w)_i        (the multipliers, explicit)
    rows i >= k:  (K w)_i - P_i(h) = 0           (the free nodes' equilibrium, and p_c,k = 0)

in the unknowns (w_{k+1..n-1}, d): n - k equations in n - k unknowns. The edge condition is
p_c,k = 0, the multiplier vanishing at the edge node. Why this one: (i) it is the discrete
form of the continuum's edge condition - with bounded surface forces outside the contact a
compressive contact pressure must vanish at the edge (a stress-intensity factor K_I > 0 would
need a tensile p_c < 0, one < 0 a gap below sigma just outside), p_c ~ (c - r)^1/2; (ii) a
state with h_k = sigma and p_c,k = 0 solves the collocation problem with node k held *and*
with node k free (its free-node equation is row k; its gap is at the bound): it is the state
where the fixed-grid branch releases node k, the junction of two of its pieces, so every
state of this branch is a solution of the runner's equations on its scaled grid (checked by
tests/test_sigma_edge.py and validation/sigma_edge.py: residual, the runner's Newton and
stability test), with complementarity holding as long as p_c,i >= 0 for i < k and
h_i > sigma for i > k (:meth:`SigmaEdgeBranch.complementarity`); (iii) it leaves a square,
regular system (the Jacobian below is the free block of K + diag(P') bordered by the d
column: the system of the edge branch with the edge node's gap pinned at sigma). Pinning
another quantity (a gap of the first free node, a multiplier p_c,k > 0) gives states that
are not the fixed grid's junctions and carry a lattice offset of their own.

The force is F_ex = sum_i area_i (P_i - p_c,i) (attractive positive, as the runner's F_ex;
areas lambda^2 area^0). A law integrated sub-grid (:mod:`femadh.contact.subgrid`, the
capillary step as the stepping solver has it) has a nodal pressure f_k / area_k that is
invariant under the scaling (both scale like lambda^2): the reference problem's nodal
pressure and law Jacobian serve every scaled grid.

On the retract the contact radius decreases monotonically from deep contact to the
displacement-controlled pull-off, the fold of d(c) (dd/dc = 0; measured at every point of
the stiction map where d(c) has a fold, validation/results/sigma_edge.md: no turning point
of c, complementarity with margin on every state): the branch is traced by plain Newton in
c with :class:`~femadh.contact.edge_branch.BranchTrace` (its march, its fold as the root of
dd/dc, its parabolic search of the largest force).
"""
from dataclasses import dataclass
import math

import numpy as np
from scipy.linalg import lapack

from ..interrupt import check as safe_point
from .edge_branch import GAP_CLOSURE, EdgeState, scaled_problem
from .problem import ContactProblem

#: Newton iterations allowed per state
MAX_ITER = 40
#: the multipliers and free gaps must satisfy complementarity to this much of their scale:
#: p_c,i >= -COMPL_SLACK max|p_c| (round-off of the explicit rows), h_i - sigma >= 0 on
#: the free nodes (strictly: a free gap at sigma is a second edge)
COMPL_SLACK = 1e-9


@dataclass
class SigmaEdgeState(EdgeState):
    """An :class:`~femadh.contact.edge_branch.EdgeState` of the sigma-gap branch with its
    contact multipliers ``p_c`` (Pa, repulsive positive; zero from the edge node k on)."""

    p_c: np.ndarray = None

    @property
    def p_net(self):
        """Net attractive pressure P - p_c (Pa) at the nodes."""
        return self.P - self.p_c


class SigmaEdgeBranch:
    """Solves of the sigma-gap contact branch at given edge radii.

    Parameters
    ----------
    base : GreenOperator
        The operator on the reference grid (a node at r = 0).
    k : int
        Index of the edge node of the reference grid (0 < k < n - 1).
    sphere : Sphere
    effects : dict
        The laws acting outside the contact (LJ, capillary step, ...), as the scene has them.
    gap : AsperityGap
        The sigma-gap; its contact model must be "complementarity" without eq 20's adhesion
        on the contact set (a contact node holding a tension moves the edge condition).
    tol : float
        Residual max |w - C (P - p_c)| (m) every state meets: the runner's.
    subgrid : bool
        Integrate the step laws sub-grid, as the runner's stepping solver does.
    """

    def __init__(self, base, k, sphere, effects, gap, tol, subgrid=True):
        if gap is None or gap.contact_model != "complementarity" or gap.adhesion:
            raise ValueError("sigma-edge branch: needs the sigma-gap with the "
                             "complementarity contact model and no eq 20 adhesion")
        n = base.grid.n
        if not 0 < k < n - 1:
            raise ValueError(f"sigma-edge branch: edge node k = {k} must lie in 1..{n - 2}")
        self.base, self.sphere, self.effects, self.gap = base, sphere, dict(effects), gap
        self.sigma, self.k, self.n, self.tol = gap.sigma, k, n, tol
        self.nodes0 = base.grid.nodes
        self.r0 = float(self.nodes0[k])
        self.K0, self.C0 = base.stiffness, base.compliance
        self.areas0 = base.grid.areas
        # the reference problem: its nodal pressure and law Jacobian are the scaled grids'
        self._ref = ContactProblem(base, sphere, self.effects, gap, check_laws=False,
                                   subgrid=subgrid)
        # the d column's elastic part: rows k.. of K0 times the held nodes' dw/dd = 1
        self._kheld = self.K0[k:, :k + 1].sum(axis=1)
        self.n_solves = self.n_iter = self.n_factor = 0
        #: the laws' pressure is multiplied by this (1: the scene's; below 1 only in
        #: :func:`start_state`'s homotopy from Hertz's state)
        self.strength = 1.0

    # -- the pieces ---------------------------------------------------------------------
    def _shape(self, lam):
        return self.sphere.shape(lam * self.nodes0)

    def _fields(self, lam, wf, d):
        """(w, h, P, R): displacements, gaps, nodal law pressures and the K-form residual
        K0 w - lam P (rows k.., m x lam; rows < k are the multipliers' and not equations)."""
        k, sigma = self.k, self.sigma
        shape = self._shape(lam)
        w = np.empty(self.n)
        w[:k + 1] = d + shape[:k + 1] - sigma
        w[k + 1:] = wf
        h = (d + shape) - w
        h[:k + 1] = sigma          # exactly: the held nodes sit on the floor
        P = self.strength * self._ref.pressure(h)
        R = self.K0[k:] @ w - lam * P[k:]
        return w, h, P, R

    def _jacobian(self, lam, h):
        """d R / d (w_{k+1..}, d) (rows k..n-1): the free block of K0 + lam J (J = dP/dh, a
        vector or tridiagonal matrix) bordered by the d column K0[k:, :k+1] 1 - lam J 1."""
        k, n = self.k, self.n
        J = self.strength * self._ref.law_jacobian(h)
        M = np.empty((n - k, n - k))
        M[:, :-1] = self.K0[k:, k + 1:]
        if J.ndim == 1:
            lJ = lam * J[k + 1:]
            M[1:, :-1][np.diag_indices(n - k - 1)] += lJ
            M[:, -1] = self._kheld
            M[1:, -1] -= lJ
        else:
            B = lam * J[k:, k + 1:]
            M[:, :-1] += B
            M[:, -1] = self._kheld - B.sum(axis=1)
        return M, J

    def multipliers(self, lam, w, P):
        """p_c (Pa): P - K w on the held nodes 0..k-1, zero from the edge node on."""
        p = np.zeros(self.n)
        k = self.k
        p[:k] = P[:k] - (self.K0[:k] @ w) / lam
        return p

    # -- a state -------------------------------------------------------------------------
    def solve(self, c, w0, d0):
        """The state with its edge on node k at c (m) from the guess (w0 on all nodes, d0):
        Newton, steps limited so that no free gap closes by more than GAP_CLOSURE of itself.
        Returns a SigmaEdgeState, or None if Newton did not converge in MAX_ITER."""
        k = self.k
        lam = c / self.r0
        wf, d = np.array(w0[k + 1:], float), float(d0)
        self.n_solves += 1
        for it in range(1, MAX_ITER + 1):
            safe_point()
            w, h, P, R = self._fields(lam, wf, d)
            if h[k + 1:].min() <= 0 or not math.isfinite(float(R.sum())):
                return None
            # the runner's residual w - C (P - p_c) = C0 (K0 w - lam (P - p_c))
            res = float(np.abs(self.C0[:, k:] @ R).max())
            if res <= self.tol:
                self.n_iter += it - 1
                st = SigmaEdgeState(c, d, w, it - 1, res, lam, h, P,
                                    make_problem=self.problem)
                st.p_c = self.multipliers(lam, w, P)
                return st
            M, _ = self._jacobian(lam, h)
            lu, piv, info = lapack.dgetrf(M, overwrite_a=True)
            self.n_factor += 1
            if info > 0:
                return None
            dx = lapack.dgetrs(lu, piv, -R)[0]
            if not np.all(np.isfinite(dx)):
                return None
            closing = dx[:-1] - dx[-1]          # dh = dd - dw: a free gap closes if dw > dd
            worst = float((closing / h[k + 1:]).max())
            alpha = 1.0 if worst <= GAP_CLOSURE else GAP_CLOSURE / worst
            wf = wf + alpha * dx[:-1]
            d = d + alpha * dx[-1]
        self.n_iter += MAX_ITER
        return None

    def tangent(self, st):
        """(dw_free/dc, dd/dc) along the branch at a state: M dx/dc = -dR/dc with the
        shape on nodes that move with c (d shape(r_i(c))/dc = shape'(r_i) r_i / c), the held
        nodes' w = d + shape - sigma and the law pressure scaled by lam = c / r_k^0."""
        k, lam = self.k, st.lam
        r = lam * self.nodes0
        ds = self.sphere.slope(r) * r / st.c
        M, J = self._jacobian(lam, st.h)
        dh = np.zeros(self.n)
        dh[k + 1:] = ds[k + 1:]                  # free gaps move with the shape
        Jdh = J * dh if J.ndim == 1 else J @ dh
        dR = self.K0[k:, :k + 1] @ ds[:k + 1] - st.P[k:] / self.r0 - lam * Jdh[k:]
        lu, piv, info = lapack.dgetrf(M, overwrite_a=True)
        self.n_factor += 1
        if info > 0:
            raise np.linalg.LinAlgError(f"sigma-edge branch: singular Jacobian at "
                                        f"c = {st.c:.6g} m")
        dx = lapack.dgetrs(lu, piv, -dR)[0]
        return dx[:-1], float(dx[-1])

    def slope(self, st):
        """dd/dc (-) at a state (the fold of the retract, the displacement-controlled
        pull-off, is its root)."""
        return self.tangent(st)[1]

    # -- what a state is -------------------------------------------------------------------
    def problem(self, c):
        """The runner's :class:`ContactProblem` on the grid whose node k sits at c (m): the
        reference problem scaled (:func:`~femadh.contact.edge_branch.scaled_problem`, its
        sub-grid laws built on the scaled nodes; the branch's own Newton reuses the
        reference's nodal pressure instead: force and area both scale like lam^2)."""
        return scaled_problem(self._ref, self.base, self.sphere, c / self.r0)

    def force(self, st):
        """F_ex (N, attractive positive) on the analysis disk of the state's scaled grid:
        sum area (P - p_c), the runner's F_LJ + F_cap - F_el."""
        return st.lam * st.lam * float(self.areas0 @ st.p_net)

    def radius(self, st):
        """The analysis radius (m) of a state's scaled grid."""
        return st.lam * self.base.grid.radius

    def complementarity(self, st):
        """(smallest p_c,i / max p_c over i < k, smallest (h_i - sigma) / sigma over the
        free nodes i > k): both must be >= 0 (the first to round-off) for the state to
        solve the collocation problem."""
        k = self.k
        pmax = float(np.abs(st.p_c).max()) or 1.0
        return (float(st.p_c[:k].min()) / pmax,
                float(st.h[k + 1:].min() - self.sigma) / self.sigma)

    def complementary(self, st):
        """True when the state satisfies complementarity (see :meth:`complementarity`)."""
        p, g = self.complementarity(st)
        return p >= -COMPL_SLACK and g > 0

    def stable(self, st):
        """Whether the state is an energy minimum with nodes 0..k held (the runner's
        stability test, :func:`~femadh.contact.stability.is_stable`, on its scaled grid)."""
        from .stability import is_stable

        free = np.zeros(self.n, bool)
        free[self.k + 1:] = True
        return is_stable(st.problem, st.h, free)


def hertz_guess(branch, c):
    """(w, d): Hertz's state of edge radius c (m) on the branch's grid scaled to c, as a
    Newton start (Johnson 1985 eq 3.42, a rigid paraboloid of radius R: interference
    delta = c^2 / R, d = sigma - delta; the surface moves down by u = delta - r^2/2R inside
    and u(r) = ((2c^2 - r^2) asin(c/r) + c sqrt(r^2 - c^2)) / (pi R) outside, w = -u)."""
    R = branch.sphere.radius
    lam = c / branch.r0
    r = lam * branch.nodes0
    delta = c * c / R
    d = branch.sigma - delta
    u = np.empty_like(r)            # Hertz's indentation (down), w = -u (w up positive)
    inside = r <= c
    u[inside] = delta - r[inside] ** 2 / (2 * R)
    ro = r[~inside]
    u[~inside] = ((2 * c * c - ro ** 2) * np.arcsin(c / ro)
                  + c * np.sqrt(ro ** 2 - c * c)) / (math.pi * R)
    return -u, d


def tail_between(effects, sphere, d, a1, a2):
    """Force (N, attractive positive) of the laws on the undeformed paraboloid between radii
    a1 < a2 (m): 2 pi R int_{h1}^{h2} P dh = 2 pi R (U(h2) - U(h1)) with h = d + shape(a)
    (P = dU/dh, attractive positive), i.e. :func:`femadh.contact.forces.tail_force`'s
    integral between two analysis radii (what a scaled grid's disk holds beyond the
    runner's)."""
    R = sphere.radius
    h = np.array([d + sphere.shape(a1), d + sphere.shape(a2)])
    u = sum(np.asarray(e.energy(h), float) for e in effects.values())
    return float(2 * math.pi * R * (u[1] - u[0]))


@dataclass
class Retract:
    """The retract of a sigma-gap contact traced in its edge radius: its states (increasing
    c), the displacement-controlled pull-off (the fold of d(c)), the largest tensile force
    on the stable part c >= c_fold and where, and the work done (solves, factorisations)."""

    states: list
    fold: SigmaEdgeState
    best: SigmaEdgeState
    max_adhesion: float
    at_fold: bool
    n_solves: int
    n_factor: int
    worst_complementarity: tuple


#: relative steps of the march, start and largest (edge_branch's: a state of the scaled grid
#: is a smooth function of c; the sigma-gap branch converges in 2-4 Newton steps at 8 %)
STEP0 = 0.02


def trace_retract(branch, c0, c_low, c_high, value=None):
    """Trace the retract branch from edge radius c0 (m; Newton from Hertz's state) up until
    the force ``value(state)`` (default :meth:`SigmaEdgeBranch.force`) has passed a maximum
    or c reaches c_high, and down to the fold of d(c) (dd/dc = 0, the pull-off under
    displacement control) or c_low. Every state's complementarity is checked (ValueError
    naming the state where it fails: the branch is then not a branch of the collocation
    problem). Returns a :class:`Retract`; the largest force is searched on the stable part
    c >= c_fold (parabolic search of BranchTrace where it is interior, else the fold's)."""
    from ..errors import ConvergenceError
    from .edge_branch import BranchTrace

    value = value or branch.force
    start = start_state(branch, c0)
    tr = BranchTrace(branch)
    tr.states.append(start)
    worst = [math.inf, math.inf]

    def visit(s):
        if s.force is None:
            s.force = value(s)
            s.dd_dc = branch.slope(s)
            p, g = branch.complementarity(s)
            worst[0], worst[1] = min(worst[0], p), min(worst[1], g)
            if not (p >= -COMPL_SLACK and g > 0):
                raise ValueError(f"sigma-edge branch: complementarity fails at c = {s.c:.6g} m "
                                 f"(d = {s.d:.6g} m): smallest multiplier {p:.3g} of the "
                                 f"largest, smallest free gap above sigma {g:.3g} sigma")
        return s

    def up_done(run):
        s = visit(run[-1])
        return s.c >= c_high or (len(run) >= 3 and s.force < run[-2].force)

    def down_done(run):
        s = visit(run[-1])
        return s.c <= c_low or s.dd_dc > 0

    tr.march(start, +1, up_done, STEP0)
    tr.march(start, -1, down_done, STEP0)
    states = tr.states
    for s in states:
        visit(s)
    # the fold: the root of dd/dc between the last two states of the downward march
    i = next((j for j in range(len(states) - 1)
              if states[j].dd_dc > 0 >= states[j + 1].dd_dc), None)
    if i is None:
        raise ConvergenceError(f"sigma-edge branch: no fold of d(c) above c = "
                               f"{states[0].c:.6g} m", d=states[0].d, residual=math.nan,
                               n_iter=0)
    fold = visit(tr.fold(states[i].c, states[i + 1].c))
    stable = [fold] + [s for s in tr.states if s.c > fold.c]
    j = int(np.argmax([s.force for s in stable]))
    if 0 < j < len(stable) - 1:
        best_value, best = tr.maximize(lambda s: visit(s).force, stable[j - 1], stable[j],
                                       stable[j + 1])
        at_fold = False
    elif j == 0:
        best_value, best, at_fold = fold.force, fold, True
    else:
        raise ConvergenceError(f"sigma-edge branch: the force still grows at c = "
                               f"{stable[-1].c:.6g} m (c_high)", d=stable[-1].d,
                               residual=math.nan, n_iter=0)
    return Retract(sorted(tr.states, key=lambda s: s.c), fold, best, best_value, at_fold,
                   branch.n_solves, branch.n_factor, tuple(worst))


#: the homotopy's first step in the law strength, and its smallest
HOMOTOPY_STEP0, HOMOTOPY_STEP_MIN = 0.25, 1e-3


def start_state(branch, c):
    """The branch's state at edge radius c (m): Newton from Hertz's state (:func:`hertz_guess`)
    and, where that fails (a narrow capillary step pulls the free gaps onto sigma), a
    homotopy in the laws' strength t from 0 (Hertz, the discrete problem without laws) to 1,
    each step's Newton started from the last state (the step halved on failure or where a
    state leaves complementarity, doubled after a success). ConvergenceError names c and the
    strength reached."""
    from ..errors import ConvergenceError

    w, d = hertz_guess(branch, c)
    st = branch.solve(c, w, d)
    # Newton from Hertz's state may reach a root of the equations that is not a state of
    # the collocation problem (measured: sigma = 0.489 nm, p/psat 0.15 on a 2-nm grid, a
    # free gap below sigma at d = 3.4 nm): taken only where complementarity holds
    if st is not None and branch.complementary(st):
        return st
    t, step = 0.0, HOMOTOPY_STEP0
    try:
        branch.strength = 0.0
        st = branch.solve(c, w, d)
        while st is not None and t < 1.0:
            nxt = min(1.0, t + step)
            branch.strength = nxt
            trial = branch.solve(c, st.w, st.d)
            if trial is None or not branch.complementary(trial):
                step *= 0.5
                if step < HOMOTOPY_STEP_MIN:
                    st = None
                continue
            st, t, step = trial, nxt, 2 * step
    finally:
        branch.strength = 1.0
    if st is None:
        raise ConvergenceError(f"sigma-edge branch: no state at c = {c:.6g} m (the homotopy "
                               f"from Hertz's state stalled at law strength {t:.3g})", d=d,
                               residual=math.nan, n_iter=MAX_ITER)
    # its force and multipliers at full strength (the last solve ran at t = 1)
    return st


def extend_deep(branch, retract, d_deep, max_states=None):
    """The retract's branch traced on up in c (deeper contact) until its separation is at
    most ``d_deep`` (m): the sweep's retract starts at its deepest separation, below the
    largest force's state where :func:`trace_retract` stops. The new states join
    ``retract.states`` (kept in increasing c), each checked for complementarity as
    :func:`trace_retract` checks them (ValueError naming the state). Returns the states of
    the stable part (c >= the fold's, the fold included) in increasing c."""
    from .edge_branch import MAX_STATES, BranchTrace

    tr = BranchTrace(branch)
    tr.states = list(retract.states)
    top = tr.states[-1]
    cap = MAX_STATES if max_states is None else max_states

    def done(run):
        if len(run) > cap:
            from ..errors import ConvergenceError

            raise ConvergenceError(f"sigma-edge branch: the retract does not reach d = "
                                   f"{d_deep * 1e9:.6g} nm in {cap} states up from c = "
                                   f"{top.c:.6g} m", d=run[-1].d, residual=math.nan,
                                   n_iter=0)
        return run[-1].d <= d_deep

    if top.d > d_deep:
        run = tr.march(top, +1, done, STEP0)
        for s in run[1:]:
            p, g = branch.complementarity(s)
            if not (p >= -COMPL_SLACK and g > 0):
                raise ValueError(f"sigma-edge branch: complementarity fails at c = "
                                 f"{s.c:.6g} m (d = {s.d:.6g} m) on the way to the sweep's "
                                 f"deepest separation: smallest multiplier {p:.3g} of the "
                                 f"largest, smallest free gap above sigma {g:.3g} sigma")
        retract.states = sorted(tr.states, key=lambda s: s.c)
    fold = retract.fold
    return [fold] + [s for s in retract.states if s.c > fold.c]


#: branch solves allowed to place a state at a requested separation (secant in c)
AT_D_SOLVES = 6


def state_at_separation(branch, stable, d):
    """The branch's state at separation d (m) on its stable part ``stable`` (states in
    increasing c, d decreasing; d within their range): secant iterations in c from the
    bracketing states (at most AT_D_SOLVES solves, to |d_state - d| <= 1e-6 of the
    bracket's width in d). The state's d is then within a round-off of d: the runner's
    corrector at d itself (:func:`runner_state`) removes the rest. None where d lies
    outside the states' range."""
    for hi, lo in zip(stable, stable[1:]):
        # hi at the smaller c (larger d), lo at the larger c (smaller d)
        if lo.d <= d <= hi.d:
            break
    else:
        return None
    for s in (hi, lo):
        if s.d == d:
            return s
    a, b = hi, lo
    width = hi.d - lo.d
    best = None
    for _ in range(AT_D_SOLVES):
        t = (d - a.d) / (b.d - a.d)
        c = a.c + t * (b.c - a.c)
        w0 = a.w + t * (b.w - a.w)
        st = branch.solve(c, w0, a.d + t * (b.d - a.d))
        if st is None:
            break
        best = st
        if abs(st.d - d) <= 1e-6 * width:
            break
        # keep the bracket (d(c) is monotone on the stable part)
        if st.d > d:
            a = st
        else:
            b = st
    return best


def runner_state(st, d, tol, max_iter):
    """The runner's State at separation d (m) on the scaled grid of the branch state ``st``
    (its :class:`ContactProblem`, ``st.problem``): the runner's corrector from the branch
    state's surface with its contact set (nodes 0..k-1 held, the edge node k too), so that
    the committed state is a solution of the runner's own equations (paper 1 eqs 6, 8) with
    the runner's convergence and stability flags. Returns (problem, State)."""
    from .complementarity import solve_complementarity

    pb = st.problem
    active = np.asarray(st.h <= pb.sigma * (1 + 1e-12))
    new = solve_complementarity(pb, d, st.w, tol=tol, max_iter=max_iter, active0=active)
    return pb, new


def as_runner_state(st, tol):
    """The branch state ``st`` as the runner's State on its scaled grid, as it is (no
    corrector: at the fold the runner's Jacobian at fixed d is singular, its Newton need not
    converge there): nodes 0..k held (the edge node at sigma with p_c,k = 0), each law's
    pressure on the scaled problem, the runner's residual max |w - C (P - p_c)| and
    stability test (:func:`~femadh.contact.stability.is_stable`, marginal at a fold);
    converged where that residual is within ``tol`` (m). Returns (problem, State)."""
    from .state import State
    from .stability import is_stable

    pb = st.problem
    n = st.w.size
    A = np.zeros(n, bool)
    A[:int(np.count_nonzero(st.h <= pb.sigma))] = True
    p_eff = pb.effect_pressures(st.h)
    p_net = sum(p_eff.values()) - st.p_c
    res = float(np.max(np.abs(st.w - pb.C @ p_net)))
    r_c = math.sqrt(float(pb.areas[A].sum()) / math.pi)
    return pb, State(st.d, st.w.copy(), st.h.copy(), p_eff, st.p_c.copy(), A, r_c,
                     st.n_iter, res, res <= tol,
                     bool(is_stable(pb, st.h, ~A)))
