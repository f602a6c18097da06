"""Composite roughness of two surfaces (slider and disk), paper 1 sec 6 and Table 2.

Paper 1 combines the two surfaces' summit statistics as

    sigma_a = (sigma_a1^2 + sigma_a2^2)^(1/2),  z_m = z_m1 + z_m2,  R_a = (1/R_a1 + 1/R_a2)^-1

(0.344 nm, 1.08 nm and 0.94 um for Table 2), and leaves the composite density open ("it is
not easy to evaluate the equivalent asperity density", so Fig 8 varies rho). The standard
composite of two independent rough surfaces (the gap is the sum of two uncorrelated random
fields) adds their spectral moments, m_n = m_n1 + m_n2, and McCool's relations of the sum
give all four numbers, density included. femadh reports both: the Table 2 rule for
sigma_a, z_m and R_a with rho from the summed moments (the paper's rule where it has one),
and the full summed-moment composite beside it.
"""
import math

from ..laws.gw import Summits
from .moments import mccool


def table2_rule(s1, s2, density):
    """Paper 1's composite of two surfaces' summit statistics (sec 6, Table 2).

    Parameters
    ----------
    s1, s2 : Summits
        Each surface's statistics (sigma_a, z_m, radius in m).
    density : float
        The composite summit density rho (1/m^2), which the paper's rule does not fix.

    Returns
    -------
    Summits
        sigma_a = hypot(sigma_a1, sigma_a2), z_m = z_m1 + z_m2, R_a = 1/(1/R_a1 + 1/R_a2).
    """
    return Summits(sigma_a=math.hypot(s1.sigma_a, s2.sigma_a), z_m=s1.z_m + s2.z_m,
                   radius=1.0 / (1.0 / s1.radius + 1.0 / s2.radius), density=density)


def composite(m1, m2):
    """Composite summit statistics of two surfaces from their spectral moments.

    Parameters
    ----------
    m1, m2 : SpectralMoments
        Each surface's moments (at its own cutoff).

    Returns
    -------
    table2 : Summits
        :func:`table2_rule` of the two surfaces' McCool statistics, rho from the summed
        moments.
    spectral : Summits
        McCool's relations of the summed moments m1 + m2.
    moments : SpectralMoments
        The summed moments.
    """
    total = m1 + m2
    spectral = mccool(total)
    return table2_rule(mccool(m1), mccool(m2), spectral.density), spectral, total
