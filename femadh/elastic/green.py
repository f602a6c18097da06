"""Exact Green-function surface operator of an elastic half-space for annular loads.

A uniform pressure p on a disk of radius a displaces the half-space surface by
(Johnson, *Contact Mechanics*, 1985, eq 3.41, with the composite modulus E* of paper 1 eq 2)

    r <= a :  w(r) = 4 p a / (pi E*) * E((r/a)^2)
    r >= a :  w(r) = 4 p r / (pi E*) * [E(m) - (1 - m) K(m)],  m = (a/r)^2
                   = p a^2 / (E* r) * 2F1(1/2, 1/2; 2; m)

(E, K: complete elliptic integrals with parameter m; the hypergeometric form is the same
function without the cancellation of E - (1-m)K for r >> a, evaluated by
:func:`outside_factor`). An annulus [e_j, e_j+1] is the
difference of two disks, so the influence coefficients are exact: no Taylor series of the point-
load Green function (paper 1 eq 1; the paper used 2000 terms of one) is needed.
"""
import math

import numpy as np
from scipy import special

from .grid import RadialGrid
from .operator import SurfaceOperator


#: below this parameter m the outside kernel (:func:`outside_factor`) runs the AGM, above it
#: E - (1-m) K from the elliptic integrals (cancellation ~4/m ulps there, <= 8 at the split)
AGM_SPLIT = 0.5
#: AGM steps after the first: c_n falls quadratically from c_1 <= 0.146 at m = 0.5 (c_5 ~ 1e-22)
AGM_STEPS = 4


def outside_factor(m):
    """2F1(1/2, 1/2; 2; m) for 0 <= m < 1: the far-field factor of a loaded disk's displacement.

    Equal to 4 / (pi m) [E(m) - (1 - m) K(m)] (E, K: complete elliptic integrals), which
    cancels for small m. Below AGM_SPLIT it is taken from the arithmetic-geometric mean of 1
    and k' = sqrt(1 - m) without that cancellation (Abramowitz & Stegun 17.6): with
    a_n, b_n, c_n the AGM's sequences, K = pi / (2 a_N) and E = K (1 - sum 2^(n-1) c_n^2), so
    E - (1 - m) K = K (m/2 - S), S = sum_{n>=1} 2^(n-1) c_n^2, and the factor is
    (1 - 2 S / m) / a_N; c_n is carried as c_n^2 / (4 a_n+1), never as a difference.
    Above AGM_SPLIT the elliptic form loses at most ~4/m ulps. Measured against a 50-digit
    reference (mpmath's hyp2f1): within 4.2 ulps, the largest just above AGM_SPLIT (4.16 at
    m = 0.5095; 31 of 6000 parameters in [0.5, 0.9] above 3), within 1.6 on the AGM side and
    2.4 near m = 1 (scipy's hyp2f1, which it replaces for speed: up to 48 ulps near m = 1),
    at ~1/3 of hyp2f1's time.

    Parameters
    ----------
    m : ndarray
        Parameter m = (a/r)^2 in [0, 1) (a: disk radius, r > a: observation radius).
    """
    m = np.asarray(m, float)
    out = np.empty(m.shape)
    low = m < AGM_SPLIT
    ml = np.maximum(m[low], np.finfo(float).tiny)        # m = 0: S = 0, the factor 1
    kp = np.sqrt(1.0 - ml)
    c = ml / (2.0 * (1.0 + kp))                           # c_1 = (1 - k') / 2
    a, b = 0.5 * (1.0 + kp), np.sqrt(kp)                  # a_1, b_1 (a_0 = 1, b_0 = k')
    s, weight = c * c, 1.0
    for _ in range(AGM_STEPS):
        a_next = 0.5 * (a + b)
        c = c * c / (4.0 * a_next)
        b = np.sqrt(a * b)
        a = a_next
        weight *= 2.0
        s += weight * c * c
    out[low] = (1.0 - 2.0 * s / ml) / a
    mh = m[~low]
    out[~low] = 4.0 / (math.pi * mh) * (special.ellipe(mh) - (1.0 - mh) * special.ellipk(mh))
    return out


def _inside(r, a):
    """E* w / p (m) inside a uniformly loaded disk, r <= a: 4 a / pi E((r/a)^2) (Johnson
    eq 3.41); r, a broadcast, a > 0."""
    return 4.0 * a / math.pi * special.ellipe((r / a) ** 2)


def _outside(r, a):
    """E* w / p (m) outside a uniformly loaded disk, r > a: a^2 / r 2F1(1/2, 1/2; 2; (a/r)^2)
    (:func:`outside_factor`); r, a broadcast, 0 < a < r."""
    return a ** 2 / r * outside_factor((a / r) ** 2)


def disk_displacement(r, a, e_star, p=1.0):
    """Surface displacement (m) at radius r of a uniform pressure p (Pa) on a disk of radius a.

    Parameters
    ----------
    r, a : array_like
        Observation radius and disk radius (m); broadcast against each other.
    e_star : float
        Composite modulus E* (Pa), paper 1 eq (2).
    p : float
        Pressure (Pa); positive displaces the surface towards the load (w > 0).
    """
    r, a = np.broadcast_arrays(np.asarray(r, float), np.asarray(a, float))
    w = np.zeros(r.shape)
    inside = (r <= a) & (a > 0)
    w[inside] = _inside(r[inside], a[inside])
    outside = (r > a) & (a > 0)
    w[outside] = _outside(r[outside], a[outside])
    return p * w / e_star


#: rows of the compliance assembled together (:func:`annulus_compliance`): a block's arrays
#: stay in cache (at 860 nodes half the time of assembling the whole matrix at once), its
#: ragged part (rows whose nodes fall between the same edges) small
BLOCK_ROWS = 64


def annulus_compliance(nodes, edges, e_star):
    """C_ij (m/Pa): displacement at node i per unit pressure on the annulus [e_j, e_j+1].

    The difference of two disks' displacements, bit for bit those of
    :func:`disk_displacement`, assembled in blocks of rows without its whole-matrix masks:
    nodes and edges increase, so the disks that contain node i (e_j >= r_i, the elliptic
    form) are a suffix of the edges and those it lies outside (the hypergeometric form) a
    prefix; a block of rows splits into the columns inside for all its rows, those outside
    for all, and a ragged band between them.

    Parameters
    ----------
    nodes : ndarray (N,)
        Node radii r_i (m), increasing.
    edges : ndarray (N+1,)
        Annulus edges (m), increasing, edges[0] == 0 (the empty disk displaces nothing).
    e_star : float
        Composite modulus E* (Pa), paper 1 eq (2).
    """
    n = nodes.size
    e = edges[1:]
    first_in = np.searchsorted(e, nodes, side="left")      # first j with e_j >= r_i
    w = np.zeros((n, n + 1))                               # column 0: the empty disk
    for i0 in range(0, n, BLOCK_ROWS):
        i1 = min(n, i0 + BLOCK_ROWS)
        r = nodes[i0:i1, None]
        lo, hi = first_in[i0], first_in[i1 - 1]            # first_in does not decrease
        if hi < n:
            w[i0:i1, 1 + hi:] = _inside(r, e[hi:])
        if lo > 0:
            w[i0:i1, 1:1 + lo] = _outside(r, e[:lo])
        if hi > lo:
            rr, a = np.broadcast_arrays(r, e[None, lo:hi])
            band = w[i0:i1, 1 + lo:1 + hi]
            inside = a >= rr
            band[inside] = _inside(rr[inside], a[inside])
            band[~inside] = _outside(rr[~inside], a[~inside])
    w /= e_star               # p w / E* with p = 1 Pa: the bits of disk_displacement
    return np.diff(w, axis=1)


class GreenOperator(SurfaceOperator):
    """Surface compliance of the half-space on a :class:`RadialGrid` (exact annulus loads).

    Parameters
    ----------
    grid : RadialGrid
        Nodes (collocation points) and annuli (pressure cells).
    e_star : float
        Composite modulus (Pa).

    Attributes
    ----------
    compliance : ndarray (N, N)
        C_ij = displacement at node i (m) per unit pressure (Pa) on annulus j.
    stiffness : ndarray (N, N)
        K = C^-1 (Pa/m): nodal pressures that hold the surface at given nodal displacements.
    """

    name = "green"

    def __init__(self, grid: RadialGrid, e_star: float):
        self.grid = grid
        self.e_star = float(e_star)
        self.compliance = annulus_compliance(grid.nodes, grid.edges, self.e_star)
