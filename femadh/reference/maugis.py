"""Maugis-Dugdale adhesive contact (Maugis 1992, J. Colloid Interface Sci. 150:243) and the
JKR/DMT limits in Maugis' dimensionless variables.

    A = a (K / (pi dg R^2))^(1/3),  P = F / (pi dg R),  D = delta (K^2 / (pi^2 dg^2 R))^(1/3),
    K = 4 E* / 3,  lambda = 2 sigma0 (R / (pi dg K^2))^(1/3).

Parametric in m = c/a (> 1, c the radius of the Dugdale cohesive zone):

    (lam A^2 / 2)[s + (m^2 - 2) atan s] + (4 lam^2 A / 3)[s atan s - m + 1] = 1,   s = sqrt(m^2-1)
    P = A^3 - lam A^2 (s + m^2 atan s)
    D = A^2 - (4/3) lam A s

F positive = compressive load (the adhesive pull-off is the most negative P).

Two pull-offs: under load control the contact breaks at the most negative P
(:func:`maugis_pull_off`); under displacement control (fixed grips) it breaks where the P(D)
curve has a vertical tangent, dD/dm = 0 with the separation -D largest
(:func:`maugis_fixed_grip_pull_off`): -(5/6) in the JKR limit, and no such point (a smooth
separation) below lambda ~ 0.938.
"""
import math

import numpy as np
from scipy import optimize


def maugis_curve(lam, m):
    """(A, P, D) arrays of the Maugis-Dugdale solution for lambda and m-values (> 1); complex
    m is passed through (for complex-step derivatives)."""
    m = np.asarray(m)
    m = m.astype(np.result_type(m.dtype, float))
    s = np.sqrt(m * m - 1)
    at = np.arctan(s)
    alpha = 0.5 * lam * (s + (m * m - 2) * at)
    beta = 4.0 * lam * lam / 3.0 * (s * at - m + 1)
    A = (-beta + np.sqrt(beta * beta + 4 * alpha)) / (2 * alpha)
    P = A**3 - lam * A * A * (s + m * m * at)
    D = A * A - 4.0 / 3.0 * lam * A * s
    return A, P, D


#: log(m - 1) range scanned for the extrema of the parametric curve: m - 1 from 1e-11 (the JKR
#: end at large lambda) to 1.6e5 (A -> 0, the curve's end as the contact vanishes)
_LOG_M1 = np.linspace(-25.0, 12.0, 1500)


def _refined_min(f, xs, values):
    """Minimum of f near the smallest of its sampled ``values`` (bounded Brent between the
    sample's neighbours). Returns (x, f(x))."""
    k = int(np.argmin(values))
    lo, hi = xs[max(k - 1, 0)], xs[min(k + 1, xs.size - 1)]
    res = optimize.minimize_scalar(f, bounds=(lo, hi), method="bounded",
                                   options={"xatol": 1e-12})
    return (float(res.x), float(res.fun)) if res.fun < values[k] else (xs[k], values[k])


def maugis_pull_off(lam):
    """Load-controlled pull-off -min P (in units of pi dg R): 2 (DMT) at lam -> 0, 1.5 (JKR)
    at lam -> inf."""
    return -maugis_pull_off_state(lam)[2]


def maugis_pull_off_state(lam):
    """The load-controlled pull-off state (m, A, P): m = c/a the cohesive zone's outer radius
    over the contact radius, A and P in Maugis units (P the most negative load). The cohesive
    zone's width there is (m - 1) A a_unit (:func:`maugis_length_units`)."""
    def P_of_logm(x):
        return maugis_curve(lam, 1.0 + np.exp(x))[1]

    x, P = _refined_min(P_of_logm, _LOG_M1, P_of_logm(_LOG_M1))
    m = 1.0 + float(np.exp(x))
    return m, float(maugis_curve(lam, m)[0]), float(P)


def maugis_fixed_grip_pull_off(lam):
    """Displacement-controlled (fixed-grip) pull-off of Maugis-Dugdale.

    Under fixed grips the contact is stable until the P(D) curve has a vertical tangent:
    dD/dm = 0 at the smallest (most tensile) approach D, after which the contact jumps off.

    Parameters
    ----------
    lam : float
        Maugis' lambda (-).

    Returns
    -------
    (pull_off, D) or None
        -P (units of pi dg R) and the approach D (Maugis units) at the vertical tangent; None
        when D(m) decreases all the way to the curve's end (A -> 0): no fixed-grip
        instability, the contact peels off smoothly (lambda below 0.9379). JKR limit: 5/6 at
        A = 6^(-1/3), D = 6^(-2/3) - (2/3) 6^(1/3) = -0.9086.
    """
    def D_of_logm(x):
        return maugis_curve(lam, 1.0 + np.exp(x))[2]

    def dD_dlogm(x):
        # complex-step derivative: exact to rounding, so the root is as sharp as the curve
        # (minimising D itself locates a flat minimum only to sqrt(eps))
        return float(np.imag(D_of_logm(complex(x, 1e-30)))) / 1e-30

    D = D_of_logm(_LOG_M1)
    k = int(np.argmin(D))
    if k >= _LOG_M1.size - 2 or k == 0:
        return None
    x = optimize.brentq(dD_dlogm, _LOG_M1[k - 1], _LOG_M1[k + 1], xtol=1e-14, maxiter=100)
    _, P, Dv = maugis_curve(lam, 1.0 + np.exp(x))
    return -float(P), float(Dv)


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


def maugis_length_units(radius, e_star, work_of_adhesion):
    """(a_unit, delta_unit) in m: Maugis' A = a / a_unit, D = delta / delta_unit."""
    K = 4.0 * e_star / 3.0
    dg = work_of_adhesion
    return ((math.pi * dg * radius**2 / K) ** (1 / 3),
            (math.pi**2 * dg**2 * radius / K**2) ** (1 / 3))


def lj_dugdale_lambda(tabor_mu):
    """Maugis lambda matching a Lennard-Jones 3-9 surface law of Tabor parameter mu: the
    Dugdale stress equal to the LJ maximum (16 dg / (9 sqrt 3 z0)) gives lambda = 1.16 mu
    (Johnson & Greenwood 1997)."""
    sigma0_factor = 16.0 / (9.0 * math.sqrt(3.0))
    return 2 * sigma0_factor * (9.0 / (16.0 * math.pi)) ** (1.0 / 3.0) * tabor_mu


def jkr_snap_off_with_spring(k_tilde):
    """JKR pull-off tension recorded by an instrument of stiffness k in series (in units of
    pi dg R), k_tilde = k delta_unit / (pi dg R) (Maugis units, :func:`maugis_length_units`).

    Along the JKR curve (:func:`jkr_curve`; P the load, compressive positive, D the approach)
    a spring of stiffness k holds the contact while dP/dD > -k; it snaps off where
    dP/dD = P'(A)/D'(A) = -k, on the part between the load-controlled pull-off (P' = 0,
    A^3 = 3/2, tension 3/2) and the displacement-controlled one (D' = 0, A^3 = 1/6, tension
    5/6). k -> 0 gives 3/2, k -> infinity 5/6.
    """
    from scipy import optimize

    def slope_plus_k(A):
        dP = 3 * A * A - 1.5 * math.sqrt(6 * A)
        dD = 2 * A - math.sqrt(6 / A) / 3
        return dP + k_tilde * dD
    a_lo, a_hi = (1 / 6) ** (1 / 3), 1.5 ** (1 / 3)
    if k_tilde <= 0:
        A = a_hi
    else:
        A = optimize.brentq(slope_plus_k, a_lo * (1 + 1e-12), a_hi, xtol=1e-14, maxiter=200)
    P, _ = jkr_curve(A)
    return float(-P)
