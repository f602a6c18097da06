"""Greenwood-Williamson asperity pressures as laws of the mean-plane gap (paper 1 eqs 23-24).

Summit heights are Gaussian (eq 26 with its normalisation corrected: 1/(sqrt(2 pi) sigma_a),
not the printed 1/sqrt(2 pi sigma_a)). With t = (h - z_m)/sigma_a the GW integrals reduce to

    I_n(t) = int_t^inf (s - t)^n phi*(s) ds = Gamma(n+1) exp(-t^2/4) D_{-n-1}(t) / sqrt(2 pi)

(phi* the standard normal density, D_v the parabolic cylinder function: scipy.special.pbdv),
so the elastic asperity pressure of eq 23 and the adhesive one of eqs 20/24 are closed-form,
smooth laws of the gap: the continuous alternative to the hard sigma-gap (beyond the paper).
Their independent judge is ``femadh.reference.gw`` (the same equations by quadrature).
"""
from dataclasses import dataclass
import math

import numpy as np
from scipy import special

from ..schema import Key, Table


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


@dataclass(frozen=True)
class Summits:
    """Composite summit statistics of two rough surfaces (paper 1 sec 6, Table 2).

    Attributes
    ----------
    sigma_a : float
        rms summit height (m).
    z_m : float
        Mean summit height above the mean plane (m).
    radius : float
        R_a, mean summit radius (m).
    density : float
        rho, summits per area (1/m^2).
    """

    sigma_a: float
    z_m: float
    radius: float
    density: float



def _t(summits, h):
    """Gap h (m) in units of the summit height distribution, (h - z_m)/sigma_a. Any object
    with the four attributes of :class:`Summits` serves (e.g. the reference's statistics)."""
    return (np.asarray(h, float) - summits.z_m) / summits.sigma_a


@dataclass(frozen=True)
class GWElastic:
    """Repulsive asperity pressure -P_ela(h) (attractive-positive convention), eq 23:
    P_ela = 4/3 E* rho sqrt(R_a) sigma_a^(3/2) I_3/2(t)."""

    summits: Summits
    e_star: float

    @property
    def _c(self):
        s = self.summits
        return 4.0 / 3.0 * self.e_star * s.density * math.sqrt(s.radius)

    def pressure(self, h):
        s = self.summits
        return -self._c * s.sigma_a**1.5 * gw_integral(1.5, _t(s, h))

    def dpressure(self, h):
        s = self.summits
        return self._c * 1.5 * s.sigma_a**0.5 * gw_integral(0.5, _t(s, h))

    def energy(self, h):
        s = self.summits
        return self._c * 0.4 * s.sigma_a**2.5 * gw_integral(2.5, _t(s, h))


@dataclass(frozen=True)
class GWAdhesion:
    """Adhesive asperity pressure P_LJa(h) = 2 pi R_a dg rho p(h), eqs 20 and 24, with the
    fraction of summits in contact p(h) = I_0(t)."""

    summits: Summits
    surface_energy: float

    @property
    def _c(self):
        s = self.summits
        return 2 * math.pi * s.radius * self.surface_energy * s.density

    def pressure(self, h):
        return self._c * gw_integral(0.0, _t(self.summits, h))

    def dpressure(self, h):
        s = self.summits
        t = _t(s, h)
        return -self._c * np.exp(-t * t / 2) / (math.sqrt(2 * math.pi) * s.sigma_a)

    def energy(self, h):
        s = self.summits
        return -self._c * s.sigma_a * gw_integral(1.0, _t(s, h))


def _build(values, ctx):
    from .registration import Built

    s = Summits(values["rms_height"], values["mean_height"], values["asperity_radius"],
                values["density"])
    laws = {"asperity_elastic": GWElastic(s, ctx.e_star)}
    if values["surface_energy"] > 0:
        laws["asperity_adhesion"] = GWAdhesion(s, values["surface_energy"])
    return Built(laws)


def _topography_files(reader, raw, path):
    """``topography``: one file, or [slider, disk] for paper 1's composite (Table 2)."""
    files = [raw] if isinstance(raw, str) else raw
    if (not isinstance(files, list) or not 1 <= len(files) <= 2
            or not all(isinstance(f, str) and f for f in files)):
        return reader.fail(path, raw, "a topography file name, or a list of two (slider, "
                           "disk) for the composite")
    return tuple(files)


#: the keys by which an asperity section takes its summit numbers from measured surfaces
#: (femadh.scene.topography resolves them)
TOPOGRAPHY_KEYS = (
    Key("topography", "custom", "A measured surface (path relative to the scene file; needs "
        "the 'data' extra), or [slider, disk] for paper 1's Table 2 composite, whose McCool "
        "statistics replace the summit numbers (femadh topography FILE shows them).",
        default=None, parse=lambda r, raw, path: None if raw is None else
        _topography_files(r, raw, path),
        expect="a topography file name, or a list of two (slider, disk)"),
    Key("topography_cutoff", "length", "Short-wavelength cutoff of the topography's "
        "spectral moments (default: the pixel scale).", default=None, lo=0.0),
)


def _registration():
    from .registration import Output, Registration

    table = Table("effects.asperity_contact", "Greenwood-Williamson asperity pressures "
                  "(eqs 23-24) as smooth laws of the mean-plane gap, instead of the hard "
                  "sigma-gap.", (
        Key("model", "choice", "The asperity model.", choices=("greenwood-williamson",)),
        Key("rms_height", "length", "rms summit height sigma_a (Table 2 composite: "
            "0.344 nm).", lo=0.0),
        Key("mean_height", "length", "Mean summit height z_m above the mean plane (1.08 nm)."),
        Key("asperity_radius", "length", "Summit radius R_a (0.94 um).", lo=0.0),
        Key("density", "areal_density", "Summit density rho.", lo=0.0),
        Key("surface_energy", "surface_energy", "Surface energy of a summit contact (eq 24); "
            "0 for no asperity adhesion.", default=0.0, lo=0.0, lo_closed=True),
    ) + TOPOGRAPHY_KEYS)
    return Registration(table, _build, (
        Output("asperity_elastic", "F_ela_N", "P_ela_Pa", -1.0, "asperity elasticity (eq 23)"),
        Output("asperity_adhesion", "F_LJa_N", "P_LJa_Pa", 1.0, "asperity adhesion (eq 24)")))


REGISTRATION = _registration()
