"""Exact meniscus by ODE shooting in the filling angle (scipy solve_ivp + brentq): the
independent cross-check of the FE solver."""
import math

import numpy as np
from scipy import integrate, optimize

from ..errors import DomainError
from .geometry import Geometry


def _shoot(phi, geo, rtol):
    """Integrate from the sphere point back to psi = pi; return (z there, solution)."""
    r0, z0 = geo.sphere_point(phi)

    def rhs(u, y):
        r, z, psi = y
        return [-math.cos(psi), -math.sin(psi), -(geo.kappa - math.sin(psi) / r)]

    def flat(u, y):
        return y[2] - math.pi
    flat.terminal, flat.direction = True, 1

    def plane(u, y):
        return y[1]
    plane.terminal, plane.direction = True, -1

    def axis(u, y):
        return y[0] - 1e-9 * r0
    axis.terminal = True

    span = 50.0 * (r0 + abs(1.0 / geo.kappa) + 1.0)
    sol = integrate.solve_ivp(rhs, (0.0, span), [r0, z0, phi], method="DOP853", rtol=rtol,
                              atol=rtol * 1e-3 * min(1.0, abs(1 / geo.kappa)),
                              events=(flat, plane, axis), dense_output=True)
    if sol.t_events[0].size:
        return float(sol.y_events[0][0][1]), sol   # turned horizontal at height z >= 0
    if sol.t_events[1].size:
        # reached the flat still descending: residual -(pi - psi) -> 0 as the two events merge,
        # so the residual is continuous in phi across the root
        return -(math.pi - float(sol.y_events[1][0][2])), sol
    return -math.pi, sol


def solve_shooting(geo: Geometry, phi_guess, rtol=1e-12, phi_max=math.pi / 2):
    """Filling angle (dimensionless problem) with z = 0 where the meridian turns horizontal.

    Brackets the root around ``phi_guess`` (e.g. the circular approximation's), then Brent.
    Returns (phi, profile r, z, psi from flat to sphere, u-span).
    """
    def resid(phi):
        return _shoot(phi, geo, rtol)[0]

    lo, hi = phi_guess, phi_guess
    f_lo = f_hi = resid(phi_guess)
    step = 0.05 * max(phi_guess - geo.phi_min, 1e-6)
    for _ in range(200):
        if f_lo * f_hi < 0:
            break
        lo = max(geo.phi_min + 1e-14, lo - step)
        hi = min(phi_max, hi + step)
        f_lo, f_hi = resid(lo), resid(hi)
        step *= 1.6
    if f_lo * f_hi >= 0:
        raise DomainError(f"shooting: no filling angle below {math.degrees(phi_max):.0f} deg "
                          f"gives a meniscus for R_e/r_K = {geo.kappa:.4g}")
    phi = optimize.brentq(resid, lo, hi, xtol=1e-15, rtol=4 * np.finfo(float).eps)
    z, sol = _shoot(phi, geo, rtol)
    if not sol.t_events[0].size or abs(z) > 1e-8:
        raise DomainError(f"shooting: the residual changes sign without a root near "
                          f"phi = {phi:.6g} (R_e/r_K = {geo.kappa:.4g})")
    u_end = sol.t_events[0][0]
    u = np.linspace(u_end, 0.0, 400)
    r, zz, psi = sol.sol(u)
    return float(phi), r, zz, psi
