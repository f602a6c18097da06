"""The contact branch of a smooth adhesive sphere traced in its edge radius, on a grid that
moves with the edge.

On the JKR side of the smooth-sphere problem (no sigma-gap; paper 1 eqs 5-6 with a smooth law)
the law acts in a cohesive zone ~ell wide at a contact edge that travels hundreds of ell along
the curve (mu = 20: ~500 ell). A grid exchanged in steps as the edge moves (a band that is
re-centred once the edge has left its middle, :class:`~femadh.discretisation.moving.MovingBand`)
sees the edge cross its nodes: the discrete curve carries lattice wiggles of the node spacing,
which near the flat jump-out fold become extra folds unless the band is very fine, and the
continuation's predictor moves the edge by a fraction of the cohesive zone per step.

Here the grid follows the edge continuously: its nodes are r_i = lambda r_i^0 with
lambda = c / r_k^0, where c is the edge radius (the continuation parameter) and r^0 a banded
grid (:class:`~femadh.discretisation.family.GridFamily`) fine around its node k. The edge sits
on node k at every state, so the discretisation seen by the edge is the same along the branch:
no lattice wiggles, and the branch is a smooth function of c. The half-space compliance is
homogeneous of degree one in length (Johnson 1985 eq 3.41: a uniform pressure p on a disk of
radius a displaces the surface by p a / E* times a function of r / a), so the operator of the
scaled grid is C = lambda C^0 and K = K^0 / lambda exactly: one Green operator serves the
whole branch.

Unknowns at edge radius c: the displacements w (m) and the separation d (m), with

    K w - P(h) = 0,   h_k - g_e = 0,   h = d + shape(r) - w,

the second pinning the edge gap g_e (the gap that marks the edge) on node k. On the JKR side
the contact radius increases monotonically along the whole curve (the folds are extrema of
d(c), not turning points of c), so the branch is traced by plain Newton in c, folds included:
the jump-out fold is the root of dd/dc (from the linearised system), the load-controlled
pull-off the largest tension, the landing after the jump-in the root of d(c) = d_in.
"""
from dataclasses import dataclass, field
import copy
import functools
import math

import numpy as np
from scipy import optimize
from scipy.linalg import lapack

from ..errors import ConvergenceError
from ..interrupt import check as safe_point
from .problem import ContactProblem

#: Newton iterations allowed per state
MAX_ITER = 40
#: largest fraction of its gap one Newton step may close (LJ repulsion grows like h^-9)
GAP_CLOSURE = 0.3
#: the relative change of c per step starts here and adapts to the Newton iterations
STEP0 = 0.02
#: largest and smallest relative steps in c
STEP_MAX = 0.08
STEP_MIN = 1e-5
#: Newton iterations a step aims at (the step grows below, shrinks above; a state's count is
#: its factorisations plus its chord steps / CHORD_PER_FACTOR)
TARGET_ITER = 4
#: the Newton loop keeps its factorisation while each step cuts the residual to below this
#: fraction of the previous one (chord steps), and refactorises otherwise
CHORD_RATE = 0.1
CHORD_PER_FACTOR = 3
#: a solve starts on the last factorisation if its state's parameter (c, or the centre gap)
#: lies within this fraction of the new one (the root searches' solves; a march step of a
#: few per cent moves the Jacobian too far for a chord step to gain a decade)
REUSE_SPAN = 0.01
#: relative accuracy in c of the fold and of the landing (root finding: the fold's tension and
#: the landing's work move by ~this relative to themselves)
C_XTOL = 1e-8
#: relative accuracy in c of the largest tension's location: the value at a smooth maximum
#: is off by ~(this)^2 relative
MAX_XTOL = 1e-4
#: solves the maximum search may take (a smooth maximum: 2-4)
MAX_PARABOLA = 30
#: states the march's predictor extrapolates from (2: the secant, 3: a parabola)
PREDICTOR_POINTS = 3
#: the branch ends after this many states (a cap: a healthy branch takes 30-80)
MAX_STATES = 2000


def edge_grid(radius, edge, spacing, half, grading, max_nodes=4000):
    """A radial grid with a node exactly at ``edge`` (m), uniform spacing h within ``half`` of
    it on both sides and coarsening linearly beyond, Delta = h (1 + (|r - edge| - half) /
    grading) (the banded family of :class:`~femadh.discretisation.family.GridFamily`, laid
    out from the edge node instead of from r = 0): its members at every h are refinements of
    one mesh density around the edge node, whatever h, which a Richardson estimate of the
    edge-following trace needs (a band laid out from r = 0 puts its node nearest the edge up
    to h/2 off the band's centre, differently for each h). Towards r = 0 the last step is
    cut to land on 0 (the contact's interior, where the solution is smooth)."""
    if not (0.0 < edge < radius and spacing > 0 and half >= 0 and grading > 0):
        raise ValueError(f"edge grid needs 0 < edge ({edge:.4g} m) < radius ({radius:.4g} m), "
                         f"spacing > 0 ({spacing:.4g} m), grading > 0 ({grading:.4g} m)")

    def delta(x):
        return spacing * (1.0 + max(x - half, 0.0) / grading)

    def walk(limit):
        out, x = [], 0.0
        while True:
            step = delta(x + 0.5 * delta(x))
            if x + step >= limit:
                return out, x
            x += step
            out.append(x)
            if len(out) > max_nodes:
                raise ValueError(f"edge grid needs more than {max_nodes} nodes (spacing "
                                 f"{spacing:.3g} m on a radius of {radius:.3g} m)")
    inner, _ = walk(edge)
    # outside: stop where the last annulus (half-way edge to a) would be narrower than a step
    outer, x = [], 0.0
    while True:
        step = delta(x + 0.5 * delta(x))
        if edge + x + 1.5 * step > radius:
            break
        x += step
        outer.append(x)
        if len(outer) > max_nodes:
            raise ValueError(f"edge grid needs more than {max_nodes} nodes")
    if inner and edge - inner[-1] < 0.5 * delta(inner[-1]):
        inner = inner[:-1]          # no sliver of a last step before r = 0
    nodes = np.r_[0.0, edge - np.array(inner[::-1]), edge, edge + np.array(outer)]
    from ..elastic.grid import RadialGrid
    return RadialGrid.from_nodes(nodes, radius, fine_radius=edge + half), len(inner) + 1


class ScaledOperator:
    """The half-space operator of a grid scaled by lambda from a reference grid: C = lambda
    C^0, K = K^0 / lambda (the compliance is homogeneous of degree one in length)."""

    name = "green-scaled"

    def __init__(self, base, lam):
        g = base.grid
        # a scaled valid grid is valid: its checks (monotone edges, nodes inside their
        # annuli) are not repeated at every state
        self.grid = object.__new__(type(g))
        for name, value in (("nodes", g.nodes * lam), ("edges", g.edges * lam),
                            ("fine_radius", None if g.fine_radius is None
                             else g.fine_radius * lam)):
            object.__setattr__(self.grid, name, value)
        self.compliance = lam * base.compliance
        self.stiffness = base.stiffness / lam
        self.lam = lam


def scaled_problem(ref, base, sphere, lam):
    """The :class:`ContactProblem` ``ref`` (on the operator ``base``) on the grid scaled by
    ``lam`` (r = lam r0): the operator scaled (:class:`ScaledOperator`; the energy stiffness
    diag(area) K scales like lam), the sphere's shape on the new nodes, and sub-grid laws
    built again on them - a problem's ``pressure``, ``law_jacobian`` and energy divide a
    sub-grid force by its own nodes' areas, so a law kept on the reference nodes would be off
    by lam^-2 (and a stability verdict with it)."""
    from .subgrid import SubgridStep

    op = ScaledOperator(base, lam)
    pb = copy.copy(ref)
    pb.operator, pb.grid = op, op.grid
    pb.shape = sphere.shape(op.grid.nodes)
    pb.K, pb.C, pb.areas = op.stiffness, op.compliance, op.grid.areas
    pb.S_sym = lam * ref.S_sym
    pb._finest = None
    if ref.integrated:
        pb.integrated = {name: SubgridStep(step.law, op.grid.nodes, op.grid.radius)
                         for name, step in ref.integrated.items()}
    return pb


@dataclass
class EdgeState:
    """A state of the contact branch: edge radius c (m), separation d (m), displacements w (m)
    on the grid scaled to c (lam = c / r_k^0), Newton iterations and residual (m), and the
    gaps h (m) and pressures P (Pa) of the converged iterate. ``problem`` (the
    :class:`ContactProblem` of the scaled grid) is built when first asked for: a trace needs
    it for a few states only (the landing's stability), the rest reads h, P and lam."""

    c: float
    d: float
    w: np.ndarray
    n_iter: int
    residual: float
    lam: float = 1.0
    h: np.ndarray = None
    P: np.ndarray = None
    dd_dc: float = math.nan
    force: float | None = None    # the caller's force of this state (N), once computed
    make_problem: object = field(default=None, repr=False)
    _problem: object = field(default=None, repr=False)

    @property
    def problem(self):
        if self._problem is None:
            self._problem = self.make_problem(self.c)
        return self._problem


class _Newton:
    """Newton on K w - P(h) = 0, h_k = g (the pinned gap on node k) in the unknowns (w, d),
    on a grid scaled by lam from a reference grid (C = lam C0, K = K0 / lam): the shared
    solver of the contact branch (k the edge node, lam = c / r_k^0) and the approach branch
    (k = 0, lam = 1).

    The system is solved with its first n rows multiplied by lam,

        [K0 + lam diag(D), -lam D; -e_k^T, 1] dx = [lam P - K0 w; g - h_k],   D = P'(h),

    whose matrix changes along the branch only through lam D (the law's stiffness in the
    cohesive zone, which sits on the same nodes at every state of the scaled grid): the last
    factorisation is kept and serves the next solve, if its state lies within REUSE_SPAN in
    the parameter (the root searches' solves), as a chord Jacobian while it contracts the
    residual CHORD_RATE-fold per step (the slope's factorisation, at a converged state, is
    the best chord Jacobian for a nearby one).
    """

    def _setup(self, C0, K0, shape0, nodes0, k, tol):
        self.C0, self.K0, self.shape0, self.nodes0 = C0, K0, shape0, nodes0
        self.k, self.tol = k, tol
        self._kdiag0 = np.diag(K0).copy()
        self.n = n = K0.shape[0]
        self.n_solves = 0
        self.n_iter = 0
        self.n_factor = 0
        # the Jacobian's fixed part: K0 and the pinned gap's row
        J0 = np.zeros((n + 1, n + 1))
        J0[:n, :n] = K0
        J0[n, k] = -1.0
        J0[n, n] = 1.0
        self._J0 = J0
        self._diag = np.arange(n) * (n + 2)     # flat indices of J's first n diagonal entries
        self._lu = None                         # the last factorisation (lu, piv)
        self._lu_at = math.nan                  # the parameter c of its state

    def _pressure(self, h):
        P = self._laws[0].pressure(h)
        for law in self._laws[1:]:
            P = P + law.pressure(h)
        return P

    def _dpressure(self, h):
        D = self._laws[0].dpressure(h)
        for law in self._laws[1:]:
            D = D + law.dpressure(h)
        return D

    def _factorise(self, lam, D):
        """Factorise the scaled Jacobian at law stiffness D (Pa/m); False if singular."""
        J = self._J0.copy()
        lD = lam * D
        J.ravel()[self._diag] += lD
        J[:self.n, self.n] = -lD
        lu, piv, info = lapack.dgetrf(J, overwrite_a=True)
        self.n_factor += 1
        if info > 0:
            self._lu = None
            return False
        self._lu = (lu, piv)
        return True

    def _exact_solve(self, lam, D, b, c):
        """x with (scaled Jacobian at D) x = b, on a fresh factorisation at the state of
        parameter c, kept for the next solve. (At these sizes a factorisation, ~30 us, costs
        less than the ~6 corrections that iterative refinement on a nearby state's takes to
        reach round-off: measured.)"""
        if not self._factorise(lam, D):
            raise ConvergenceError("edge branch: singular Jacobian", residual=math.nan,
                                   n_iter=0)
        self._lu_at = c
        return lapack.dgetrs(*self._lu, b)[0]

    def _newton(self, lam, contour, c, w0, d0, ge):
        """Newton on K w - P(h) = 0, h_k = ge with h = contour + d - w (contour: the shape on
        the scaled grid's nodes) from (w0, d0), steps limited so that no gap closes by more
        than GAP_CLOSURE of itself; the state is labelled by the parameter c. Returns an
        EdgeState or None if Newton did not converge in MAX_ITER iterations."""
        n, k = self.n, self.k
        C0, K0 = self.C0, self.K0
        w, d = np.array(w0, float), float(d0)
        self.n_solves += 1
        rhs = np.empty(n + 1)
        if self._lu is not None and abs(c - self._lu_at) > REUSE_SPAN * abs(c):
            self._lu = None     # another state's Jacobian, too far away to be a chord
        last = math.inf         # the residual before the last step
        n_lu = self.n_factor
        for it in range(1, MAX_ITER + 1):
            safe_point()
            h = (contour + d) - w
            if h.min() <= 0:
                return None
            P = self._pressure(h)
            res = float(np.abs(w - lam * (C0 @ P)).max())
            if not math.isfinite(res):
                raise ConvergenceError(f"edge branch: the law's pressure is not finite at "
                                       f"c = {c:.6g} m (smallest gap {h.min():.6g} m)",
                                       d=d, residual=res, n_iter=it - 1)
            g = h[k] - ge
            if res <= self.tol and abs(g) <= 1e-9 * ge:
                self.n_iter += it - 1
                n_lu = self.n_factor - n_lu
                return EdgeState(c, d, w, n_lu + (it - 1 - n_lu) // CHORD_PER_FACTOR,
                                 res, lam, h, P, make_problem=self.problem)
            r = max(res, abs(g))
            # chord: a factorisation serves while it contracts the residual by CHORD_RATE
            # per step (a solve with it costs a tenth of a factorisation)
            if self._lu is None or r > CHORD_RATE * last:
                if not self._factorise(lam, self._dpressure(h)):
                    return None
                self._lu_at = c
            rhs[:n] = lam * P - K0 @ w
            rhs[n] = -g
            last = r
            dx = lapack.dgetrs(*self._lu, rhs)[0]
            if not math.isfinite(float(np.add.reduce(dx))):
                return None
            closing = dx[:n] - dx[n]        # dh = dd - dw: gaps close where dw > dd
            worst = float((closing / h).max())
            alpha = 1.0 if worst <= GAP_CLOSURE else GAP_CLOSURE / worst
            w = w + alpha * dx[:n]
            d = d + alpha * dx[n]
        self.n_iter += MAX_ITER
        return None

    def node_softening_ratio(self, st):
        """max_i -P'(h_i) / K_ii at a state (on a scaled grid K = K0 / lam; lam = 1 on the
        centre-gap branch's fixed grid), as :meth:`ContactProblem.node_softening_ratio`
        without a gap constraint."""
        return float((-self._dpressure(st.h) * st.lam / self._kdiag0).max())


class EdgeBranch(_Newton):
    """Solves of the contact branch at given edge radii.

    Parameters
    ----------
    base : GreenOperator
        The operator on the reference grid.
    k : int
        Index of the edge node of the reference grid.
    sphere, effects
        As :class:`~femadh.contact.problem.ContactProblem`.
    edge_gap : float
        The gap g_e (m) that marks the edge.
    tol : float
        Residual of eq (6) every state meets (m).
    """

    def __init__(self, base, k, sphere, effects, edge_gap, tol):
        self.base, self.sphere, self.effects = base, sphere, effects
        self.edge_gap = edge_gap
        self.r0 = float(base.grid.nodes[k])
        # the laws' own pressure and derivative, called directly in the Newton loop (the
        # problem's sum checks every law's values for NaN at every call: here one check of
        # the residual, which any non-finite pressure makes non-finite, does it per iteration)
        self._laws = tuple(effects.values())
        self._base = ContactProblem(base, sphere, effects, check_laws=False,
                                    subgrid=False)
        self._setup(base.compliance, base.stiffness, None, base.grid.nodes, k, tol)
        self._areas0 = base.grid.areas

    def problem(self, c):
        """The problem on the grid whose node k sits at c (m): the reference problem with its
        operator scaled (its energy stiffness diag(area) K scales like lambda too)."""
        return scaled_problem(self._base, self.base, self.sphere, c / self.r0)

    def softening_ratio(self):
        """The largest softening stiffness of the laws against the edge node's own stiffness
        K_kk on the reference grid (:meth:`ContactProblem.surface_force_stiffness`'s law
        side): near 1 a node snaps on its own."""
        _, _, soft, _ = self._base.surface_force_stiffness()
        return soft / float(self._base.K[self.k, self.k])

    def grid_force(self, st):
        """The force (N) of a state's pressure on the analysis disk of its scaled grid (the
        annuli's areas scale like lam^2)."""
        return st.lam * st.lam * float(self._areas0 @ st.P)

    def radius(self, st):
        """The analysis radius (m) of a state's scaled grid."""
        return st.lam * self.base.grid.radius

    def solve(self, c, w0, d0):
        """The state with its edge at c (m) from the guess (w0, d0) (Newton, steps limited so
        that no gap closes by more than GAP_CLOSURE of itself). Returns an EdgeState, or
        None if Newton did not converge in MAX_ITER iterations."""
        lam = c / self.r0
        return self._newton(lam, self.sphere.shape(lam * self.nodes0), c, w0, d0,
                            self.edge_gap)

    def slope(self, st):
        """dd/dc (-) along the branch at a state: J dx/dc = -dF/dc with K = K^0 r_k^0 / c and
        the contour's shape on nodes that move with c."""
        n, k, lam = self.n, self.k, st.lam
        r = lam * self.nodes0
        dshape = self.sphere.slope(r) * r / st.c          # d shape(r_i(c)) / dc
        D = self._dpressure(st.h)
        rhs = np.empty(n + 1)          # (the first n rows times lam, as the Jacobian's)
        rhs[:n] = (self.K0 @ st.w) / st.c + lam * D * dshape
        rhs[n] = -dshape[k]
        return float(self._exact_solve(lam, D, rhs, st.c)[n])


class CentreGapBranch(_Newton):
    """Solves of the approach branch (no contact yet) at given centre gaps, on one grid.

    Before the jump-in the surface bulges towards the sphere and the gap at r = 0,
    g = d - w(0), decreases monotonically along the branch, through the jump-in fold (d(g)
    has its smallest value there: a root of dd/dg, not a turning point of g). The branch is
    therefore traced by plain Newton in g with the same unknowns (w, d) and the same pinned
    gap as the contact branch's edge node, here node 0 at g: K w - P(h) = 0, h_0 - g = 0.

    Parameters
    ----------
    problem : ContactProblem
        The approach grid's problem (a node at r = 0).
    tol : float
        Residual of eq (6) every state meets (m).
    """

    def __init__(self, problem, tol):
        if problem.grid.nodes[0] != 0.0:
            raise ValueError("centre-gap branch: the grid needs a node at r = 0")
        self.pb = problem
        self.sphere, self.effects = problem.sphere, problem.effects
        self._laws = tuple(problem.effects.values())
        self._setup(problem.C, problem.K, problem.shape, problem.grid.nodes, 0, tol)

    def problem(self, g):
        return self.pb

    def solve(self, g, w0, d0):
        """The approach state of centre gap g (m) from the guess (w0, d0); an EdgeState
        (``c`` = g) or None if Newton did not converge."""
        return self._newton(1.0, self.shape0, g, w0, d0, g)

    def at_separation(self, d, w0):
        """The approach state at separation d (m) from the guess w0 (interpolated between
        two traced states that bracket d): Newton on K w - P(d + shape - w) = 0 with chord
        steps as in :meth:`_newton`. Returns an EdgeState (``c`` = its centre gap) or None if
        Newton did not converge."""
        pb, n = self.pb, self.n
        K, C = pb.K, pb.C
        contour = pb.contour(d)
        w = np.array(w0, float)
        lu, last, n_lu = None, math.inf, 0
        self.n_solves += 1
        for it in range(1, MAX_ITER + 1):
            safe_point()
            h = contour - w
            if h.min() <= 0:
                return None
            P = self._pressure(h)
            res = float(np.abs(w - C @ P).max())
            if not math.isfinite(res):
                raise ConvergenceError(f"centre-gap branch: the law's pressure is not finite "
                                       f"at d = {d:.6g} m", d=d, residual=res, n_iter=it - 1)
            if res <= self.tol:
                self.n_iter += it - 1
                self.n_factor += n_lu
                return EdgeState(float(h[0]), d, w, it - 1, res, 1.0, h, P,
                                 make_problem=self.problem)
            if lu is None or res > CHORD_RATE * last:
                J = K.copy()
                J.ravel()[np.arange(n) * (n + 1)] += self._dpressure(h)
                lu, piv, info = lapack.dgetrf(J, overwrite_a=True)
                n_lu += 1
                if info > 0:
                    return None
            last = res
            dw = lapack.dgetrs(lu, piv, P - K @ w)[0]
            if not np.all(np.isfinite(dw)):
                return None
            alpha = 1.0
            if dw.max() > 0:        # gaps close where dw > 0
                pos = dw > 0
                alpha = min(1.0, float(np.min(GAP_CLOSURE * h[pos] / dw[pos])))
            w = w + alpha * dw
        self.n_iter += MAX_ITER
        self.n_factor += n_lu
        return None

    def slope(self, st):
        """dd/dg (-) along the branch: J dx/dg = -dF/dg = (0, ..., 0, 1)."""
        rhs = np.zeros(self.n + 1)
        rhs[self.n] = 1.0
        return float(self._exact_solve(1.0, self._dpressure(st.h), rhs, st.c)[self.n])


@functools.lru_cache(maxsize=8)
def gauss_legendre(n):
    """Nodes and weights of n-point Gauss-Legendre on [-1, 1] (computed once per n: an
    eigenvalue problem of ~1 ms, a tenth of a small member's trace)."""
    x, w = np.polynomial.legendre.leggauss(n)
    x.flags.writeable = w.flags.writeable = False
    return x, w


def tail_energy_change(law, radius, a, d1, d2):
    """E_tail(d1) - E_tail(d2) (J): the change of the interaction energy beyond the analysis
    radius a of a rigid paraboloid, E_tail(d) = 2 pi int_a^inf U(d + r^2/2R) r dr
    = 2 pi R int_b^inf U(h) dh with b = d + a^2/2R (the surface is undeformed there), i.e.
    2 pi R int_b1^b2 U(h) dh: 16-point Gauss-Legendre (U is smooth at these gaps, b >= 20 z0
    at the smallest analysis radius)."""
    b1, b2 = d1 + a * a / (2 * radius), d2 + a * a / (2 * radius)
    x, wq = gauss_legendre(16)
    h = 0.5 * (b1 + b2) + 0.5 * (b2 - b1) * x
    return 2 * math.pi * radius * 0.5 * (b2 - b1) * float(wq @ law.energy(h))


def extrapolate(states, c):
    """(w, d) at c (m) by the Lagrange polynomial through the given states (in c): the
    march's predictor (the state on the scaled grid is a smooth function of c; with three
    states the error falls like step^3 instead of the secant's step^2)."""
    cs = [s.c for s in states]
    w, d = 0.0, 0.0
    for i, si in enumerate(states):
        li = 1.0
        for j, cj in enumerate(cs):
            if j != i:
                li *= (c - cj) / (cs[i] - cj)
        w = w + li * si.w
        d = d + li * si.d
    return w, d


class BranchTrace:
    """The traced contact branch: states in increasing c and what is read off it."""

    def __init__(self, branch):
        self.branch = branch
        self.states = []

    def _guess(self, c):
        """Secant extrapolation in c from the two nearest traced states (w on the moving
        nodes is a smooth function of c)."""
        s = sorted(self.states, key=lambda x: abs(x.c - c))[:2]
        if len(s) == 1:
            return s[0].w, s[0].d
        a, b = s
        t = (c - a.c) / (b.c - a.c)
        return a.w + t * (b.w - a.w), a.d + t * (b.d - a.d)

    def at(self, c):
        """The state at edge radius c (from the traced states); ConvergenceError if Newton
        fails. A traced state at exactly c is returned as it is (the root and maximum
        searches start from brackets of traced states)."""
        for st in self.states:
            if st.c == c:
                return st
        w0, d0 = self._guess(c)
        st = self.branch.solve(c, w0, d0)
        if st is None:
            raise ConvergenceError(f"edge branch: Newton failed at edge radius c = {c:.6g} m",
                                   d=d0, residual=math.nan, n_iter=MAX_ITER)
        return st

    def march(self, start, direction, done, step0=STEP0):
        """Trace from ``start`` (an EdgeState) in the direction of c (+1, -1), the first
        relative step ``step0``, until ``done(states_in_march_order)`` is True; the states
        join ``self.states``."""
        run = [start]
        step = step0
        while not done(run):
            if len(self.states) + len(run) > MAX_STATES:
                raise ConvergenceError(f"edge branch: more than {MAX_STATES} states",
                                       d=run[-1].d, residual=math.nan, n_iter=0)
            p = run[-1]
            c = p.c * (1 + direction * step)
            w0, d0 = extrapolate(run[-PREDICTOR_POINTS:], c)
            st = self.branch.solve(c, w0, d0)
            if st is None:
                step *= 0.5
                if step < STEP_MIN:
                    raise ConvergenceError(f"edge branch stalled at c = {p.c:.6g} m "
                                           f"(d = {p.d:.6g} m): Newton fails at every step",
                                           d=p.d, residual=math.nan, n_iter=MAX_ITER)
                continue
            run.append(st)
            step = min(STEP_MAX, step * (1.5 if st.n_iter <= TARGET_ITER else 0.7))
        self.states.extend(run[1:])
        self.states.sort(key=lambda x: x.c)
        return run

    def fold(self, lo, hi):
        """The fold (root of dd/dc) between edge radii lo and hi (m)."""
        cache = {}

        def slope(c):
            st = self.at(c)
            if math.isnan(st.dd_dc):
                st.dd_dc = self.branch.slope(st)
            cache[c] = st
            return st.dd_dc
        c = optimize.brentq(slope, lo, hi, xtol=C_XTOL * hi, rtol=4 * np.finfo(float).eps)
        return cache.get(c) or self.at(c)

    def where_d(self, d, lo, hi):
        """The state at separation d (m) between edge radii lo and hi."""
        cache = {}

        def f(c):
            st = self.at(c)
            cache[c] = st
            return st.d - d
        c = optimize.brentq(f, lo, hi, xtol=C_XTOL * hi, rtol=4 * np.finfo(float).eps)
        return cache.get(c) or self.at(c)

    def maximize(self, value, lo, mid, hi):
        """The state of largest value(state) in the bracket of traced states lo < mid < hi
        (value(mid) >= value(lo), value(hi)): successive parabolic interpolation through the
        three best states, which keep bracketing the maximum (a smooth maximum: the vertex
        converges superlinearly; a vertex outside the bracket or too near a known state is
        replaced by a golden-section point). Stops when the vertex moves by less than
        MAX_XTOL of c, after at most MAX_PARABOLA solves. Returns (value, state)."""
        pts = [(st.c, value(st), st) for st in (lo, mid, hi)]
        for _ in range(MAX_PARABOLA):
            (a, fa, _), (b, fb, _), (c, fc, _) = pts
            num = (b - a) ** 2 * (fb - fc) - (b - c) ** 2 * (fb - fa)
            den = (b - a) * (fb - fc) - (b - c) * (fb - fa)
            x = b - 0.5 * num / den if den != 0 else math.nan
            tol = MAX_XTOL * c
            if abs(x - b) <= tol:       # the vertex is on the best state: located
                break
            if not (a + tol < x < c - tol):
                # a degenerate vertex: golden section in the larger half
                x = b + 0.381966 * ((c - b) if c - b > b - a else (a - b))
            st = self.at(x)
            fx = value(st)
            if fx > fb:     # the new best (the old one bounds on its side)
                pts = [pts[0], (x, fx, st), pts[1]] if x < b else [pts[1], (x, fx, st), pts[2]]
            else:           # the best stays: x bounds on its side
                pts = [(x, fx, st), pts[1], pts[2]] if x < b else [pts[0], pts[1], (x, fx, st)]
        else:
            raise ConvergenceError(f"edge branch: the largest value between c = {lo.c:.6g} "
                                   f"and {hi.c:.6g} m not located in {MAX_PARABOLA} solves",
                                   d=pts[1][2].d, residual=math.nan, n_iter=MAX_PARABOLA)
        return pts[1][1], pts[1][2]
