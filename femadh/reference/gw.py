"""Greenwood-Williamson asperity statistics (paper 1 eqs 20-26) by direct quadrature: the
judge of the closed-form laws in :mod:`femadh.laws.gw`, and the source of the paper's Fig 7
and Table 2 numbers.

Eq 26, the Gaussian density of summit heights, is printed with the normalisation
1/sqrt(2 pi sigma_a); it must read 1/(sqrt(2 pi) sigma_a) to integrate to 1 and to have units
of 1/length. Every quantity here integrates eqs 23-25 against that density with adaptive
quadrature (scipy.integrate.quad), independently of the parabolic-cylinder closed forms the
solver uses.
"""
from dataclasses import dataclass
import math

import numpy as np
from scipy import integrate

#: the density is negligible (< 1e-300) beyond this many sigma_a from its mean
_SPAN = 38.0


def height_density(z, z_m, sigma_a):
    """phi(z) of eq 26 with the normalisation corrected (1/m)."""
    return np.exp(-((np.asarray(z) - z_m) ** 2) / (2 * sigma_a**2)) / (math.sqrt(2 * math.pi)
                                                                      * sigma_a)


@dataclass(frozen=True)
class SummitStatistics:
    """Composite summit statistics (paper 1 sec 6): rms height sigma_a (m), mean height z_m
    above the mean plane (m), summit radius R_a (m), density rho (1/m^2). Same attributes as
    :class:`femadh.laws.gw.Summits`, so a law can be built from it."""

    sigma_a: float
    z_m: float
    radius: float
    density: float

    def _moment(self, d, n):
        """int_d^inf (z - d)^n phi(z) dz by quadrature (m^n), vectorised in d."""
        def one(x):
            top = self.z_m + _SPAN * self.sigma_a
            if x >= top:
                return 0.0
            return integrate.quad(lambda z: (z - x) ** n * height_density(z, self.z_m,
                                                                          self.sigma_a),
                                  x, top, epsabs=0.0, epsrel=1e-12, limit=200)[0]
        return np.vectorize(one, otypes=[float])(np.asarray(d, float))

    def contact_probability(self, d):
        """p = int_d^inf phi dz: the fraction of summits touching at separation d (m)."""
        return self._moment(d, 0)

    def elastic_pressure(self, d, e_star):
        """P_ela (Pa), eq 23: 4/3 E* rho sqrt(R_a) int (z - d)^(3/2) phi dz."""
        return 4.0 / 3.0 * e_star * self.density * math.sqrt(self.radius) * self._moment(d, 1.5)

    def lj_pressure(self, d, work_of_adhesion):
        """P_LJa (Pa), eq 24: 2 pi R_a dg rho p (eq 20 with the contact probability)."""
        return (2 * math.pi * self.radius * work_of_adhesion * self.density
                * self.contact_probability(d))

    def real_area_ratio(self, d):
        """AR_a, eq 25: pi R_a rho int (z - d) phi dz."""
        return math.pi * self.radius * self.density * self._moment(d, 1)


def composite(s1, s2, density):
    """Combine two surfaces' (rms height, mean height, summit radius) (paper 1 sec 6):
    sigma = sqrt(s1^2 + s2^2), z_m = z1 + z2, 1/R = 1/R1 + 1/R2; density chosen separately."""
    return SummitStatistics(math.hypot(s1[0], s2[0]), s1[1] + s2[1],
                            1.0 / (1.0 / s1[2] + 1.0 / s2[2]), density)


def paper1_table2_roughness(density):
    """Composite statistics of the R2 glass slider and the magnetic disk (Table 2)."""
    slider = (0.15e-9, 0.56e-9, 1.36e-6)
    disk = (0.31e-9, 0.52e-9, 3.06e-6)
    return composite(slider, disk, density)


def mean_plane_dominance_bound(z0, asperity_radius, density):
    """Largest sigma with P_LJa(p = 1) <= P_LJ(sigma), eq 22: (4 z0^2 / (3 pi R_a rho))^(1/3)."""
    return (4.0 / 3.0 * z0 * z0 / (math.pi * asperity_radius * density)) ** (1.0 / 3.0)
