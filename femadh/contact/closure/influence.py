"""Influences of annulus and disk loads at any radius, for the closure's edge condition at
r = r_c: exact for the Green operator (elliptic integrals), interpolated for any other (FE)."""
import math

import numpy as np
from scipy import special

from ...elastic.green import GreenOperator
from . import hertz

#: K(m) is log-singular at m = 1 (the slope of a uniform disk load's displacement at its edge);
#: derivatives are evaluated at m <= 1 - M_CLIP there. Only the Jacobian sees this.
M_CLIP = 1e-16


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
        """Closed-form Hertz displacement (m, into the disk) of eq (9) at every node."""
        return hertz.displacement(self.nodes, a, self.radius)

    def hertz_nodes_da(self, a):
        """d/da of :meth:`hertz_nodes` (m/m)."""
        return hertz.displacement_da(self.nodes, a, self.radius)

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
        return self.C @ (hertz.annulus_force(self.edges, a, self.radius, self.e_star)
                         / self.areas)

    def hertz_nodes_da(self, a):
        return self.C @ (hertz.annulus_force_da(self.edges, a, self.radius, self.e_star)
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
