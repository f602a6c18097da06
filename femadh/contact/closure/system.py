"""The discrete closure of one ContactProblem: residuals of eq (10) on the free nodes and of
the edge condition at r = r_c, and their Jacobian blocks (see the package docstring)."""
from dataclasses import dataclass
import math

import numpy as np

from ...errors import ConvergenceError
from .influence import influence_for

#: below this fraction of the first node spacing the contact has closed (r_c -> 0)
RC_FLOOR_FRACTION = 1e-3


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
        # eq (20) acts as a constant pressure over r < r_c, carried by the sigma-gap
        self.laws = dict(problem.effects)
        self.p_asperity = float(problem.gap.adhesion)
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
