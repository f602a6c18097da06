"""The discrete sphere-flat problem: K w = P(h) - p_c with h = b(r; d) - w (paper 1 eqs 5-10).

Unknowns live on the operator's radial nodes; pressures are piecewise constant on its annuli.
Sign convention: w > 0 moves the disk surface up,
towards the sphere; effect pressures P > 0 are attractive (pull the surface up); the contact
pressure p_c >= 0 is repulsive.
"""
from dataclasses import dataclass, field
import math

import numpy as np

from ..errors import ConvergenceError
from ..indenter import Sphere
from .constraints import AsperityGap
from .linalg import diagonal

_F8 = np.dtype(np.float64)


@dataclass(eq=False)
class ContactProblem:
    """Everything the solvers need, precomputed once per operator.

    Parameters
    ----------
    operator : SurfaceOperator
        Provides ``grid``, ``compliance`` C (m/Pa) and ``stiffness`` K = C^-1 (Pa/m).
    sphere : Sphere
        The rigid indenter, b(r; d) = d + shape(r) (eq 4).
    effects : dict[str, effect]
        Pressure laws of the gap, by name (e.g. ``{"lj": LennardJones(...)}``); only these are
        evaluated.
    gap : AsperityGap or None
        The sigma-gap constraint (eq 8) and its contact model; None for a smooth sphere.
    check_laws : bool
        Verify each law's derivative and energy against finite differences of its value
        (:func:`femadh.laws.check_law`) before solving; a LawError names the first
        inconsistency. Off only for deliberately partial laws (tests).
    subgrid : bool
        Integrate the step laws that ask for it (``SUBGRID = True``: the capillary
        condensate) over the gap field piecewise-linear between the nodes
        (:mod:`femadh.contact.subgrid`) instead of collocating them at the nodes. Their
        nodal force then depends on the neighbours' gaps: the law Jacobian is tridiagonal
        (:meth:`law_jacobian`). Off for the solvers that take only a diagonal law Jacobian
        (the Hertz closure; the scene builder turns it off for arclength continuation).
    """

    operator: object
    sphere: Sphere
    effects: dict
    gap: AsperityGap | None = None
    check_laws: bool = True
    subgrid: bool = True
    shape: np.ndarray = field(init=False)

    def __post_init__(self):
        if self.check_laws:
            from ..laws import check_law

            for name, law in self.effects.items():
                check_law(name, law)
        g = self.operator.grid
        self.grid = g
        self.shape = self.sphere.shape(g.nodes)
        self.K = self.operator.stiffness
        self.C = self.operator.compliance
        self.areas = g.areas
        # Symmetric force-displacement stiffness for the energy and the stability test.
        S = self.areas[:, None] * self.K
        self.S_sym = 0.5 * (S + S.T)
        # the laws integrated over the sub-grid gap field (by name), and the ones collocated
        self.integrated = {}
        if self.subgrid and self.contact_model != "hertz-closure":
            from .subgrid import SubgridStep

            self.integrated = {name: SubgridStep(law, g.nodes, g.radius)
                               for name, law in self.effects.items()
                               if getattr(law, "SUBGRID", False)}
        self.collocated = {k: v for k, v in self.effects.items() if k not in self.integrated}

    @property
    def banded(self):
        """True when a law is integrated sub-grid: the law Jacobian is then tridiagonal."""
        return bool(self.integrated)

    def require_collocated(self, solver):
        """Raise ValueError (one line) for a solver that takes only a diagonal law Jacobian
        when a law is integrated sub-grid (build the problem with ``subgrid=False``)."""
        if self.integrated:
            raise ValueError(f"{solver} takes collocated laws only; the problem integrates "
                             f"{sorted(self.integrated)} sub-grid (build it with subgrid=False)")

    @property
    def contact_model(self):
        return None if self.gap is None else self.gap.contact_model

    @property
    def sigma(self):
        return None if self.gap is None else self.gap.sigma

    def surface_force_stiffness(self):
        """The largest softening stiffness of the effects against the surface's own.

        Returns (ratio, gap, -dP/dh, k_node): the largest -dP/dh (Pa/m) over the gaps the
        surface can reach, the gap where it occurs, and k_node = min_k K_kk, the pressure per
        unit displacement of a single node (Pa/m). Reachable gaps: h >= sigma with the gap
        constraint; otherwise h above the largest gap where the summed law turns repulsive
        (z0 for LJ alone, ~1 nm with Greenwood-Williamson asperities). With ratio near 1 a
        single node can snap on its own: the answer then depends on the mesh, not the physics.
        """
        # the nodes of the fine band (all, on a uniform grid): a graded far field never comes
        # close, and its wide annuli are softer by design
        k_node = float(np.min(np.diag(self.K)[self.grid.fine]))
        if not self.collocated:
            return 0.0, math.nan, 0.0, k_node
        if self.sigma is not None:
            floor = self.sigma
        else:
            scan = np.logspace(-7, -11, 4000)            # 100 nm down to 0.01 nm
            repulsive = np.flatnonzero(self._sum("pressure", scan) < 0)
            floor = float(scan[repulsive[0]]) if repulsive.size else float(scan[-1])
        h = floor * np.logspace(0, 2, 400)
        # the collocated laws pointwise; a sub-grid law is left out: its nodal softening is
        # not its pointwise -P'(h) (P0/(4w) for a step) but depends on the gap's slope
        # across the node, which :meth:`node_softening_ratio` measures on the states
        soft = -self._sum("dpressure", h, self.collocated)
        k = int(np.argmax(soft))
        return float(max(soft[k], 0.0) / k_node), float(h[k]), float(soft[k]), k_node

    def contour(self, d):
        """b(r_k; d) (m) at the nodes."""
        return d + self.shape

    def _nodal(self, h):
        """True when h is a field of nodal gaps (shape (n,)) and a law is integrated
        sub-grid; any other array is a set of gaps at which the laws are evaluated
        pointwise (scans, the contact gap)."""
        return bool(self.integrated) and np.shape(h) == (self.grid.n,)

    def pointwise_pressure(self, h):
        """Sum of the effect pressures (Pa) of every law evaluated pointwise at gaps h (a scan
        of gaps, whatever its length: never read as a nodal field)."""
        return self._sum("pressure", h)

    def pressure(self, h):
        """Sum of the effect pressures (Pa, attractive positive) at gaps h: at the nodes
        (h of shape (n,)) a sub-grid law's nodal pressure f_k / area_k, else every law
        pointwise."""
        if not self._nodal(h):
            return self._sum("pressure", h)
        out = self._sum("pressure", h, self.collocated)
        for name, sub in self.integrated.items():
            out = out + self._finite(name, "pressure", sub.force(h) / self.areas, h)
        return out

    def dpressure(self, h):
        """d/dh of :meth:`pressure` (Pa/m); at the nodes with a sub-grid law, the diagonal
        d P_k / d h_k of the (tridiagonal) law Jacobian :meth:`law_jacobian`."""
        if not self._nodal(h):
            return self._sum("dpressure", h)
        out = self._sum("dpressure", h, self.collocated)
        for name, sub in self.integrated.items():
            out = out + self._finite(name, "dpressure", sub.stiffness(h)[0] / self.areas, h)
        return out

    def law_jacobian(self, h):
        """J = dP/dh (Pa/m) of the nodal pressures at nodal gaps h: a vector (the diagonal)
        when every law is collocated, else the dense (n, n) matrix diag(1/area) T with T the
        symmetric tridiagonal d f / d h of the sub-grid laws plus the collocated diagonal."""
        if not self.integrated:
            return self.dpressure(h)
        a = self.areas
        diag = self._sum("dpressure", h, self.collocated)
        off = np.zeros(a.size - 1)
        for name, sub in self.integrated.items():
            d, o = sub.stiffness(h)
            diag = diag + self._finite(name, "dpressure", d / a, h)
            off = off + o
        n = a.size
        J = np.zeros((n, n))
        flat = J.reshape(-1)
        flat[::n + 1] = diag
        flat[1::n + 1] = off / a[:-1]          # row k, column k + 1: T_k,k+1 / area_k
        flat[n::n + 1] = off / a[1:]           # row k + 1, column k
        return J

    def effect_pressures(self, h):
        """Each law's nodal pressure (Pa) at nodal gaps h, by name (what a State carries:
        :func:`femadh.contact.forces.state_forces` sums area x pressure)."""
        out = {}
        for name, eff in self.effects.items():
            sub = self.integrated.get(name)
            out[name] = eff.pressure(h) if sub is None else sub.force(h) / self.areas
        return out

    @staticmethod
    def _finite(name, part, v, h):
        """v, after checking that every entry is finite (else a ConvergenceError names the law,
        the part and the first node that is not).

        (The mask's own ``all``: np.all's dispatch cost more than the test on a few hundred
        nodes. Not a sum's one reduction: a sum of finite values can overflow, which warns -
        or raises under np.seterr(all="raise") - where the elementwise test is silent.)"""
        finite = np.isfinite(v)
        if not finite.all():
            k = int(np.flatnonzero(~finite)[0])
            raise ConvergenceError(f"law {name!r}: {part} is not finite at node {k} "
                                   f"(gap h = {np.ravel(h)[k]:.6g} m)")
        return v

    def _sum(self, part, h, laws=None):
        """Sum of one part of every law (or of ``laws``), pointwise; a non-finite value stops
        the solve where it arose.

        The laws' values summed in their order from zero, ((0 + v1) + v2) + ...: the first
        as v1 + 0.0 (the bits of 0.0 + v1, a -0.0 made +0.0 as before) when it is a float
        array of h's shape, without the zeros it was added to."""
        out = None
        for name, eff in (self.effects if laws is None else laws).items():
            v = self._finite(name, part, getattr(eff, part)(h), h)
            if out is None:
                if (type(v) is np.ndarray and type(h) is np.ndarray and v.dtype == _F8
                        and h.dtype == _F8 and v.shape == h.shape and v.ndim > 0):
                    out = v + 0.0
                    continue
                out = np.zeros_like(h)
            out += v
        return np.zeros_like(h) if out is None else out

    def energy(self, w, d):
        """Total potential energy (J): elastic 1/2 w.S.w plus sum_k area_k U(h_k).

        Its gradient S w - area * P(h) vanishes at equilibrium (S = diag(area) K); it is the
        merit function that decides where the surface lands after a jump.
        """
        h = self.contour(d) - w
        u = sum(eff.energy(h) for eff in self.collocated.values()) if self.collocated \
            else 0.0 * h
        sub = sum(s.energy(h) for s in self.integrated.values())
        return 0.5 * w @ (self.S_sym @ w) + self.areas @ u + sub

    def energy_gradient(self, w, d):
        h = self.contour(d) - w
        return self.S_sym @ w - self.areas * self.pressure(h)

    def energy_hessian(self, h, free=None):
        """Symmetric Hessian (N/m) of :meth:`energy` at gaps h, on the nodes ``free`` (mask;
        all by default): sym(S) + diag(area P'(h)), with a sub-grid law's tridiagonal
        T = df/dh in place of its diagonal. Positive definite = a stable state."""
        if self.integrated:
            # area x J is the symmetric tridiagonal T (plus the collocated diagonal)
            J, a, n = self.law_jacobian(h), self.areas, self.grid.n
            H = self.S_sym.copy()
            flat = H.reshape(-1)
            flat[::n + 1] += a * np.diagonal(J)
            flat[1::n + 1] += a[:-1] * np.diagonal(J, 1)
            flat[n::n + 1] += a[1:] * np.diagonal(J, -1)
            if free is None:
                return H
            m = free.size - int(np.count_nonzero(free))
            return H[m:, m:] if free[m:].all() else H[np.ix_(free, free)]
        if free is None:
            H = self.S_sym.copy()
            d = diagonal(H)
            d += self.areas * self.dpressure(h)
        else:
            m = free.size - int(np.count_nonzero(free))
            # the free nodes of a disk contact are the trailing block m..n-1: a slice copy
            # (5x faster than the fancy-indexed one at 631 nodes, 0.5 against 2.4 ms)
            H = (self.S_sym[m:, m:].copy() if free[m:].all()
                 else self.S_sym[np.ix_(free, free)])
            d = diagonal(H)
            d += self.areas[free] * self.dpressure(h[free])
        return H

    def node_softening_ratio(self, h):
        """max_k -P'(h_k) / K_kk at the gaps h of a state: the a-posteriori twin of
        :meth:`surface_force_stiffness` (each node against its own stiffness, at the gap it
        actually reached). Near 1 a node can snap on its own (lattice trapping).

        Nodes held at the floor (h = sigma) coarser than the grid's finest spacing are left
        out: inside the contact of a grid whose fine band follows the edge (coarse there by
        design) they are pinned by the constraint, and the edge, where nodes are released or
        join, is always in the band. On a uniform grid or a static band [0, r_b] every node
        that reaches the floor has the finest spacing (the ratio is the max over all).

        With a sub-grid law, -P'(h_k) is the diagonal -T_kk / area_k of its integrated
        stiffness: the energy's curvature when node k moves alone against S_kk = area_k K_kk."""
        ratio = -self.dpressure(h) / np.diag(self.K)
        if self.sigma is not None:
            keep = (h > self.sigma * (1 + 1e-9)) | self.finest_nodes
            return float(np.max(ratio[keep])) if keep.any() else 0.0
        return float(np.max(ratio))

    @property
    def finest_nodes(self):
        """Mask of the nodes whose spacing to both neighbours is within 2 % of the grid's
        smallest (all nodes of a uniform grid; the band of a banded one)."""
        if getattr(self, "_finest", None) is None:
            dr = np.diff(self.grid.nodes)
            left = np.r_[dr[0], dr]
            right = np.r_[dr, dr[-1]]
            self._finest = np.maximum(left, right) <= 1.02 * float(np.min(dr))
        return self._finest
