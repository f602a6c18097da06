"""Adsorption isotherms: film thickness h (m) as a function of x = p/psat.

The adsorbed film is part of the condensed phase (paper 2 sec 1, 2.1): at equilibrium with the
vapour it covers the sphere and the flat with thickness h(x).
"""
from dataclasses import dataclass

import numpy as np

from ..errors import DomainError


def _check_x(x):
    x = np.asarray(x, float)
    if np.any((x <= 0) | (x >= 1)):
        raise DomainError(f"relative pressure outside (0, 1): {x}")
    return x


@dataclass(frozen=True)
class GAB:
    """Guggenheim-Anderson-de Boer: h = t_m c k x / ((1 - k x)(1 - k x + c k x)).

    Attributes: monolayer thickness t_m (m), energy constant c, multilayer factor k (< 1 keeps
    the film finite at saturation; k = 1 is BET).
    """

    monolayer: float
    c: float
    k: float
    source: str = "user supplied"

    def __call__(self, x):
        x = _check_x(x)
        kx = self.k * x
        return self.monolayer * self.c * kx / ((1 - kx) * (1 - kx + self.c * kx))


@dataclass(frozen=True)
class BET:
    """Brunauer-Emmett-Teller: h = t_m c x / ((1 - x)(1 - x + c x)); diverges at saturation."""

    monolayer: float
    c: float
    source: str = "user supplied"

    def __call__(self, x):
        x = _check_x(x)
        return self.monolayer * self.c * x / ((1 - x) * (1 - x + self.c * x))


@dataclass(frozen=True)
class Polynomial:
    """h = sum_i a_i x^i (coefficients in metres, lowest order first)."""

    coefficients: tuple
    source: str = "user supplied"

    def __call__(self, x):
        x = _check_x(x)
        return np.polynomial.polynomial.polyval(x, np.asarray(self.coefficients, float))


@dataclass(frozen=True)
class Tabulated:
    """Measured (x, h) pairs, interpolated linearly (monotone x required)."""

    x: tuple
    h: tuple
    source: str = "user supplied"

    def __post_init__(self):
        if len(self.x) != len(self.h) or len(self.x) < 2 or np.any(np.diff(self.x) <= 0):
            raise ValueError("tabulated isotherm needs >= 2 points with increasing x")

    def __call__(self, x):
        x = _check_x(x)
        if np.any(x < self.x[0]) or np.any(x > self.x[-1]):
            raise DomainError(f"p/psat = {x} outside the tabulated range "
                              f"[{self.x[0]}, {self.x[-1]}]")
        return np.interp(x, self.x, self.h)


_REPRESENTATIVE = ("representative GAB parameters chosen by femadh to give a sub-monolayer "
                   "film at low p/psat and ~1.5 nm near saturation, the order of alcohol "
                   "films on hydroxylated SiO2 reported by Asay & Kim; NOT fitted to their "
                   "data and NOT the polynomial of paper 2, which is not in its text")

#: monolayer thickness ~ molecular size (m): a rough estimate from the molar volume
_DEFAULTS = {"ethanol": GAB(0.46e-9, 15.0, 0.7, _REPRESENTATIVE),
             "n-butanol": GAB(0.54e-9, 15.0, 0.7, _REPRESENTATIVE),
             "n-pentanol": GAB(0.57e-9, 15.0, 0.7, _REPRESENTATIVE),
             "water": GAB(0.28e-9, 15.0, 0.7, _REPRESENTATIVE)}


def default_isotherm(liquid_name):
    """The representative isotherm for a built-in liquid (see the ``source`` attribute)."""
    try:
        return _DEFAULTS[liquid_name]
    except KeyError:
        raise KeyError(f"no default isotherm for {liquid_name!r}; give one in the scene") \
            from None
