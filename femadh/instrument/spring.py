"""The instrument's spring: an AFM cantilever as calibrated, or a beam from its geometry.

The drive is the spring's base position z (the piezo); the sphere hangs at separation d. The
spring carries k (z - d), which at equilibrium balances the contact's external force F_ex
(femadh's sign: tension, adhesion, positive), so z = d + F_ex / k.
"""
from dataclasses import dataclass


def cantilever_stiffness(length, width, thickness, youngs_modulus):
    """End-loaded rectangular cantilever (clamped-free, Euler-Bernoulli): k = 3 E I / L^3 with
    I = w t^3 / 12, i.e. k = E w t^3 / (4 L^3) (N/m). Lengths in m, E in Pa."""
    return youngs_modulus * width * thickness**3 / (4.0 * length**3)


def bridge_stiffness(length, width, thickness, youngs_modulus):
    """Fixed-fixed rectangular bridge loaded at its middle (Euler-Bernoulli, no axial
    stress): k = 192 E I / L^3 with I = w t^3 / 12, i.e. k = 16 E w t^3 / L^3 (N/m)."""
    return 16.0 * youngs_modulus * width * thickness**3 / length**3


BEAMS = {"cantilever": cantilever_stiffness, "bridge": bridge_stiffness}


@dataclass(frozen=True)
class Spring:
    """The instrument in series with the contact.

    Attributes
    ----------
    stiffness : float
        k (N/m).
    kind : str
        "stiffness" (given as calibrated), "cantilever" or "bridge" (from the geometry).
    geometry : dict or None
        The beam's length, width, thickness (m) and youngs_modulus (Pa).
    rest_gap : float or None
        Where the suspension holds the part at rest (m, the base position z at rest): a MEMS
        part stuck to the flat frees itself iff the instrument lets go (jumps out or peels
        off) before z comes back to it (:func:`femadh.runner.instrument.mems_verdict`).
    """

    stiffness: float
    kind: str = "stiffness"
    geometry: dict | None = None
    rest_gap: float | None = None

    @classmethod
    def beam(cls, kind, length, width, thickness, youngs_modulus):
        k = BEAMS[kind](length, width, thickness, youngs_modulus)
        return cls(k, kind, {"length_m": length, "width_m": width, "thickness_m": thickness,
                             "youngs_modulus_Pa": youngs_modulus})

    def at_rest_gap(self, gap):
        """The same spring with its rest position (the base at rest) at separation ``gap``."""
        return Spring(self.stiffness, self.kind, self.geometry, gap)

    def as_dict(self):
        return {"stiffness_N_per_m": self.stiffness, "kind": self.kind,
                "geometry": self.geometry, "rest_gap_m": self.rest_gap}
