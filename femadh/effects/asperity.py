"""Asperity effects (paper 1 sec 5.2-6).

- :class:`AsperityAdhesion`: eq (20), P_LJa = 2 pi R_a dg rho p, acting "over the contact
  region" with the sigma-gap model. In femadh's complementarity model the contact region is
  where the gap sits at sigma, so the law is a step down to zero just above sigma:
  P(h) = P_LJa S((sigma + 5 w - h)/w) with w = smoothing * sigma (S logistic; S(5) = 0.993).
- :class:`GWElastic`, :class:`GWAdhesion`: the Greenwood-Williamson asperity pressures of eqs
  (23)-(24) as smooth laws of the local mean-plane gap h (summits taller than h touch), the
  continuous alternative to the hard sigma-gap (beyond the paper).
"""
from dataclasses import dataclass
import math

import numpy as np

from ..reference.gw import Roughness, gw_integral
from .step import SmoothStepLaw


@dataclass(frozen=True)
class AsperityAdhesion(SmoothStepLaw):
    """Attributes: pressure P_LJa (Pa, eq 20), sigma (m), width w (m)."""

    pressure_value: float
    sigma: float
    width: float

    @classmethod
    def from_asperities(cls, asperity_radius, surface_energy, density, probability, sigma,
                        smoothing=0.02):
        p = 2 * math.pi * asperity_radius * surface_energy * density * probability
        return cls(p, sigma, smoothing * sigma)

    @property
    def _amplitude(self):
        return self.pressure_value

    @property
    def _center(self):
        return self.sigma + 5 * self.width


@dataclass(frozen=True)
class GWElastic:
    """Repulsive asperity pressure -P_ela(h) (attractive-positive convention), eq 23."""

    roughness: Roughness
    e_star: float

    @property
    def _c(self):
        r = self.roughness
        return 4.0 / 3.0 * self.e_star * r.density * math.sqrt(r.radius)

    def pressure(self, h):
        r = self.roughness
        return -self._c * r.sigma_a**1.5 * gw_integral(1.5, r.t(h))

    def dpressure(self, h):
        r = self.roughness
        return self._c * 1.5 * r.sigma_a**0.5 * gw_integral(0.5, r.t(h))

    def energy(self, h):
        r = self.roughness
        return self._c * 0.4 * r.sigma_a**2.5 * gw_integral(2.5, r.t(h))


@dataclass(frozen=True)
class GWAdhesion:
    """Adhesive asperity pressure P_LJa(h) = 2 pi R_a dg rho p(h), eqs 20 and 24."""

    roughness: Roughness
    surface_energy: float

    @property
    def _c(self):
        r = self.roughness
        return 2 * math.pi * r.radius * self.surface_energy * r.density

    def pressure(self, h):
        return self._c * gw_integral(0.0, self.roughness.t(h))

    def dpressure(self, h):
        r = self.roughness
        t = r.t(h)
        return -self._c * np.exp(-t * t / 2) / (math.sqrt(2 * math.pi) * r.sigma_a)

    def energy(self, h):
        r = self.roughness
        return -self._c * r.sigma_a * gw_integral(1.0, r.t(h))
