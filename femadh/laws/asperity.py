"""Asperity adhesion of eq (20) acting "over the contact region" of the sigma-gap model,
as a smooth law: P(h) = P_LJa S((sigma + 5 w - h)/w) with w = smoothing * sigma (S logistic;
S(5) = 0.993), P_LJa = 2 pi R_a dg rho p.

A range-less pressure on the contact set is the paper's statement; the smoothed step is one way
to give it a range, and the result depends on the width (see validation/README.md). The exact
range-less limit is a property of the sigma-gap constraint (a contact node holds tension up to
P_LJa): :class:`femadh.contact.constraints.AsperityGap` with ``adhesion``.
"""
from dataclasses import dataclass
import math

from .step import SmoothStepLaw


def eq20_pressure(asperity_radius, surface_energy, density, probability):
    """P_LJa = 2 pi R_a dg rho p (Pa), paper 1 eq (20): the summits in contact (a fraction p
    of rho per area, radius R_a) each pull with the Derjaguin force 2 pi R_a dg."""
    return 2 * math.pi * asperity_radius * surface_energy * density * probability


@dataclass(frozen=True)
class AsperityAdhesion(SmoothStepLaw):
    """Attributes: pressure P_LJa (Pa, eq 20), sigma (m), width w (m)."""

    pressure_value: float
    sigma: float
    width: float

    @classmethod
    def from_asperities(cls, asperity_radius, surface_energy, density, probability, sigma,
                        smoothing=0.02):
        return cls(eq20_pressure(asperity_radius, surface_energy, density, probability), sigma,
                   smoothing * sigma)

    @property
    def _amplitude(self):
        return self.pressure_value

    @property
    def _center(self):
        return self.sigma + 5 * self.width
