"""Capillary force of a film-covered sphere on a film-covered flat (paper 2), SI units.

Forces are on the sphere, attractive positive, and normalised by 4 pi R gamma with R the
*solid* sphere radius (the film-covered sphere has radius R + h).
"""
from dataclasses import dataclass, field
import math

import numpy as np

from ..errors import ConvergenceError, DomainError
from .circular import circular_force, circular_profile, solve_circular
from .geometry import Geometry, force_over_2pi
from .kelvin import kelvin_radius
from .profile_fe import MeridianFE
from .shooting import solve_shooting

from .methods import METHODS  # noqa: E402  (re-exported)


@dataclass
class MeniscusResult:
    """One meniscus.

    Attributes
    ----------
    method : str
    force : float
        Capillary force on the sphere (N), attractive positive.
    force_over_4piRgamma : float
    filling_angle : float
        phi (rad) on the film-covered sphere.
    neck_radius : float
        Radius of the neck (m; nan if the meridian has no vertical point).
    kelvin_radius, film : float
        r_K (m, negative) and adsorbed film thickness h (m) used.
    r, z : ndarray
        Meridian (m) from the flat to the sphere; z from the flat's film surface.
    force_neck, force_flat : float
        The force evaluated at the neck and at the flat's contact line (N): equal to ``force``
        for an exact solution (first integral of Young-Laplace).
    n_iter : int
    state : object
        Warm start for the next solve of a sweep (FE only).
    """

    method: str
    force: float
    force_over_4piRgamma: float
    filling_angle: float
    neck_radius: float
    kelvin_radius: float
    film: float
    r: np.ndarray = field(repr=False)
    z: np.ndarray = field(repr=False)
    force_neck: float = math.nan
    force_flat: float = math.nan
    n_iter: int = 0
    state: object = field(default=None, repr=False)


def _circle_guess(fe, geo):
    """FE initial guess from the circular approximation; past its own limits (no neck below the
    equator) the circle is still a usable starting shape, so the FE solve can report where the
    exact meniscus goes instead of failing on the approximation's limit."""
    try:
        phi_c, rho, _ = solve_circular(geo)
    except DomainError:
        phi_c, rho, _ = solve_circular(geo, phi_max=0.95 * math.pi)
    return fe.initial_from_circle(geo, phi_c, rho)


def _fe_solver(n, cache={}):
    if n not in cache:
        cache[n] = MeridianFE(n)
    return cache[n]


def meniscus(method, radius, gamma, r_k, film=0.0, separation=None, *, elements=16,
             warm=None):
    """Solve one meniscus.

    Parameters
    ----------
    method : {"fe", "shooting", "circular", "no-film"}
        ``no-film`` is the exact (FE) meniscus on the bare solids: film = 0, zero contact angle.
    radius : float
        Solid sphere radius R (m).
    gamma : float
        Surface tension (N/m).
    r_k : float
        Kelvin radius (m, < 0).
    film : float
        Adsorbed film thickness h (m) on sphere and flat (ignored for ``no-film``).
    separation : float or None
        Solid-solid separation s >= 0 (m); None = contact (s = 0, so D = -2h, paper 2 Fig 2b).
    elements : int
        FE elements of the meridian.
    warm : MeniscusResult, optional
        Previous solution of a sweep (continuation).

    Raises
    ------
    DomainError
        No meniscus exists (foot past the equator, no neck in the circular approximation, ...).
    """
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {method!r}")
    if not r_k < 0:
        raise DomainError(f"Kelvin radius {r_k} m must be negative (p < psat)")
    h = 0.0 if method == "no-film" else float(film)
    s = 0.0 if separation is None else float(separation)
    if s < 0:
        raise DomainError(f"solid separation {s} m is negative: the solids would overlap")
    Re = radius + h
    geo = Geometry(Re / r_k, (s - 2 * h) / Re)
    F0 = 4 * math.pi * radius * gamma
    scale = 2 * math.pi * gamma * Re
    if method == "circular":
        phi, rho, rn = solve_circular(geo)
        F = circular_force(geo, phi) * scale
        r, z, _ = circular_profile(geo, phi, rho)
        return MeniscusResult(method, F, F / F0, phi, rn * Re, r_k, h, r * Re, z * Re,
                              force_over_2pi(rn, math.pi / 2, geo.kappa) * scale,
                              -0.5 * geo.kappa * r[0] ** 2 * scale)
    if method == "shooting":
        phi_c, rho, rn = solve_circular(geo)
        phi, r, z, psi = solve_shooting(geo, phi_c)
        F = force_over_2pi(math.sin(phi), phi, geo.kappa) * scale
        k = np.flatnonzero(np.diff(np.sign(psi - math.pi / 2)))
        rn = float(np.interp(math.pi / 2, psi[k[0]:k[0] + 2][::-1], r[k[0]:k[0] + 2][::-1])) \
            if k.size else math.nan
        return MeniscusResult(method, F, F / F0, phi, rn * Re, r_k, h, r * Re, z * Re,
                              force_over_2pi(rn, math.pi / 2, geo.kappa) * scale,
                              -0.5 * geo.kappa * r[0] ** 2 * scale)
    fe = _fe_solver(elements)
    init = None
    if warm is not None and isinstance(warm.state, tuple) and warm.state[0] == elements:
        init = warm.state[1]
    if init is None:
        init = _circle_guess(fe, geo)
    try:
        sol = fe.solve(geo, init)
    except ConvergenceError:
        if warm is None:
            raise
        sol = fe.solve(geo, _circle_guess(fe, geo))  # continuation failed: restart
    F = sol.force_contact(geo) * scale
    neck = sol.neck(geo)
    r, z, _ = sol.profile()
    return MeniscusResult(method, F, F / F0, sol.phi, neck[1] * Re if neck else math.nan, r_k,
                          h, r * Re, z * Re, neck[2] * scale if neck else math.nan,
                          sol.force_flat(geo) * scale, sol.n_iter,
                          (elements, (sol.psi.copy(), sol.r.copy(), sol.z.copy(), sol.S,
                                      sol.phi)))


def sweep_points(method, radius, liquid, temperature, isotherm, p_ratios, separation=None, *,
                 elements=16):
    """Solve along p/psat with continuation, yielding (p/psat, MeniscusResult) or, where no
    meniscus exists or its solve fails, (p/psat, the DomainError/ConvergenceError saying why):
    such a point does not stop the sweep (the next one starts afresh)."""
    warm = None
    for x in p_ratios:
        try:
            r_k = kelvin_radius(liquid, x, temperature)
            h = 0.0 if (method == "no-film" or isotherm is None) else float(isotherm(x))
            res = meniscus(method, radius, liquid.surface_tension, r_k, h, separation,
                           elements=elements, warm=warm)
            warm = res
        except (DomainError, ConvergenceError) as exc:
            res, warm = exc, None
        yield x, res


def sweep(method, radius, liquid, temperature, isotherm, p_ratios, separation=None, *,
          elements=16):
    """:func:`sweep_points` as a list of results/errors, one per p/psat, in order."""
    return [r for _, r in sweep_points(method, radius, liquid, temperature, isotherm,
                                       p_ratios, separation, elements=elements)]
