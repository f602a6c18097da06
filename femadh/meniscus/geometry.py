"""Pendular-ring geometry with adsorbed films (paper 2 Fig 2b), in units of R_e = R + h.

The flat's film surface is the plane z = 0; the film-covered sphere has radius R_e = R + h and
its lowest point at height D (D = s - 2h for a solid-solid separation s; D = -2h in contact,
where the film-covered sphere interpenetrates the film-covered flat, which paper 2 notes does
not affect the capillary force). Its centre is at z_c = R_e + D.

The meridian of the meniscus runs from the flat (r_2, 0), tangent to it (zero contact angle on
the film: psi = pi), to the sphere point (R_e sin phi, z_c - R_e cos phi), tangent to the sphere
(psi = phi, phi = filling angle). Along it psi' = kappa - sin(psi)/r, r' = cos psi,
z' = sin psi, with kappa = 1/r_K the Kelvin curvature (negative), and

    F / (2 pi gamma) = r sin(psi) - kappa r^2 / 2        (first integral: constant)

is the capillary force on the sphere (attractive positive), evaluated anywhere on the meridian.
"""
from dataclasses import dataclass
import math


@dataclass(frozen=True)
class Geometry:
    """Dimensionless problem: kappa = R_e / r_K and D' = D / R_e."""

    kappa: float
    D: float

    @property
    def zc(self):
        return 1.0 + self.D

    def sphere_point(self, phi):
        return math.sin(phi), self.zc - math.cos(phi)

    @property
    def phi_min(self):
        """Smallest filling angle with the sphere point above the flat (0 unless D < 0)."""
        c = 1.0 + self.D
        return math.acos(min(1.0, c)) if c < 1.0 else 0.0


def force_over_2pi(r, psi, kappa):
    """F / (2 pi gamma R_e) from a point (r, psi) of the meridian (first integral)."""
    return r * math.sin(psi) - 0.5 * kappa * r * r
