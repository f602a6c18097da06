"""The Lj82 interaction of the Adhesion package (Pastewka, Sanner et al.) as a gap law.

Adhesion's ``Adhesion.Interactions.Lj82(w, z0)`` (file ``Adhesion/Interactions/VdW82.py`` of
github.com/ContactEngineering/Adhesion) is its ``VDW82`` potential with
c_sr = w z0^8 / 3 and Hamaker constant A = 16 pi w z0^2:

    V(h) = -A / (12 pi h^2) + c_sr / h^8 = w [ -(4/3) (z0/h)^2 + (1/3) (z0/h)^8 ],

an energy per area with its minimum V(z0) = -w at h = z0. Here it is written in femadh's
convention: ``energy`` = V, ``pressure`` = dV/dh (positive = attractive), so

    P(h) = (8 w / (3 z0)) [ (z0/h)^3 - (z0/h)^9 ],
    P'(h) = (8 w / (3 z0^2)) [ 9 (z0/h)^10 - 3 (z0/h)^4 ].

It is the same 9-3 pressure as paper 1's eq (3) with A = 16 pi w z0^2 (eq 19): the peer's law
parametrised by its work of adhesion instead of its Hamaker constant.
"""
from dataclasses import dataclass
import math

import numpy as np


@dataclass(frozen=True)
class Lj82:
    """Lj82 gap law (energy 8-2, pressure 9-3).

    Attributes
    ----------
    work_of_adhesion : float
        w = -V(z0) (J/m^2).
    z0 : float
        Equilibrium gap (m): P(z0) = 0.
    """

    work_of_adhesion: float
    z0: float

    def pressure(self, h):
        """Attractive pressure dV/dh (Pa) at gap h (m)."""
        x = self.z0 / np.asarray(h, dtype=float)
        return 8.0 * self.work_of_adhesion / (3.0 * self.z0) * (x**3 - x**9)

    def dpressure(self, h):
        """dP/dh (Pa/m)."""
        x = self.z0 / np.asarray(h, dtype=float)
        return 8.0 * self.work_of_adhesion / (3.0 * self.z0**2) * (9.0 * x**10 - 3.0 * x**4)

    def energy(self, h):
        """V(h) (J/m^2), zero at infinite gap, -w at h = z0."""
        x = self.z0 / np.asarray(h, dtype=float)
        return self.work_of_adhesion * (x**8 / 3.0 - 4.0 * x**2 / 3.0)

    @property
    def hamaker(self):
        """Hamaker constant A = 16 pi w z0^2 (J) of its attractive term."""
        return 16.0 * math.pi * self.work_of_adhesion * self.z0**2
