"""Finite-element half-space, homogeneous or layered: gmsh mesh with named boundaries
(:mod:`.mesh`, layered bands in :mod:`.layered_mesh`), layers and their through-thickness
grading (:mod:`.layers`), the settings and mesh rules (:mod:`.settings`), the body
(:mod:`.body`), axisymmetric weak form and surface load (:mod:`.weakform`), far-field data
(:mod:`.farfield`), the condensed surface operator (:mod:`.operator`: ``FEOperator.homogeneous``,
``FEOperator.layered``), its on-disk cache (:mod:`.cache`) and the full fields for inspection
(:mod:`.fields`). Needs the ``fe`` extra (scikit-fem, meshio, gmsh)."""
from .body import FEBody
from .layers import Layer
from .operator import FEOperator
from .settings import FESettings, mesh_spec

__all__ = ["FEBody", "FEOperator", "FESettings", "Layer", "mesh_spec"]
