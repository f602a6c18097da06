"""Pressure laws of the local gap h: each a small frozen object with ``pressure(h)`` (Pa,
positive = attractive, pulls the disk surface up), ``dpressure(h)`` (Pa/m) and ``energy(h)``
(J/m^2, zero at infinite gap, with pressure = d energy / dh). :func:`check_law` verifies the
three belong together. The contact problem sums only the laws a scene names.

- :mod:`.lj` - mean-plane Lennard-Jones, paper 1 eq (3)
- :mod:`.lj82` - the Adhesion package's Lj82 law (by work of adhesion; the peer benchmark)
- :mod:`.capillary` - condensate-filled gap (paper 2 physics in a paper 1 scene)
- :mod:`.asperity` - eq (20) asperity adhesion as a smoothed step above sigma
- :mod:`.gw` - Greenwood-Williamson elastic and adhesive asperity pressures (eqs 23-24)
- :mod:`.step` - the smoothed step the capillary and eq 20 laws share
"""
from .asperity import AsperityAdhesion, eq20_pressure
from .capillary import CapillaryCondensate
from .check import check_law
from .gw import GWAdhesion, GWElastic, Summits, gw_integral
from .lj import LennardJones
from .lj82 import Lj82

__all__ = ["LennardJones", "Lj82", "CapillaryCondensate", "AsperityAdhesion", "eq20_pressure",
           "GWElastic", "GWAdhesion", "Summits", "gw_integral", "check_law"]
