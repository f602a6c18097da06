"""Lennard-Jones surface pressure between mean planes, paper 1 eq (3)."""
from dataclasses import dataclass
import math

import numpy as np

from ..schema import Key, Table


#: floating-point events that are the law's own value at h -> 0+, not an error: below
#: h ~ 1e-61 m (z0/h)^6 overflows, below ~1e-108 m h^3 underflows to 0 (and at h = 0 the
#: division is by 0), so P = -inf, dP/dh = +inf, U = +inf: the exact values beyond the double
#: range (infinite repulsion at contact). A failed contact solve evaluates its last iterate's
#: laws at gaps clamped to 1e-300 m (femadh.contact.complementarity) and meets these.
#: "invalid" (a NaN made here, e.g. inf - inf) is not silenced: it stays an error where it
#: appears; no gap h >= 0 makes one (tests/test_lj_limits.py).
AT_CONTACT = {"over": "ignore", "divide": "ignore", "under": "ignore"}


@dataclass(frozen=True)
class LennardJones:
    """LJ pressure P(h) = A/(6 pi h^3) [1 - (z0/h)^6] (Pa), positive = attractive (eq 3).

    Attributes
    ----------
    hamaker : float
        Hamaker constant A (J).
    z0 : float
        Atomic equilibrium distance z0 (m); P(z0) = 0.
    """

    hamaker: float
    z0: float

    def pressure(self, h):
        """Attractive pressure (Pa) at gap h (m), eq (3); -inf as h -> 0+ (see
        :data:`AT_CONTACT`)."""
        h = np.asarray(h, dtype=float)
        with np.errstate(**AT_CONTACT):
            s = (self.z0 / h) ** 6
            return self.hamaker / (6.0 * math.pi * h**3) * (1.0 - s)

    def dpressure(self, h):
        """dP/dh (Pa/m): -A/(2 pi h^4) [1 - 3 (z0/h)^6]; +inf as h -> 0+."""
        h = np.asarray(h, dtype=float)
        with np.errstate(**AT_CONTACT):
            s = (self.z0 / h) ** 6
            return -self.hamaker / (2.0 * math.pi * h**4) * (1.0 - 3.0 * s)

    def energy(self, h):
        """Interaction energy per area (J/m^2), zero at h -> inf; dU/dh = P.

        U(h) = -A/(12 pi h^2) [1 - (z0/h)^6 / 4]; U(z0) = -A/(16 pi z0^2) = -Delta gamma (eq 19).
        """
        h = np.asarray(h, dtype=float)
        with np.errstate(**AT_CONTACT):
            s = (self.z0 / h) ** 6
            return -self.hamaker / (12.0 * math.pi * h**2) * (1.0 - 0.25 * s)

    @property
    def peak_gap(self):
        """Gap (m) of the maximum attractive pressure, 3^(1/6) z0 (paper 1 sec 5.1)."""
        return 3.0 ** (1.0 / 6.0) * self.z0

    @property
    def work_of_adhesion(self):
        """Delta gamma = -U(z0) = A/(16 pi z0^2) (J/m^2), eq (19)."""
        return self.hamaker / (16.0 * math.pi * self.z0**2)


def _build(values, ctx):
    from .registration import Built

    return Built({"lj": LennardJones(values["hamaker"], values["equilibrium_distance"])})


def _registration():
    from .registration import Output, Registration

    table = Table("effects.lennard_jones", "Mean-plane Lennard-Jones pressure, paper 1 eq (3).", (
        Key("hamaker", "energy", "Hamaker constant A (paper 1 Table 1: 1e-19 J).", lo=0.0),
        Key("equilibrium_distance", "length", "Atomic equilibrium distance z0, where the LJ "
            "pressure vanishes (Table 1: 0.165 nm).", lo=0.0),
    ))
    return Registration(table, _build, (Output("lj", "F_LJ_N", "P_LJ_Pa", 1.0,
                                               "Lennard-Jones"),))


REGISTRATION = _registration()
