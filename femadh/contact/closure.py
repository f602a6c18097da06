"""Paper 1's Hertz closure as the paper states it: one Newton system in the free surface
displacements *and* a continuous contact radius r_c, traced in d through its folds.

Formulation (paper 1 eqs 3-10 and the Fig 2 flowchart)
------------------------------------------------------
Inside the contact, r <= r_c, the gap is clamped to the asperity spacing, h = sigma (eq 8 held
with equality: the flowchart's "w = b - sigma in the contact region"), and the contact pressure
is Hertz's (eq 9), P_el = p_m sqrt(1 - r^2/r_c^2) with p_m = 2 E* r_c/(pi R). Outside, eq (10)
gives the surface:

    w10(r) = P_in D(r, r_c) + P_j [D(r, e_j+1) - D(r, r_c)]
             + sum_{k > j} P(h_k) [D(r, e_k+1) - D(r, e_k)] - W_H(r; r_c)

- D(r, a): displacement at radius r of a unit pressure on the disk r < a (exact, elliptic
  integrals: :func:`femadh.elastic.green.disk_displacement`);
- P_in = P(sigma) + P_LJa: the gap laws at h = sigma plus the eq (20) asperity adhesion, a
  constant attractive pressure acting "over the contact region" r < r_c only;
- e_j <= r_c < e_j+1: the annulus cut by the contact edge; its outer part carries the law at
  its node's gap, P_j = P(h_j) (P(sigma) if that node is inside), so the load is continuous in
  r_c (no jumps when the edge crosses a node or an annulus edge);
- W_H(r; r_c): the Hertz displacement of eq (9) in closed form (Johnson eq 3.42), no
  discretisation of the sqrt edge.

Unknowns: w at the nodes outside r_c (r_k > r_c) and r_c. Equations: eq (10) at those nodes,
F_k = w_k - w10(r_k) = 0, and the edge condition of the flowchart, w(r_c) = b(r_c) - sigma,
evaluated *at r = r_c itself* through the influence of every annulus at that radius,

    G = w10(r_c) - (b(r_c) - sigma) = 0.

One bordered Newton system: the w-block I + coef diag(P'(h)), the r_c column d/dr_c of the
Hertz displacement and of the clamped disk's load (the ring influence dD/da), the edge row d/dw
and d/dr_c of w10(r_c) - b(r_c). A plain backtracking line search on ||(F, G)||_2. Eq (10) is
*not* imposed inside the contact: w = b - sigma there, and its distance from w10 is reported
(``diagnostics["eq10_violation_inside_m"]``). With A = 0 the closure is exactly Hertz:
G = d - sigma + r_c^2/R, so r_c = sqrt(R (sigma - d)).

Stability
---------
The closure has no energy (the Hertz shape is imposed, not derived from a minimum), so
"stable" cannot mean an energy minimum. We call a contact state stable when it lies on the part
of the solution branch connected to the Hertz limit (A -> 0) without crossing a fold, i.e. when
the determinant of the joint Jacobian d(F, G)/d(w_free, r_c) (unknowns and equations in that
order) has the sign it has in the Hertz limit: negative (there the w-block is the identity and
dG/dr_c = -2 r_c/R). The determinant vanishes exactly where the branch x(d) folds (implicit
function theorem), so its sign flips at snap-in and snap-out. Read through the paper's own
iteration: with the w-block regular, det < 0 means the reduced edge residual G(r_c) decreases
through its root, so an under-relaxed r_c update (the flowchart's beta) is drawn back to it. The
sign of the w-block alone, the Schur complement and the branch slope dr_c/dd are kept in
``diagnostics``. A state without contact (r_c = 0) is a true equilibrium of an energy (elastic +
gap laws): it is stable when the energy Hessian is positive definite, as in femadh's solvers.

Landing rule after a fold
-------------------------
At the landing separation the contact branch is scanned in r_c (solving for (w, d) at fixed
r_c, which passes the folds in d), from the departing state's r_c in the direction the contact
moves on the snap (growing on approach, shrinking on retract). The surface lands on the first
*stable* state at that d met by the scan: on approach the stable state with the smallest r_c
above the departing one, on retract the one with the largest r_c below it, or the free
(r_c = 0) state when the scan reaches r_c -> 0 first. With no such state a ConvergenceError
gives the scanned range of d(r_c). A step between the free surface and contact is accepted as
continuous only if the contact branch is stable at its onset (half a node spacing); otherwise
touch-down is itself a fold (eq 20's pull grows with r_c) and the same landing applies.

For an operator with no influence function at arbitrary radii (FE), :class:`InterpolatedInfluence`
interpolates the disk influences between the node/edge radii (first order in the edge position);
the Green operator uses the exact functions (:class:`GreenInfluence`).
"""
from dataclasses import dataclass
import math
import time

import numpy as np
from scipy import linalg, special

from ..effects.asperity import AsperityAdhesion
from ..elastic.green import GreenOperator
from ..errors import ConvergenceError
from ..reference.hertz import (hertz_annulus_force, hertz_annulus_force_drc,
                               hertz_displacement)
from .continuation import Jump, Sweep
from .problem import State

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
#: below this fraction of the first node spacing the contact has closed (r_c -> 0)
RC_FLOOR_FRACTION = 1e-3
#: K(m) is log-singular at m = 1 (the slope of a uniform disk load's displacement at its edge);
#: derivatives are evaluated at m <= 1 - M_CLIP there. Only the Jacobian sees this.
M_CLIP = 1e-16
#: smallest continuation step as a fraction of the grid step: folds are located to this
MIN_STEP_FRACTION = 2.0**-10
#: solves allowed between two requested separations (healthy steps need a handful, a fold ~12)
MAX_SOLVES_PER_STEP = 200
#: a corrector moving any gap by more than this fraction of it away from the prediction has
#: left the branch (jumped), even if it converged
MAX_CORRECTION_FRACTION = 0.25
#: ratio of successive contact radii in the landing scan, and its largest step in node spacings
SCAN_RATIO, SCAN_MAX_NODES = 1.12, 4.0
#: iteration budget (times max_iter) of the scan's first point
ENTRY_BUDGET = 5


# --------------------------------------------------------------------------- influences

def _ellipk(m):
    return special.ellipk(np.minimum(m, 1.0 - M_CLIP))


def disk_displacement_da(r, a, e_star):
    """d/da of the displacement at r of a unit pressure on the disk of radius a (m/Pa per m).

    The load added at the rim is a ring of radius a: dD/da = 4 a K(m) / (pi E* (r + a)),
    m = 4 r a / (r + a)^2 (log-singular at r = a; clipped there, see M_CLIP). At r = 0: 2/E*.
    """
    r, a = np.broadcast_arrays(np.asarray(r, float), np.asarray(a, float))
    m = 4.0 * r * a / (r + a) ** 2
    return 4.0 * a * _ellipk(m) / (math.pi * e_star * (r + a))


def disk_displacement_dr_inside(r, a, e_star):
    """d/dr of the displacement of a unit pressure on the disk of radius a, for r <= a (1/Pa).

    w = 4 a E(m)/(pi E*), m = r^2/a^2, so dw/dr = 4 a (E(m) - K(m)) / (pi E* r); for small m the
    series -(r/(a E*)) (1 + 3m/8 + 15m^2/64) avoids the cancellation of E - K.
    """
    r, a = np.broadcast_arrays(np.asarray(r, float), np.asarray(a, float))
    m = (r / a) ** 2
    out = np.empty(r.shape)
    small = m < 1e-3
    ms = m[small]
    out[small] = -(r[small] / (a[small] * e_star)) * (1 + 3 * ms / 8 + 15 * ms * ms / 64)
    big = ~small
    mb = np.minimum(m[big], 1.0 - M_CLIP)
    out[big] = 4 * a[big] * (special.ellipe(mb) - special.ellipk(mb)) / (math.pi * e_star
                                                                           * r[big])
    return out


class GreenInfluence:
    """Exact influences of the half-space (Green function) at any radius.

    Parameters
    ----------
    problem : ContactProblem
        Its operator must be a :class:`GreenOperator` (for E*); its grid gives nodes/edges.
    """

    exact = True

    def __init__(self, problem):
        self.e_star = problem.operator.e_star
        self.radius = problem.sphere.radius
        self.nodes = problem.grid.nodes
        self.edges = problem.grid.edges

    def disk_nodes(self, a):
        """D(r_i, a) (m/Pa) at every node for a unit pressure on r < a (the formulas of
        :func:`~femadh.elastic.green.disk_displacement` for one radius a, without broadcasting:
        this is the inner loop)."""
        r = self.nodes
        out = np.empty(r.size)
        k = int(np.searchsorted(r, a, side="right"))     # r[:k] <= a
        out[:k] = 4.0 * a / math.pi * special.ellipe((r[:k] / a) ** 2)
        out[k:] = a * a / r[k:] * special.hyp2f1(0.5, 0.5, 2.0, (a / r[k:]) ** 2)
        return out / self.e_star

    def disk_nodes_da(self, a):
        """dD(r_i, a)/da (1/Pa) at every node."""
        return disk_displacement_da(self.nodes, a, self.e_star)

    def disk_at(self, r, k0):
        """D(r, e_k) (m/Pa) at r for the edges k >= k0 (all > r: the inside formula)."""
        e = self.edges[k0:]
        return 4.0 * e / (math.pi * self.e_star) * special.ellipe((r / e) ** 2)

    def disk_at_dr(self, r, k0):
        """dD(r, e_k)/dr (1/Pa) at r for the edges k >= k0."""
        return disk_displacement_dr_inside(r, self.edges[k0:], self.e_star)

    def disk_self(self, a):
        """D(a, a) = 4a/(pi E*) (the disk's own rim, E(1) = 1) and its total derivative."""
        return 4 * a / (math.pi * self.e_star), 4 / (math.pi * self.e_star)

    def hertz_nodes(self, a):
        """Closed-form Hertz displacement (m, into the disk) of eq (9) at every node.

        With p_m = 2E* a/(pi R): W_H = (2a^2 - r^2)/(2R) inside (Johnson eq 3.42a),
        [(2a^2 - r^2) asin(a/r) + a sqrt(r^2 - a^2)]/(pi R) outside.
        """
        p_m = 2 * self.e_star * a / (math.pi * self.radius)
        return hertz_displacement(self.nodes, a, p_m, self.e_star)

    def hertz_nodes_da(self, a):
        """d/da of :meth:`hertz_nodes`: 2a/R inside, 4 a asin(a/r)/(pi R) outside (m/m)."""
        R, r = self.radius, self.nodes
        return np.where(r <= a, 2 * a / R,
                        4 * a * np.arcsin(np.minimum(a / np.maximum(r, a), 1.0)) / (math.pi * R))

    def hertz_self(self, a):
        """W_H(a; a) = a^2/(2R) and its total derivative a/R."""
        return a * a / (2 * self.radius), a / self.radius


class InterpolatedInfluence:
    """Influences from a compliance matrix alone (any operator, e.g. FE): an approximation.

    An FE operator knows the displacement at its nodes of a load on its annuli and nothing in
    between. The disk influence D(r_i, a) is interpolated linearly in a^2 (the load grows
    with the area) between the edge radii, the influence at r = r_c linearly in r between the
    nodes, and the Hertz displacement is the operator's response to the exact annulus averages
    of eq (9), interpolated the same way. First order in the edge position where the Green
    operator is exact; use GreenInfluence whenever the operator is a Green function.
    """

    exact = False

    def __init__(self, problem):
        self.radius = problem.sphere.radius
        self.e_star = getattr(problem.operator, "e_star", None)
        self.nodes = problem.grid.nodes
        self.edges = problem.grid.edges
        self.areas = problem.grid.areas
        C = problem.C
        self.W = np.concatenate([np.zeros((C.shape[0], 1)), np.cumsum(C, axis=1)], axis=1)
        self.C = C

    def _cell(self, a):
        k = int(np.clip(np.searchsorted(self.edges, a, side="right") - 1, 0, self.nodes.size - 1))
        e0, e1 = self.edges[k], self.edges[k + 1]
        return k, (a * a - e0 * e0) / (e1 * e1 - e0 * e0), 2 * a / (e1 * e1 - e0 * e0)

    def disk_nodes(self, a):
        k, t, _ = self._cell(a)
        return self.W[:, k] + t * (self.W[:, k + 1] - self.W[:, k])

    def disk_nodes_da(self, a):
        k, _, dt = self._cell(a)
        return dt * (self.W[:, k + 1] - self.W[:, k])

    def _row_at(self, r):
        """Interpolation weights of node values at radius r (linear in r), and their d/dr."""
        n = self.nodes
        i = int(np.clip(np.searchsorted(n, r, side="right") - 1, 0, n.size - 2))
        t = (r - n[i]) / (n[i + 1] - n[i])
        return i, t, 1.0 / (n[i + 1] - n[i])

    def disk_at(self, r, k0):
        i, t, _ = self._row_at(r)
        W = self.W[:, k0:]
        return (1 - t) * W[i] + t * W[i + 1]

    def disk_at_dr(self, r, k0):
        i, _, dt = self._row_at(r)
        W = self.W[:, k0:]
        return dt * (W[i + 1] - W[i])

    def disk_self(self, a):
        i, t, dt = self._row_at(a)
        k, s, ds = self._cell(a)
        Wl = self.W[[i, i + 1]][:, [k, k + 1]]
        def val(tt, ss):
            return ((1 - tt) * ((1 - ss) * Wl[0, 0] + ss * Wl[0, 1])
                    + tt * ((1 - ss) * Wl[1, 0] + ss * Wl[1, 1]))
        d_dt = ((1 - s) * Wl[1, 0] + s * Wl[1, 1]) - ((1 - s) * Wl[0, 0] + s * Wl[0, 1])
        d_ds = (1 - t) * (Wl[0, 1] - Wl[0, 0]) + t * (Wl[1, 1] - Wl[1, 0])
        return val(t, s), d_dt * dt + d_ds * ds

    def hertz_nodes(self, a):
        return self.C @ (hertz_annulus_force(self.edges, a, self.radius, self.e_star)
                         / self.areas)

    def hertz_nodes_da(self, a):
        return self.C @ (hertz_annulus_force_drc(self.edges, a, self.radius, self.e_star)
                         / self.areas)

    def hertz_self(self, a):
        wh, dwh = self.hertz_nodes(a), self.hertz_nodes_da(a)
        i, t, dt = self._row_at(a)
        val = (1 - t) * wh[i] + t * wh[i + 1]
        # total derivative: the field's change with a, plus its slope at r = a
        return val, (1 - t) * dwh[i] + t * dwh[i + 1] + dt * (wh[i + 1] - wh[i])


def influence_for(problem):
    """Exact Green influences for a Green operator, else the interpolated approximation."""
    if isinstance(problem.operator, GreenOperator):
        return GreenInfluence(problem)
    return InterpolatedInfluence(problem)


# --------------------------------------------------------------------------- the system

@dataclass
class _Eval:
    """Residuals (and optionally the Jacobian blocks) of the closure at (d, w, r_c)."""

    m: int              # first free node (nodes[:m] <= r_c are clamped)
    j: int              # annulus cut by the contact edge
    h: np.ndarray       # gaps (sigma inside)
    P: np.ndarray       # gap-law pressure carried by each node's annulus (P(sigma) inside)
    w10: np.ndarray     # eq (10) displacement at every node
    F: np.ndarray       # w - w10 on the free nodes
    G: float            # edge residual w10(r_c) - (b(r_c) - sigma)
    d: float = None
    r_c: float = None
    cache: dict = None  # influences reused by the Jacobian
    A: np.ndarray = None
    f_rc: np.ndarray = None
    f_d: np.ndarray = None
    g_w: np.ndarray = None
    g_rc: float = None
    g_d: float = None

    @property
    def residual(self):
        """max |w - w10| on the free nodes plus |edge residual| (m)."""
        return (float(np.max(np.abs(self.F))) if self.F.size else 0.0) + abs(self.G)

    @property
    def norm(self):
        return math.sqrt(float(self.F @ self.F) + self.G * self.G)

    def jacobian(self, border):
        """Bordered Jacobian with the last unknown r_c (``"r_c"``) or d (``"d"``)."""
        col, corner = (self.f_rc, self.g_rc) if border == "r_c" else (self.f_d, self.g_d)
        n = self.F.size
        J = np.empty((n + 1, n + 1))
        J[:n, :n] = self.A
        J[:n, n] = col
        J[n, :n] = self.g_w
        J[n, n] = corner
        return J


def _finite_or_raise(x, what, d, where):
    """Raise ConvergenceError naming the quantity and the first offending index."""
    x = np.asarray(x, float)
    bad = np.flatnonzero(~np.isfinite(np.atleast_1d(x)))
    if bad.size:
        k = int(bad[0])
        value = np.atleast_1d(x)[k]
        raise ConvergenceError(f"closure: non-finite {what} ({value}) at {where(k)}", d=d)


class ClosureSystem:
    """The discrete closure of one ContactProblem (see the module docstring).

    Parameters
    ----------
    problem : ContactProblem
        With a sigma gap; its contact_model is not consulted (this is the closure).
    influence : GreenInfluence or InterpolatedInfluence, optional
        Default: exact Green influences for a Green operator, interpolated otherwise.
    """

    def __init__(self, problem, influence=None):
        if problem.sigma is None:
            raise ValueError("the Hertz closure needs an asperity gap sigma (eq 8)")
        self.problem = problem
        self.sigma = float(problem.sigma)
        self.nodes = problem.grid.nodes
        self.edges = problem.grid.edges
        self.n = self.nodes.size
        self.C = problem.C
        self.W = np.concatenate([np.zeros((self.n, 1)), np.cumsum(self.C, axis=1)], axis=1)
        self.shape = problem.shape
        self.sphere = problem.sphere
        self.infl = influence or influence_for(problem)
        # eq (20) acts as a constant pressure over r < r_c: taken out of the gap laws
        self.laws = {k: e for k, e in problem.effects.items()
                     if not isinstance(e, AsperityAdhesion)}
        self.p_asperity = sum(e.pressure_value for e in problem.effects.values()
                              if isinstance(e, AsperityAdhesion))
        self.p_sigma = self.law(np.array([self.sigma]))[0]
        _finite_or_raise(self.p_sigma, "gap-law pressure P(sigma) (Pa) of the clamped contact",
                         None, lambda k: f"h = sigma = {self.sigma * 1e9:.4g} nm")
        self.r_floor = RC_FLOOR_FRACTION * self.nodes[1]
        self.r_max = float(self.nodes[-1])

    # gap laws (everything but eq 20), attractive positive
    def law(self, h):
        out = np.zeros_like(np.asarray(h, float))
        for e in self.laws.values():
            out = out + e.pressure(h)
        return out

    def dlaw(self, h):
        out = np.zeros_like(np.asarray(h, float))
        for e in self.laws.values():
            out = out + e.dpressure(h)
        return out

    def split(self, r_c):
        """(m, j): nodes[:m] <= r_c are clamped; e_j <= r_c < e_j+1."""
        m = int(np.searchsorted(self.nodes, r_c, side="right"))
        j = int(np.clip(np.searchsorted(self.edges, r_c, side="right") - 1, 0, self.n - 1))
        return m, j

    def clamp(self, w, d, r_c):
        """w with the contact nodes set to b - sigma (the flowchart's clamp)."""
        w = np.array(w, float)
        m, _ = self.split(r_c)
        w[:m] = d + self.shape[:m] - self.sigma
        return w

    def evaluate(self, d, w, r_c, *, jac=False, it=None):
        """Residuals of eq (10) on the free nodes and of the edge condition, at (d, w, r_c);
        with ``jac`` also the Jacobian blocks (:meth:`add_jacobian`).

        Raises ConvergenceError at once on a non-finite pressure, displacement or residual,
        naming the separation d, the quantity and the node (and Newton iteration ``it``).
        """
        m, j = self.split(r_c)
        n = self.n
        nodes = self.nodes
        tag = f", Newton iteration {it}" if it is not None else ""
        h = d + self.shape - w
        h[:m] = self.sigma
        P = np.full(n, self.p_sigma)
        if m < n:
            P[m:] = self.law(h[m:])
            _finite_or_raise(P[m:], "gap-law pressure P(h) (Pa)", d, lambda k: (
                f"node {m + k} (r = {nodes[m + k] * 1e6:.4g} um, h = {h[m + k] * 1e9:.4g} nm)"
                + tag))
        p_in = self.p_sigma + self.p_asperity
        Ds = self.infl.disk_nodes(r_c)
        WH = self.infl.hertz_nodes(r_c)
        w10 = (self.C[:, j + 1:] @ P[j + 1:] + P[j] * (self.W[:, j + 1] - Ds) + p_in * Ds - WH)
        _finite_or_raise(w10, "eq (10) displacement w10 (m)", d, lambda k: (
            f"node {k} (r = {nodes[k] * 1e6:.4g} um), r_c = {r_c * 1e6:.6g} um" + tag))
        De = self.infl.disk_at(r_c, j + 1)             # edges e_{j+1} .. e_N
        Dself, dDself = self.infl.disk_self(r_c)
        WHs, dWHs = self.infl.hertz_self(r_c)
        cE = np.diff(De)                               # annuli j+1 .. N-1 seen from r_c
        w10e = float(cE @ P[j + 1:] + P[j] * (De[0] - Dself) + p_in * Dself - WHs)
        G = w10e - (float(self.sphere.contour(r_c, d)) - self.sigma)
        F = w[m:] - w10[m:]
        _finite_or_raise(np.append(F, G), "closure residual (m)", d, lambda k: (
            (f"node {m + k}" if k < F.size else f"the edge r_c = {r_c * 1e6:.6g} um") + tag))
        ev = _Eval(m, j, h, P, w10, F, G, d, r_c,
                   dict(Ds=Ds, De=De, cE=cE, Dself=Dself, dDself=dDself, dWHs=dWHs, tag=tag))
        return self.add_jacobian(ev) if jac else ev

    def add_jacobian(self, ev):
        """Fill the Jacobian blocks of an evaluation (bordered by r_c and by d)."""
        if ev.A is not None:
            return ev
        m, j, n, d, r_c, c = ev.m, ev.j, self.n, ev.d, ev.r_c, ev.cache
        P, h = ev.P, ev.h
        p_in = self.p_sigma + self.p_asperity
        dP = self.dlaw(h[m:]) if m < n else np.zeros(0)
        _finite_or_raise(dP, "gap-law stiffness dP/dh (Pa/m)", d,
                         lambda k: f"node {m + k}" + c["tag"])
        dDs = self.infl.disk_nodes_da(r_c)
        dWH = self.infl.hertz_nodes_da(r_c)
        dDe = self.infl.disk_at_dr(r_c, j + 1)
        coef = self.C[m:, m:].copy()
        coefE = np.empty(n - m)
        if m == j:        # the cut annulus's node is free: only its outer part is loaded
            coef[:, 0] = self.W[m:, j + 1] - c["Ds"][m:]
            coefE[0] = c["De"][0] - c["Dself"]
            coefE[1:] = c["cE"]
        else:
            coefE[:] = c["cE"]
        ev.A = coef * dP[None, :]
        ev.A[np.diag_indices_from(ev.A)] += 1.0
        ev.f_rc = -((p_in - P[j]) * dDs[m:] - dWH[m:])
        ev.g_w = -coefE * dP
        ev.g_rc = float(p_in * c["dDself"] + P[j] * (dDe[0] - c["dDself"])
                        + np.diff(dDe) @ P[j + 1:] - c["dWHs"] - self.sphere.slope(r_c))
        ev.f_d = -(coef @ dP)
        ev.g_d = float(coefE @ dP - 1.0)
        return ev

    # free surface (r_c = 0): w = C P(h) on every node; an energy exists here
    def evaluate_free(self, d, w, *, it=None):
        """Gaps, gap-law pressures and the residual w - C P(h) of eq (6) without contact."""
        nodes = self.nodes
        tag = f", Newton iteration {it}" if it is not None else ""
        h = d + self.shape - w
        P = self.law(h)
        _finite_or_raise(P, "gap-law pressure P(h) (Pa)", d, lambda k: (
            f"node {k} (r = {nodes[k] * 1e6:.4g} um, h = {h[k] * 1e9:.4g} nm)" + tag))
        F = w - self.C @ P
        _finite_or_raise(F, "eq (6) residual (m)", d, lambda k: f"node {k}" + tag)
        return h, P, F


# --------------------------------------------------------------------------- Newton

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


# --------------------------------------------------------------------------- states

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
    for name, eff in problem.effects.items():
        if isinstance(eff, AsperityAdhesion):       # eq (20): constant over r < r_c
            p_eff[name] = eff.pressure_value * frac
        else:                                        # law at sigma inside, at h_k outside
            p_k = eff.pressure(h)
            p_eff[name] = frac * eff.pressure(np.array([cs.sigma]))[0] + (1 - frac) * p_k
    p_c = hertz_annulus_force(g.edges, r_c, problem.sphere.radius,
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
    p_eff = {name: (np.zeros(n) if isinstance(e, AsperityAdhesion) else e.pressure(h))
             for name, e in problem.effects.items()}
    resid = float(np.max(np.abs(F)))
    st = State(d, w, h, p_eff, np.zeros(n), np.zeros(n, bool), 0.0, res.n_iter, resid,
               res.ok, False)
    st.diagnostics["mode"] = "free"
    st.diagnostics["eq10_violation_inside_m"] = 0.0
    st.diagnostics["edge_residual_m"] = 0.0
    if not res.ok:
        st.diagnostics["failure"] = res.reason
        return st
    # a true energy exists without contact: stable = positive definite Hessian
    H = problem.S_sym.copy()
    H[np.diag_indices_from(H)] += problem.areas * cs.dlaw(h)
    try:
        linalg.cho_factor(H, check_finite=False)
        st.stable = True
    except linalg.LinAlgError:
        st.stable = False
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
        ``AsperityAdhesion`` effect (eq 20) acts as a constant pressure over r < r_c.
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


# --------------------------------------------------------------------------- continuation

def _predict(cs, state, d):
    """Tangent predictor (w, r_c) at d from a converged state. (A curvature term from the
    previous state's tangent saved only 3 % of the Newton iterations: the branch is jagged at
    the node scale, see drc_dd, so it is left out.)"""
    dd = d - state.d
    dw = state.diagnostics.get("dw_dd")
    w = state.w + (dw * dd if dw is not None else 0.0)
    if state.r_c > 0:
        r = state.r_c + state.diagnostics.get("drc_dd", 0.0) * dd
        if r <= 2 * cs.r_floor:
            r = None    # the predictor closes the contact: start without it
    else:
        r = None
    return w, r


def _close_to_prediction(cs, new, w_pred, r_pred):
    """The corrector stayed on the predicted branch: no gap moved by more than
    MAX_CORRECTION_FRACTION of itself and, on a contact branch, r_c by no more than that
    fraction plus two node spacings. Entering or leaving contact (predicted or new r_c = 0)
    only the gaps are checked: r_c goes like sqrt(d_touch - d) there, faster than any
    predictor, while a snap (sigma = 0.5 nm) moves the gaps by far more than the fraction."""
    h_pred = new.h + (new.w - w_pred)
    if not np.all(np.abs(new.w - w_pred) <= MAX_CORRECTION_FRACTION * np.maximum(h_pred, 0)
                  + 1e-15):
        return False
    if r_pred is None or new.r_c == 0:
        return True
    return abs(new.r_c - r_pred) <= (MAX_CORRECTION_FRACTION * max(r_pred, new.r_c)
                                     + 2 * cs.nodes[1])


@dataclass
class BranchPoint:
    """A point of the contact branch parametrised by r_c (landing scan)."""

    r_c: float
    d: float
    w: np.ndarray


def _scan_branch(cs, start_w, start_d, r_from, direction, d_target, *, tol, max_iter,
                 stop_at_first=True, r_to=None):
    """Scan the contact branch d*(r_c) from r_from in ``direction`` (+1 up, -1 down).

    Returns (points, landing state or None, crossings [(r_c, stable)]). At each r_c the
    closure is solved for (w, d) (border "d"): regular through the folds in d.
    """
    pts, crossings = [], []
    w, d, r = np.array(start_w, float), float(start_d), float(r_from)
    dr_node = float(cs.nodes[1])
    # down: to half a node spacing (the approach scan's entry point), then the free surface
    r_end = r_to if r_to is not None else (0.5 * dr_node if direction < 0 else 0.98 * cs.r_max)
    prev = None
    for k in range(400):
        # the first point may start far from the branch (a free surface entering contact):
        # a larger budget for it, the predictor keeps the others close
        res = _newton_contact(cs, d, w, r, border="d", tol=tol,
                              max_iter=max_iter * (ENTRY_BUDGET if k == 0 else 1))
        if not res.ok:
            raise _ScanFailure(pts, r, res.reason)
        p = BranchPoint(r, res.d, res.w)
        pts.append(p)
        if prev is not None and (prev.d - d_target) * (p.d - d_target) <= 0 and prev.d != p.d:
            t = (d_target - prev.d) / (p.d - prev.d)
            r_x = prev.r_c + t * (p.r_c - prev.r_c)
            w_x = prev.w + t * (p.w - prev.w)
            land = _newton_contact(cs, d_target, w_x, r_x, border="r_c", tol=tol,
                                   max_iter=max_iter)
            st = _contact_state(cs, land, tol) if land.ok else None
            crossings.append((r_x, bool(st is not None and st.stable)))
            if st is not None and st.stable and stop_at_first:
                return pts, st, crossings
        if (direction > 0 and r >= r_end) or (direction < 0 and r <= r_end):
            return pts, None, crossings
        # next r_c: geometric, at most SCAN_MAX_NODES node spacings; secant predictor in r_c
        r_next = r * SCAN_RATIO if direction > 0 else r / SCAN_RATIO
        r_next = (min(r_next, r + SCAN_MAX_NODES * dr_node) if direction > 0
                  else max(r_next, r - SCAN_MAX_NODES * dr_node))
        r_next = min(r_next, r_end) if direction > 0 else max(r_next, r_end)
        if prev is not None and p.r_c != prev.r_c:
            s = (r_next - p.r_c) / (p.r_c - prev.r_c)
            w, d = p.w + s * (p.w - prev.w), p.d + s * (p.d - prev.d)
        else:
            w, d = p.w, p.d
        prev, r = p, r_next
    return pts, None, crossings


class _ScanFailure(Exception):
    def __init__(self, pts, r, reason):
        super().__init__(reason)
        self.pts, self.r, self.reason = pts, r, reason


def _scan_evidence(pts, crossings, d_target):
    if not pts:
        return "the scan found no contact state at all"
    ds = np.array([p.d for p in pts]) * 1e9
    rs = np.array([p.r_c for p in pts]) * 1e6
    txt = (f"contact branch scanned over r_c = {rs.min():.4g}..{rs.max():.4g} um reaches "
           f"d = {ds.min():.6g}..{ds.max():.6g} nm (target {d_target * 1e9:.6g} nm)")
    if crossings:
        txt += "; crossings at r_c = " + ", ".join(
            f"{r * 1e6:.4g} um ({'stable' if s else 'unstable'})" for r, s in crossings)
    else:
        txt += "; d*(r_c) - d has no sign change"
    return txt


def land_closure(problem, departing, d_land, *, branch, tol, max_iter=40, system=None):
    """The state the surface snaps to at d_land after the branch of ``departing`` folded.

    Rule (module docstring): scan the contact branch in r_c from the departing contact radius,
    upwards on approach and downwards on retract; land on the first stable state at d_land; on
    retract, below the smallest contact the free surface (r_c = 0) is the landing if it is a
    stable state with h >= sigma.

    Raises
    ------
    ConvergenceError
        When no stable landing exists, with the scanned d*(r_c) range and its crossings.
    """
    cs = system or ClosureSystem(problem)
    direction = 1 if branch == "approach" else -1
    dr_node = float(cs.nodes[1])
    if departing.r_c > 0:
        r0, w0, d0 = departing.r_c, departing.w, departing.d
    else:
        # the contact branch is entered at its smallest contact; from the departing surface
        r0, w0, d0 = 0.5 * dr_node, departing.w, departing.d
    try:
        pts, st, crossings = _scan_branch(cs, w0, d0, r0, direction, d_land, tol=tol,
                                          max_iter=max_iter)
    except _ScanFailure as exc:
        raise ConvergenceError(
            f"landing after the fold at d = {departing.d * 1e9:.6g} nm: the r_c scan failed at "
            f"r_c = {exc.r * 1e6:.4g} um ({exc.reason}); "
            + _scan_evidence(exc.pts, [], d_land), d=d_land) from None
    if st is not None:
        st.diagnostics["landing_scan"] = _scan_evidence(pts, crossings, d_land)
        return st
    if direction < 0:
        free = _newton_free(cs, d_land, np.zeros(cs.n), tol=tol, max_iter=max_iter)
        if free.ok and np.min(d_land + cs.shape - free.w) >= cs.sigma:
            fs = _free_state(cs, free)
            if fs.stable:
                fs.diagnostics["landing_scan"] = _scan_evidence(pts, crossings, d_land)
                return fs
    raise ConvergenceError(
        f"no stable closure state at d = {d_land * 1e9:.6g} nm to land on after the fold at "
        f"d = {departing.d * 1e9:.6g} nm: " + _scan_evidence(pts, crossings, d_land), d=d_land)


def _first_state(cs, problem, d, tol, max_iter):
    st = solve_closure_state(problem, d, np.zeros(cs.n), tol=tol, max_iter=max_iter, system=cs)
    if not (st.converged and st.stable):
        raise ConvergenceError(f"closure: first state not found ({st.diagnostics.get('failure', 'unstable')})",
                               d=d, residual=st.residual if math.isfinite(st.residual) else None,
                               n_iter=st.n_iter)
    return st


def trace_closure(problem, d_values, *, branch, tol, start=None, max_iter=40, on_state=None):
    """Follow the closure's stable branch through the separations ``d_values`` (m).

    Continuation in d: tangent predictor (w, r_c), Newton corrector, step halving down to
    MIN_STEP_FRACTION of the grid step. A step is accepted when the state converged, is stable
    (module docstring) and stayed within MAX_CORRECTION_FRACTION of the predicted gaps. When the
    smallest step fails, the branch has folded at the last stable d (snap-in on approach,
    snap-out on retract; located to |grid step| * MIN_STEP_FRACTION) and the surface lands by
    :func:`land_closure` one smallest step beyond.

    Parameters
    ----------
    problem : ContactProblem
    d_values : sequence of float
        Separations (m) in the order visited.
    branch : str
        ``"approach"`` or ``"retract"`` (sets the landing direction).
    tol : float
        Residual tolerance (m).
    start : State, optional
        A converged state at d_values[0] (e.g. the approach's last); else solved from w = 0.
    on_state : callable(State), optional
        Called with every state at a requested separation.

    Returns
    -------
    Sweep
        States at the requested d, ``jumps`` (Jump objects), ``n_solves``, ``wall_time``.

    Raises
    ------
    ConvergenceError
        With the partial sweep as ``exc.sweep``: no stable landing (evidence in the message),
        the step budget exhausted, or a non-finite value (named).
    """
    t0 = time.perf_counter()
    cs = ClosureSystem(problem)
    sweep = Sweep(branch)
    d_values = [float(x) for x in d_values]
    if start is not None and not (start.converged and start.stable):
        raise ValueError("start must be a converged, stable state (e.g. a sweep's last)")
    try:
        state = start if start is not None else _first_state(cs, problem, d_values[0], tol,
                                                             max_iter)
        sweep.n_solves += 0 if start is not None else 1
        sweep.states.append(state)
        if on_state:
            on_state(state)
        for d_next in d_values[1:]:
            state = _advance(cs, problem, state, d_next, sweep, branch, tol, max_iter)
            sweep.states.append(state)
            if on_state:
                on_state(state)
    except ConvergenceError as exc:
        exc.sweep = sweep
        sweep.wall_time = time.perf_counter() - t0
        raise
    sweep.wall_time = time.perf_counter() - t0
    return sweep


def _onset_is_stable(cs, free, tol, max_iter):
    """Is the contact branch stable where it leaves the free surface ``free``?

    Solves the closure at the smallest contact (half a node spacing) for (w, d) from the free
    state and tests the stability rule there. Stable: the contact grows continuously from
    touch-down (sigma = 1 nm). Unstable: d*(r_c) first rises with r_c (e.g. eq 20's pull over
    the contact), so touch-down is a fold and entering or leaving contact is a snap.
    """
    res = _newton_contact(cs, free.d, free.w, 0.5 * cs.nodes[1], border="d", tol=tol,
                          max_iter=max_iter * ENTRY_BUDGET)
    if not res.ok:
        return False
    lu = linalg.lu_factor(cs.add_jacobian(res.ev).jacobian("r_c"), check_finite=False)
    return _lu_sign(lu) < 0


def _continuous_transition(cs, old, new, tol, max_iter):
    """A step between the free surface and contact is continuous only if the contact branch
    is stable at its onset (checked on the free state of the two); other steps pass."""
    if (old.r_c > 0) == (new.r_c > 0):
        return True
    return _onset_is_stable(cs, old if old.r_c == 0 else new, tol, max_iter)


def _advance(cs, problem, state, d_next, sweep, branch, tol, max_iter):
    """Step from state to d_next with halving; folds -> land_closure."""
    grid_step = d_next - state.d
    step = grid_step
    min_step = abs(grid_step) * MIN_STEP_FRACTION
    solves = 0
    while state.d != d_next:
        if solves >= MAX_SOLVES_PER_STEP:
            raise ConvergenceError(
                f"closure continuation stalled between d = {state.d * 1e9:.6g} and "
                f"{d_next * 1e9:.6g} nm: {solves} solves (step {abs(step) * 1e9:.3g} nm)",
                d=state.d, residual=state.residual, n_iter=state.n_iter)
        solves += 1
        d_try = state.d + step
        if (d_next - d_try) * math.copysign(1.0, grid_step) < 0 or \
                abs(d_next - d_try) < 0.5 * min_step:
            d_try = d_next
        w_pred, r_pred = _predict(cs, state, d_try)
        new = solve_closure_state(problem, d_try, w_pred, tol=tol, max_iter=max_iter,
                                  r_c0=r_pred, system=cs)
        sweep.n_solves += 1
        if (new.converged and new.stable and _close_to_prediction(cs, new, w_pred, r_pred)
                and _continuous_transition(cs, state, new, tol, max_iter)):
            state = new
            step = math.copysign(min(abs(2 * step), abs(grid_step)), grid_step)
            continue
        if abs(step) > 1.5 * min_step:
            step *= 0.5
            continue
        landed = land_closure(problem, state, d_try, branch=branch, tol=tol, max_iter=max_iter,
                              system=cs)
        sweep.n_solves += 1
        sweep.jumps.append(Jump(branch, state.d, d_try, abs(d_try - state.d), state, landed))
        state = landed
    return state
