"""Capillary meniscus with adsorbed film (paper 2): liquids, isotherms, Kelvin radius, and the
axisymmetric Young-Laplace meniscus between a sphere and a flat by three methods (1D finite
elements, ODE shooting, circular approximation) plus the classic no-film model.
"""
from .liquids import LIQUIDS, Liquid
from .isotherms import BET, GAB, Polynomial, Tabulated, default_isotherm
from .kelvin import kelvin_radius


__all__ = ["LIQUIDS", "Liquid", "BET", "GAB", "Polynomial", "Tabulated", "default_isotherm",
           "kelvin_radius"]
from .solve import METHODS, MeniscusResult, meniscus, sweep  # noqa: E402

__all__ += ["METHODS", "MeniscusResult", "meniscus", "sweep"]
