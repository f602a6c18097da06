"""Exact Green-function surface operator of an elastic half-space for annular loads.

A uniform pressure p on a disk of radius a displaces the half-space surface by
(Johnson, *Contact Mechanics*, 1985, eq 3.41, with the composite modulus E* of paper 1 eq 2)

    r <= a :  w(r) = 4 p a / (pi E*) * E((r/a)^2)
    r >= a :  w(r) = 4 p r / (pi E*) * [E(m) - (1 - m) K(m)],  m = (a/r)^2
                   = p a^2 / (E* r) * 2F1(1/2, 1/2; 2; m)

(E, K: complete elliptic integrals with parameter m; the hypergeometric form is the same
function without the cancellation of E - (1-m)K for r >> a). An annulus [e_j, e_j+1] is the
difference of two disks, so the influence coefficients are exact: no Taylor series of the point-
load Green function (paper 1 eq 1; the paper used 2000 terms of one) is needed.
"""
import math

import numpy as np
from scipy import special

from .grid import RadialGrid
from .operator import SurfaceOperator


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
    m_in = (r[inside] / a[inside]) ** 2
    w[inside] = 4.0 * a[inside] / math.pi * special.ellipe(m_in)
    outside = (r > a) & (a > 0)
    m_out = (a[outside] / r[outside]) ** 2
    w[outside] = a[outside] ** 2 / r[outside] * special.hyp2f1(0.5, 0.5, 2.0, m_out)
    return p * w / e_star


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
        r = grid.nodes[:, None]
        w_edges = disk_displacement(r, grid.edges[None, :], self.e_star)
        self.compliance = np.diff(w_edges, axis=1)
