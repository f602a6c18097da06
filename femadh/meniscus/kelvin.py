"""Kelvin equation, paper 2 eq (6)."""
import math

from ..errors import DomainError

#: universal gas constant R_u (J/(mol K)), CODATA 2018 (exact)
R_GAS = 8.314462618


def kelvin_radius(liquid, p_ratio, temperature):
    """Kelvin radius r_K = gamma V_m / (R_u T ln(p/psat)) (m), eq (6); negative for p < psat.

    Raises DomainError outside 0 < p/psat < 1 (no meniscus at or above saturation).
    """
    if not 0.0 < p_ratio < 1.0:
        raise DomainError(f"relative pressure p/psat = {p_ratio!r} is outside (0, 1): the "
                          "Kelvin radius is infinite at saturation and undefined beyond")
    return liquid.surface_tension * liquid.molar_volume / (R_GAS * temperature * math.log(p_ratio))
