"""Capillary condensate in the contact gap (paper 2 physics inside a paper 1 scene).

Vapour at p/psat condenses where the local gap is narrow enough for a meniscus of Kelvin
curvature to span it. With zero contact angle on adsorbed films of thickness t on both
surfaces, the meniscus edge sits where the free gap g - 2t equals 2|r_K| (meridional curvature
-2/(g - 2t) = 1/r_K; the azimuthal curvature ~ 1/r_edge is neglected, R >> |r_K|). Inside,
the liquid pulls the surfaces together with the Laplace pressure gamma/|r_K|:

    P(h) = (gamma / |r_K|) * S((h_fill - h) / w),   h_fill = 2 |r_K| + 2 t,

with S a logistic step of width w (a small fraction of h_fill) so that the law is smooth for
Newton; U(h) = -(gamma/|r_K|) w softplus((h_fill - h)/w), dU/dh = P. For a rigid sphere
with R >> |r_K| >> t the force is 4 pi R gamma (1 + t/|r_K|): the textbook limit.
The surface-tension ring force at the meniscus edge (relative size ~ sqrt(|r_K|/R)) is left out.
"""
from dataclasses import dataclass

from .step import SmoothStepLaw


@dataclass(frozen=True)
class CapillaryCondensate(SmoothStepLaw):
    """Attributes: surface_tension gamma (N/m), kelvin_radius r_K (m, < 0), film t (m),
    width w (m) of the smoothed meniscus edge."""

    surface_tension: float
    kelvin_radius: float
    film: float = 0.0
    width: float = 0.0

    def __post_init__(self):
        if not self.kelvin_radius < 0:
            raise ValueError(f"kelvin_radius must be < 0 (p < psat), got {self.kelvin_radius}")
        if not self.width > 0:
            object.__setattr__(self, "width", 0.02 * self.fill_gap)

    @property
    def laplace_pressure(self):
        """gamma / |r_K| (Pa): the suction of the condensate."""
        return self.surface_tension / abs(self.kelvin_radius)

    @property
    def fill_gap(self):
        """Gap (m) below which the condensate fills: 2 |r_K| + 2 t."""
        return 2 * abs(self.kelvin_radius) + 2 * self.film

    @property
    def _amplitude(self):
        return self.laplace_pressure

    @property
    def _center(self):
        return self.fill_gap
