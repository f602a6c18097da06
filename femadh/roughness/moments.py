"""Spectral moments of a measured surface and the Greenwood-Williamson summit statistics they
imply (McCool's relations for an isotropic Gaussian surface).

The profile spectral moments of order n = 0, 2, 4 are

    m_n = (1/2 pi) int_{-q_c}^{q_c} |q|^n C1D(q) dq  ~  (1/L) sum_{|q| <= q_c} |q|^n C1D(q)

(C1D the power spectral density of the profiles, averaged over the profiles): m0 = <h^2>
(m^2), m2 = <(dh/dx)^2> (1) and m4 = <(d^2h/dx^2)^2> (1/m^2), evaluated with spectral (exact)
derivatives by SurfaceTopography's ``integrate_psd_from_profile``. For a 2D map the moments of
the profiles along x and along y are both computed and averaged (the isotropic surface of
McCool's relations has the same profile moments in every direction; their ratio is reported
as a check). The sum stops at the short-wavelength cutoff lambda_c = 2 pi / q_c: at the pixel
scale every wavevector up to the Nyquist one (lambda_c = 2 pixels) is kept; a longer cutoff
drops the shorter wavelengths of each profile. m0 hardly depends on it; m2 and, above all,
m4 grow with every decade of shorter wavelengths on a self-affine surface, which is why the
cutoff is always reported beside them.

References
----------
Nayak, P. R. (1971) Random process model of rough surfaces, J. Lubr. Technol. 93, 398-407.
McCool, J. I. (1986) Comparison of models for the contact of rough surfaces, Wear 107, 37-60.
"""
from dataclasses import dataclass
import math

import numpy as np

from ..laws.gw import Summits

#: summit density coefficient, eta = m4 / (6 pi sqrt(3) m2) (Nayak 1971; McCool 1986)
DENSITY_COEFF = 1.0 / (6.0 * math.pi * math.sqrt(3.0))
#: mean summit radius, beta = 0.375 sqrt(pi / m4): the inverse of the mean summit curvature
#: (8/3) sqrt(m4/pi) of Nayak's large-alpha limit (McCool 1986)
RADIUS_COEFF = 0.375
#: summit height variance, sigma_s^2 = (1 - 0.8968/alpha) m0 (McCool 1986)
VARIANCE_COEFF = 0.8968
#: mean summit height above the mean plane, z_m = 4 sqrt(m0) / sqrt(pi alpha) (McCool 1986)
MEAN_HEIGHT_COEFF = 4.0


@dataclass(frozen=True)
class SpectralMoments:
    """Profile spectral moments of a surface up to a short-wavelength cutoff.

    Attributes
    ----------
    m0 : float
        Mean square height (m^2).
    m2 : float
        Mean square profile slope (1).
    m4 : float
        Mean square profile curvature (1/m^2).
    cutoff : float
        Short-wavelength cutoff lambda_c (m): the shortest wavelength kept (the Nyquist
        wavelength, two pixels, at the pixel scale).
    anisotropy : float
        m2 along y over m2 along x (1 for an isotropic surface and for line scans).
    """

    m0: float
    m2: float
    m4: float
    cutoff: float
    anisotropy: float = 1.0

    @property
    def alpha(self):
        """Nayak's bandwidth parameter alpha = m0 m4 / m2^2 (>= 1 by Cauchy-Schwarz)."""
        return self.m0 * self.m4 / self.m2**2

    def __add__(self, other):
        """Composite of two independent surfaces: their moments add (the gap between them is
        the sum of two uncorrelated random fields, whose spectra add). The cutoff kept is the
        longer of the two (the composite is no better resolved than its coarser member)."""
        return SpectralMoments(self.m0 + other.m0, self.m2 + other.m2, self.m4 + other.m4,
                               max(self.cutoff, other.cutoff),
                               (self.m2 * self.anisotropy + other.m2 * other.anisotropy)
                               / (self.m2 + other.m2))


def nyquist_wavelength(topography):
    """Shortest wavelength the grid resolves, 2 pixels (m): the pixel-scale cutoff (the
    coarser direction of a map)."""
    return 2.0 * max(s / n for s, n in zip(topography.physical_sizes, topography.nb_grid_pts))


def profile_moments(topography, cutoff=None):
    """Profile spectral moments m0, m2, m4 of a topography, averaged over x and y profiles.

    Parameters
    ----------
    topography : SurfaceTopography Topography or UniformLineScan
        Heights in m (see :func:`femadh.roughness.reading.read_topography`). Non-periodic data
        are Hann-windowed before the transform (SurfaceTopography's default; it keeps the
        mean square), periodic data are not.
    cutoff : float, optional
        Short-wavelength cutoff lambda_c (m): only wavevectors |q| <= q_c = 2 pi / lambda_c
        of each profile are kept (the lattice line nearest q_c weighted by the part of its
        cell below q_c: the band-limited integral by the midpoint rule). None: the pixel
        scale (every wavevector up to Nyquist).

    Returns
    -------
    SpectralMoments
        For a map, the mean of the moments of the profiles along x and along y; for a line
        scan, its own (the surface assumed isotropic).
    """
    q_c = None if cutoff is None else 2.0 * math.pi / cutoff

    def moments(t):
        if q_c is None:
            def keep(q):
                return 1.0
        else:
            # the lattice's wavevectors are dq = 2 pi / L apart: the line nearest the cutoff
            # is weighted by the fraction of its cell [q - dq/2, q + dq/2] below q_c (1/2 for
            # a line on the cutoff), so that the sum is the midpoint rule of the band-limited
            # integral for any q_c; a sharp |q| <= q_c would jump by one whole line as q_c
            # crosses it (6 % of m4 for a cutoff of L/20 on a self-affine surface)
            dq = 2.0 * math.pi / t.physical_sizes[0]

            def keep(q):
                return np.clip((q_c - np.abs(q)) / dq + 0.5, 0.0, 1.0)
        return [t.integrate_psd_from_profile(lambda q, n=n: np.abs(q) ** n * keep(q),
                                             reliable=False) for n in (0, 2, 4)]

    mx = moments(topography)
    if topography.dim == 2:
        my = moments(topography.transpose())
        m = [(a + b) / 2 for a, b in zip(mx, my)]
        aniso = my[1] / mx[1]
    else:
        m, aniso = mx, 1.0
    return SpectralMoments(float(m[0]), float(m[1]), float(m[2]),
                           nyquist_wavelength(topography) if cutoff is None else float(cutoff),
                           float(aniso))


def mccool(moments):
    """Greenwood-Williamson summit statistics of an isotropic Gaussian surface (McCool 1986,
    from Nayak's theory), in paper 1's notation.

    Parameters
    ----------
    moments : SpectralMoments

    Returns
    -------
    femadh.laws.gw.Summits
        ``density`` rho = eta = m4 / (6 pi sqrt(3) m2) (1/m^2); ``radius`` R_a = beta =
        0.375 sqrt(pi / m4) (m); ``sigma_a`` = sigma_s = sqrt(1 - 0.8968/alpha) sqrt(m0) (m),
        the rms summit height; ``z_m`` = 4 sqrt(m0) / sqrt(pi alpha) (m), the mean summit
        height above the mean plane (paper 1 eqs 23-26). The density is Nayak's exact
        result; radius, rms and mean height are his large-alpha forms (alpha >= 1 always,
        so sigma_s is real).
    """
    m0, m2, m4, a = moments.m0, moments.m2, moments.m4, moments.alpha
    return Summits(sigma_a=math.sqrt(1.0 - VARIANCE_COEFF / a) * math.sqrt(m0),
                   z_m=MEAN_HEIGHT_COEFF * math.sqrt(m0) / math.sqrt(math.pi * a),
                   radius=RADIUS_COEFF * math.sqrt(math.pi / m4),
                   density=DENSITY_COEFF * m4 / m2)
