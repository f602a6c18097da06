"""Where a measured spectrum stops being the surface's: the short-wavelength end of the power
spectral density, where the instrument (tip radius, pixel size, noise, filters) shows.

Criterion (stated, simple): fit a power law C ~ q^s by least squares in log-log over the two
octaves q in [q_N / 16, q_N / 4] below the tail (q_N = pi / pixel the Nyquist wavevector;
a lower start would reach into the long-wavelength roll-off most surfaces have) and compare
the measured PSD over the top octave [q_N / 2, q_N] with the power law extrapolated there.
If the geometric mean of measured / extrapolated over that octave is above 2, the tail
*flattens* (a noise floor, or pixel-level artefacts: m2 and m4 at the pixel scale are then
inflated); below 1/2, it *drops steeply* (the tip radius or a filter smooths the data: m4
at the pixel scale is the instrument's, not the surface's). Either way
the pixel-scale moments, above all m4, are not the surface's, and a cutoff (``--cutoff``)
above the deviation gives moments that are. For a map the radially averaged 2D PSD is used
(its tail is the isotropic spectrum up to q_N); for a line scan the profile PSD.
"""
from dataclasses import dataclass
import math

import numpy as np

#: the tail is judged over the top octave below Nyquist, against a fit over [q_N / 16, q_N / 4]
MID_LOW, MID_HIGH, TAIL_LOW = 1.0 / 16, 0.25, 0.5
#: geometric-mean ratio of the tail to the extrapolated power law beyond which it is flagged
TAIL_FACTOR = 2.0
#: a power-law fit needs this many PSD points in the mid range
MIN_POINTS = 4


@dataclass(frozen=True)
class TailCheck:
    """Result of the tail criterion.

    Attributes
    ----------
    slope : float
        Power-law exponent s of C(q) ~ q^s over the mid range (nan if not judged).
    ratio : float
        Geometric mean of measured / extrapolated PSD over the top octave (nan if not judged).
    verdict : str
        'power law', 'flattens', 'drops steeply' or 'not judged'.
    """

    slope: float
    ratio: float
    verdict: str

    def warning(self, name):
        """A one-line warning for ``name`` (None when the tail follows the power law)."""
        if self.verdict == "power law":
            return None
        if self.verdict == "not judged":
            return (f"{name}: too few spectrum points to judge its short-wavelength end "
                    "(the pixel-scale m2, m4 are unchecked)")
        cause = ("a noise floor or pixel-level artefacts" if self.verdict == "flattens"
                 else "the tip radius or a filter")
        return (f"{name}: the PSD {self.verdict} over the top octave below the pixel (Nyquist) "
                f"wavelength ({self.ratio:.2g} x the mid-range power law q^{self.slope:.2f}): "
                f"{cause} shows there; the pixel-scale m2 and m4 are the instrument's, give "
                "--cutoff above it")


def tail_check(topography):
    """Judge the short-wavelength end of a topography's PSD (see the module docstring).

    Parameters
    ----------
    topography : SurfaceTopography Topography or UniformLineScan
        Heights in m.

    Returns
    -------
    TailCheck
    """
    if topography.dim == 2:
        q, c = topography.power_spectrum_from_area(reliable=False)
    else:
        q, c = topography.power_spectrum_from_profile(reliable=False)
    q, c = np.ma.filled(np.ma.asarray(q, float), np.nan), np.ma.filled(np.ma.asarray(c, float),
                                                                       np.nan)
    pixel = max(s / n for s, n in zip(topography.physical_sizes, topography.nb_grid_pts))
    q_n = math.pi / pixel
    ok = np.isfinite(q) & np.isfinite(c) & (c > 0)
    mid = ok & (q >= MID_LOW * q_n) & (q <= MID_HIGH * q_n)
    tail = ok & (q >= TAIL_LOW * q_n) & (q <= q_n)
    if mid.sum() < MIN_POINTS or tail.sum() < 1:
        return TailCheck(math.nan, math.nan, "not judged")
    slope, icpt = np.polyfit(np.log(q[mid]), np.log(c[mid]), 1)
    ratio = float(np.exp(np.mean(np.log(c[tail]) - (icpt + slope * np.log(q[tail])))))
    verdict = ("flattens" if ratio > TAIL_FACTOR else "drops steeply"
               if ratio < 1.0 / TAIL_FACTOR else "power law")
    return TailCheck(float(slope), ratio, verdict)
