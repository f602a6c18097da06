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

from ..schema import Key, Table
from .gw import TOPOGRAPHY_KEYS
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


def _build(values, ctx):
    """Eq 20 on the sigma-gap contact set: exactly (range-less, carried by the constraint:
    a contact node holds tension up to P_LJa), or as the smoothed step law."""
    from .registration import Built

    p = eq20_pressure(values["asperity_radius"], values["surface_energy"], values["density"],
                      values["contact_probability"])
    if values["model"] == "contact-set":
        return Built({}, gap_adhesion=p)
    return Built({"asperity_adhesion": AsperityAdhesion(p, ctx.sigma,
                                                        values["smoothing"] * ctx.sigma)})


def _registration():
    from .registration import Output, Registration

    table = Table("effects.asperity_adhesion", "Asperity adhesion over the sigma-gap contact "
                  "region, paper 1 eq (20): P_LJa = 2 pi R_a dg rho p.", (
        Key("asperity_radius", "length", "Summit radius R_a (paper 1 sec 6: 0.94 um).",
            lo=0.0),
        Key("surface_energy", "surface_energy", "Surface energy dg of a summit contact "
            "(sec 6: 0.06 J/m^2).", lo=0.0),
        Key("density", "areal_density", "Summit density rho (Fig 8: 0, 100, 179 um^-2).",
            lo=0.0, lo_closed=True),
        Key("contact_probability", "number", "Fraction p of summits in contact (eq 20; sec 6: "
            "0.5).", default=0.5, lo=0.0, hi=1.0, lo_closed=True, hi_closed=True),
        Key("model", "choice", "'contact-set': P_LJa acts exactly on the contact set (a node "
            "holds tension up to P_LJa before it releases; the limit of the smoothed law); "
            "'smoothed': a logistic step of width smoothing x sigma above sigma.",
            default="contact-set", choices=("contact-set", "smoothed")),
        Key("smoothing", "number", "Step width as a fraction of sigma (model = 'smoothed').",
            default=0.02, lo=0.0, hi=0.2, hi_closed=True),
    ) + TOPOGRAPHY_KEYS)
    return Registration(table, _build, (Output("asperity_adhesion", "F_LJa_N", "P_LJa_Pa", 1.0,
                                               "asperity adhesion (eq 20)"),))


REGISTRATION = _registration()
