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

On the Green path the contact problem integrates this law over the gap field between the nodes
(``SUBGRID``; :mod:`femadh.contact.subgrid`): the edge is ~w / |dh/dr| wide in r, far narrower
than a node's annulus where the gap is shallow, and collocated it snaps node by node.

At low humidity the edge sits just above the sigma-gap floor: the condensate then acts only
over the first h_fill - sigma of opening at the contact edge, a Dugdale cohesive zone of
stress gamma/|r_K| about (pi/4) E* (h_fill - sigma) |r_K| / gamma long (~34 nm for ethanol at
p/psat = 0.15 on sigma = 0.489 nm and the 2-mm slider's E*). A band spacing comparable to it
unzips the contact node by node on the retract (the stiction map's low-humidity points); the
grid planner resolves it through the step's secant softening from the floor
(:meth:`~femadh.laws.step.SmoothStepLaw.edge_softening`,
:func:`femadh.discretisation.plan.trapping_ratio`).
"""
from dataclasses import dataclass

from ..schema import Key, Table
from .step import SmoothStepLaw


@dataclass(frozen=True)
class CapillaryCondensate(SmoothStepLaw):
    """Attributes: surface_tension gamma (N/m), kelvin_radius r_K (m, < 0), film t (m),
    width w (m) of the smoothed meniscus edge."""

    SUBGRID = True

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


def _build(values, ctx):
    """The law from a liquid, p/psat, temperature and isotherm (the built-in liquid's
    representative isotherm unless one is given; ``model = "none"`` for bare solids)."""
    from ..meniscus.isotherms import default_isotherm
    from ..meniscus.kelvin import kelvin_radius
    from ..meniscus.liquids import LIQUIDS
    from .registration import Built

    liquid, x = values["liquid"], values["relative_pressure"]
    iso = values["isotherm"]
    if iso == "default":
        iso = default_isotherm(liquid.name) if liquid.name in LIQUIDS else None
    r_k = kelvin_radius(liquid, x, values["temperature"])
    film = 0.0 if iso is None else float(iso(x))
    fill = 2 * abs(r_k) + 2 * film
    return Built({"capillary": CapillaryCondensate(liquid.surface_tension, r_k, film,
                                                   values["smoothing"] * fill)})


def _registration():
    from .registration import Output, Registration

    table = Table("effects.capillary", "Capillary condensate filling the gap where a meniscus "
                  "of Kelvin curvature spans it (paper 2 physics in a contact scene).", (
        Key("liquid", "liquid", "A built-in liquid (water, ethanol, n-butanol, n-pentanol) or "
            "a table { name, surface_tension, molar_volume }."),
        Key("relative_pressure", "number", "Vapour pressure p/psat (paper 2 eq 6).", lo=0.0,
            hi=1.0),
        Key("temperature", "temperature", "Temperature (Kelvin equation).",
            default="298.15 K", lo=0.0),
        Key("isotherm", "isotherm", "Adsorption isotherm of the film on both surfaces: "
            "{ model = gab | bet | polynomial | tabulated | none, ... }; default: the "
            "built-in liquid's representative GAB isotherm.", default="default"),
        Key("smoothing", "number", "Width of the smoothed meniscus edge as a fraction of the "
            "filled gap 2|r_K| + 2h.", default=0.02, lo=0.0, hi=0.5, hi_closed=True),
    ))
    return Registration(table, _build, (Output("capillary", "F_cap_N", "P_cap_Pa", 1.0,
                                               "capillary"),))


REGISTRATION = _registration()
