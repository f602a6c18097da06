"""Maugis-Dugdale adhesive contact (Maugis 1992, J. Colloid Interface Sci. 150:243) and the
JKR/DMT limits in Maugis' dimensionless variables.

    A = a (K / (pi dg R^2))^(1/3),  P = F / (pi dg R),  D = delta (K^2 / (pi^2 dg^2 R))^(1/3),
    K = 4 E* / 3,  lambda = 2 sigma0 (R / (pi dg K^2))^(1/3).

Parametric in m = c/a (> 1, c the radius of the Dugdale cohesive zone):

    (lam A^2 / 2)[s + (m^2 - 2) atan s] + (4 lam^2 A / 3)[s atan s - m + 1] = 1,   s = sqrt(m^2-1)
    P = A^3 - lam A^2 (s + m^2 atan s)
    D = A^2 - (4/3) lam A s

F positive = compressive load (the adhesive pull-off is the most negative P).
"""
import math

import numpy as np
from scipy import optimize


def maugis_curve(lam, m):
    """(A, P, D) arrays of the Maugis-Dugdale solution for lambda and m-values (> 1)."""
    m = np.asarray(m, float)
    s = np.sqrt(m * m - 1)
    at = np.arctan(s)
    alpha = 0.5 * lam * (s + (m * m - 2) * at)
    beta = 4.0 * lam * lam / 3.0 * (s * at - m + 1)
    A = (-beta + np.sqrt(beta * beta + 4 * alpha)) / (2 * alpha)
    P = A**3 - lam * A * A * (s + m * m * at)
    D = A * A - 4.0 / 3.0 * lam * A * s
    return A, P, D


def maugis_pull_off(lam):
    """Load-controlled pull-off -min P (in units of pi dg R): 2 (DMT) at lam -> 0, 1.5 (JKR)
    at lam -> inf."""
    def P_of_logm(x):
        return maugis_curve(lam, 1.0 + np.exp(x))[1]

    xs = np.linspace(-25, 12, 1500)
    P = P_of_logm(xs)
    k = int(np.argmin(P))
    lo, hi = xs[max(k - 1, 0)], xs[min(k + 1, xs.size - 1)]
    res = optimize.minimize_scalar(P_of_logm, bounds=(lo, hi), method="bounded",
                                   options={"xatol": 1e-12})
    return -float(min(res.fun, P[k]))


def jkr_curve(A):
    """JKR in Maugis units: P = A^3 - sqrt(6 A^3), D = A^2 - (2/3) sqrt(6 A)."""
    A = np.asarray(A, float)
    return A**3 - np.sqrt(6 * A**3), A * A - 2.0 / 3.0 * np.sqrt(6 * A)


def dmt_curve(A):
    """DMT in Maugis units: P = A^3 - 2, D = A^2."""
    A = np.asarray(A, float)
    return A**3 - 2.0, A * A


def jkr_approach(contact_radius, radius, e_star, work_of_adhesion):
    """JKR approach delta (m) at contact radius a: a^2/R - sqrt(2 pi a dg / E*)."""
    a = contact_radius
    return a * a / radius - math.sqrt(2 * math.pi * a * work_of_adhesion / e_star)


def jkr_load(contact_radius, radius, e_star, work_of_adhesion):
    """JKR load (N) at contact radius a: 4E*a^3/(3R) - sqrt(8 pi dg E* a^3)."""
    a = contact_radius
    return 4 * e_star * a**3 / (3 * radius) - math.sqrt(8 * math.pi * work_of_adhesion * e_star
                                                         * a**3)


def lj_dugdale_lambda(tabor_mu):
    """Maugis lambda matching a Lennard-Jones 3-9 surface law of Tabor parameter mu: the
    Dugdale stress equal to the LJ maximum (16 dg / (9 sqrt 3 z0)) gives lambda = 1.16 mu
    (Johnson & Greenwood 1997)."""
    sigma0_factor = 16.0 / (9.0 * math.sqrt(3.0))
    return 2 * sigma0_factor * (9.0 / (16.0 * math.pi)) ** (1.0 / 3.0) * tabor_mu
