"""Circular (toroidal) approximation of the meniscus (Orr et al. 1975; Asay & Kim), zero
contact angle on both films. Vectorised over filling angles.

The meridian is a circle arc of radius rho tangent to the flat and to the sphere at the filling
angle phi: rho = (1 - cos phi + D) / (1 + cos phi), neck radius r_n = (1 + rho) sin phi - rho.
The Kelvin condition is imposed at the neck, 1/r_n - 1/rho = kappa; the force is evaluated at
the sphere contact line (paper 2's "point 1"): F/(2 pi gamma R_e) = sin^2 phi - kappa sin^2 phi / 2.
"""
import math

import numpy as np
from scipy import optimize

from ..errors import DomainError
from .geometry import Geometry


def curvature_mismatch(phi, geo):
    phi = np.asarray(phi, float)
    c = np.cos(phi)
    rho = (1 - c + geo.D) / (1 + c)
    rn = (1 + rho) * np.sin(phi) - rho
    return 1.0 / rn - 1.0 / rho - geo.kappa, rho, rn


def solve_circular(geo: Geometry, phi_max=math.pi / 2):
    """Filling angle, meridian radius and neck radius (dimensionless) of the circular meniscus.

    Raises DomainError when no filling angle below ``phi_max`` satisfies the Kelvin condition
    with a positive neck (|r_K| too large for the sphere: the approximation loses its neck, or
    the meniscus foot would pass the equator).
    """
    lo = geo.phi_min + 1e-12 * max(1.0, geo.phi_min)
    phis = np.linspace(lo, phi_max, 2001)[1:]
    g, rho, rn = curvature_mismatch(phis, geo)
    ok = (rho > 0) & (rn > 0)
    sign = np.flatnonzero(ok[:-1] & ok[1:] & (g[:-1] < 0) & (g[1:] >= 0))
    if sign.size == 0:
        raise DomainError(f"circular approximation: no meniscus with a neck for R_e/r_K = "
                          f"{geo.kappa:.4g} below a filling angle of {math.degrees(phi_max):.0f} "
                          "deg (|r_K| too large for the sphere)")
    k = sign[0]
    phi = optimize.brentq(lambda p: curvature_mismatch(p, geo)[0], phis[k], phis[k + 1],
                          xtol=1e-15, rtol=4 * np.finfo(float).eps)
    _, rho, rn = curvature_mismatch(phi, geo)
    return float(phi), float(rho), float(rn)


def circular_force(geo: Geometry, phi):
    """F / (2 pi gamma R_e) at the sphere contact line for filling angle phi."""
    s2 = math.sin(phi) ** 2
    return s2 - 0.5 * geo.kappa * s2


def circular_profile(geo, phi, rho, n=200):
    """(r, z, psi) of the circle arc from the flat (t = 0) to the sphere (t = 1)."""
    t = np.linspace(0.0, 1.0, n)
    alpha = (math.pi - phi) * t
    rcc = (1 + rho) * math.sin(phi)
    return rcc - rho * np.sin(alpha), rho * (1 - np.cos(alpha)), math.pi - alpha
