"""Finite-element half-space: gmsh mesh (:mod:`.mesh`), axisymmetric weak form
(:mod:`.weakform`), far-field data (:mod:`.farfield`), the condensed surface operator
(:mod:`.operator`) and the full fields for inspection (:mod:`.fields`). Needs the ``fe`` extra
(scikit-fem, meshio, gmsh)."""
from .operator import FEOperator, FESettings, mesh_spec

__all__ = ["FEOperator", "FESettings", "mesh_spec"]
