"""Surface operators of the elastic half-space: w = C p on a radial node set.

A SurfaceOperator has a ``grid`` (:class:`RadialGrid`), a ``compliance`` matrix C (m/Pa:
nodal displacement per unit pressure on each annulus) and a ``stiffness`` K = C^-1 (Pa/m).
The Green-function operator and the finite-element operator share this interface so that
their solutions are comparable like-for-like.
"""
from .grid import RadialGrid
from .green import GreenOperator, disk_displacement

__all__ = ["RadialGrid", "GreenOperator", "disk_displacement"]
