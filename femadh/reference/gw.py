"""Greenwood-Williamson asperity statistics (paper 1 eqs 20-26), vectorised.

Gaussian summit heights (eq 26; the printed 1/sqrt(2 pi sigma_a) must read
1/(sqrt(2 pi) sigma_a) for phi to integrate to 1 and to have units of 1/length). With
t = (d - z_m)/sigma_a the integrals reduce to

    I_n(t) = int_t^inf (s - t)^n phi*(s) ds = Gamma(n+1) exp(-t^2/4) D_{-n-1}(t) / sqrt(2 pi)

(phi* the standard normal density, D_v the parabolic cylinder function: scipy.special.pbdv).
"""
from dataclasses import dataclass
import math

import numpy as np
from scipy import special


#: |t| beyond which scipy's pbdv overflows (t < 0) or returns nan (t > ~2071); there
#: I_n is 0 in double precision (t > 0: below 1e-300) or its Gaussian-moment series (t < 0)
_T_SAFE = 37.0


def gw_integral(n, t):
    """I_n(t) = int_t^inf (s - t)^n phi*(s) ds for n > -1, vectorised in t (finite for all t)."""
    t = np.asarray(t, float)
    tc = np.clip(t, -_T_SAFE, _T_SAFE)
    d, _ = special.pbdv(-n - 1.0, tc)
    out = special.gamma(n + 1.0) * np.exp(-tc * tc / 4.0) * d / math.sqrt(2 * math.pi)
    out = np.where(t > _T_SAFE, 0.0, out)
    low = t < -_T_SAFE
    if np.any(low):
        # E[(X + c)^n], c = -t > 37: the mass below -c is < 1e-300; binomial series in 1/c^2
        # with the Gaussian moments E[X^2k] = (2k-1)!!, 4 terms: relative error < 1e-12
        c = -t[low]
        series = np.ones_like(c)
        coef, moment = 1.0, 1.0
        for k in range(1, 4):
            coef *= (n - 2 * k + 2) * (n - 2 * k + 1) / ((2 * k - 1) * (2 * k))
            moment *= 2 * k - 1
            series = series + coef * moment * c ** (-2.0 * k)
        out = np.array(out, float)
        out[low] = c**n * series
    return out


def height_density(z, z_m, sigma_a):
    """phi(z) of eq 26 with the normalisation corrected (1/m)."""
    return np.exp(-((np.asarray(z) - z_m) ** 2) / (2 * sigma_a**2)) / (math.sqrt(2 * math.pi)
                                                                      * sigma_a)


@dataclass(frozen=True)
class Roughness:
    """Composite asperity statistics of two rough surfaces (paper 1 sec 6, Table 2).

    Attributes
    ----------
    sigma_a : float
        rms summit height (m).
    z_m : float
        mean summit height above the mean plane (m).
    radius : float
        R_a, mean summit radius (m).
    density : float
        rho, summits per area (1/m^2).
    """

    sigma_a: float
    z_m: float
    radius: float
    density: float

    @classmethod
    def composite(cls, s1, s2, density):
        """Combine two surfaces' (rms height, mean height, radius): sigma = sqrt(s1^2 + s2^2),
        z_m = z1 + z2, 1/R = 1/R1 + 1/R2 (paper 1 sec 6); density is chosen separately."""
        return cls(math.hypot(s1[0], s2[0]), s1[1] + s2[1], 1.0 / (1.0 / s1[2] + 1.0 / s2[2]),
                   density)

    def t(self, d):
        return (np.asarray(d, float) - self.z_m) / self.sigma_a

    def contact_probability(self, d):
        """p = int_d^inf phi dz (fraction of summits touching at separation d)."""
        return gw_integral(0.0, self.t(d))

    def elastic_pressure(self, d, e_star):
        """P_ela (Pa), eq 23: 4/3 E* rho sqrt(R_a) int (z - d)^(3/2) phi dz."""
        return (4.0 / 3.0 * e_star * self.density * math.sqrt(self.radius)
                * self.sigma_a**1.5 * gw_integral(1.5, self.t(d)))

    def lj_pressure(self, d, work_of_adhesion):
        """P_LJa (Pa), eq 24: 2 pi R_a dg rho p (eq 20 with the contact probability)."""
        return (2 * math.pi * self.radius * work_of_adhesion * self.density
                * self.contact_probability(d))

    def real_area_ratio(self, d):
        """AR_a, eq 25: pi R_a rho int (z - d) phi dz."""
        return math.pi * self.radius * self.density * self.sigma_a * gw_integral(1.0, self.t(d))


def paper1_table2_roughness(density):
    """Composite roughness of the R2 glass slider and the magnetic disk (Table 2)."""
    slider = (0.15e-9, 0.56e-9, 1.36e-6)
    disk = (0.31e-9, 0.52e-9, 3.06e-6)
    return Roughness.composite(slider, disk, density)


def mean_plane_dominance_bound(z0, asperity_radius, density):
    """Largest sigma with P_LJa(p = 1) <= P_LJ(sigma), eq 22: (4 z0^2 / (3 pi R_a rho))^(1/3)."""
    return (4.0 / 3.0 * z0 * z0 / (math.pi * asperity_radius * density)) ** (1.0 / 3.0)
