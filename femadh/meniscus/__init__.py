"""Capillary meniscus with adsorbed film (paper 2): liquids, isotherms, Kelvin radius, and the
axisymmetric Young-Laplace meniscus between a sphere and a flat by three methods (1D finite
elements, ODE shooting, circular approximation) plus the classic no-film model.

The solvers (:mod:`.solve`) load on first use: a contact scene that names a liquid needs only
the liquid, its isotherm and the Kelvin radius.
"""
from .liquids import LIQUIDS, Liquid
from .isotherms import BET, GAB, Polynomial, Tabulated, default_isotherm
from .kelvin import kelvin_radius

__all__ = ["LIQUIDS", "Liquid", "BET", "GAB", "Polynomial", "Tabulated", "default_isotherm",
           "kelvin_radius", "METHODS", "MeniscusResult", "meniscus", "sweep"]
_SOLVE = ("METHODS", "MeniscusResult", "meniscus", "sweep")


def __getattr__(name):
    if name in _SOLVE:
        from . import solve

        return getattr(solve, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
