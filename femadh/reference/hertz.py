"""Hertz contact of a rigid paraboloid on an elastic half-space (Johnson 1985, sec 3.4 and 4.2).

Paper 1 eq (9) is the Hertz pressure with p_m = 2 E* r_c / (pi R).
"""
import math

import numpy as np


def hertz_contact_radius(penetration, radius):
    """Contact radius a = sqrt(R delta) (m) for penetration delta (m) of a paraboloid of radius R."""
    return math.sqrt(radius * penetration)


def hertz_load(contact_radius, radius, e_star):
    """Total load F = 4 E* a^3 / (3 R) (N)."""
    return 4.0 * e_star * contact_radius**3 / (3.0 * radius)


def hertz_pressure(r, contact_radius, radius, e_star):
    """Contact pressure p_m sqrt(1 - (r/a)^2), p_m = 2 E* a/(pi R) (Pa), eq (9); zero for r > a."""
    r = np.asarray(r, float)
    p_m = 2.0 * e_star * contact_radius / (math.pi * radius)
    s = np.clip(1.0 - (r / contact_radius) ** 2, 0.0, None)
    return p_m * np.sqrt(s)


def hertz_displacement(r, contact_radius, p_max, e_star):
    """Surface displacement (m) of the Hertz pressure p_max sqrt(1 - r^2/a^2) (Johnson eq 3.42).

    r <= a: pi p0 (2a^2 - r^2) / (4 a E*);
    r >  a: p0 / (2 a E*) [(2a^2 - r^2) asin(a/r) + a sqrt(r^2 - a^2)].
    """
    r = np.asarray(r, float)
    a = contact_radius
    out = np.empty_like(r)
    i = r <= a
    out[i] = math.pi * p_max * (2 * a * a - r[i] ** 2) / (4.0 * a * e_star)
    o = ~i
    ro = r[o]
    out[o] = p_max / (2.0 * a * e_star) * ((2 * a * a - ro**2) * np.arcsin(a / ro)
                                            + a * np.sqrt(ro**2 - a * a))
    return out
