"""Surface effects: pressure laws of the local gap h (positive = attractive, pulls the disk up).

Each effect is a small frozen object with ``pressure(h)``, ``dpressure(h)`` (its derivative
with respect to the gap) and ``energy(h)`` (interaction energy per area, zero at infinite gap,
with ``pressure = d energy / dh``). The solver sums only the effects a scene names.
"""
from .lj import LennardJones
from .gap import AsperityGap
from .capillary import CapillaryCondensate
from .asperity import AsperityAdhesion, GWAdhesion, GWElastic

__all__ = ["LennardJones", "AsperityGap", "CapillaryCondensate", "AsperityAdhesion",
           "GWAdhesion", "GWElastic"]
