"""Finite-element half-space, homogeneous or layered: gmsh mesh (:mod:`.mesh`, layered bands in
:mod:`.layered_mesh`), layers and their through-thickness grading (:mod:`.layers`),
axisymmetric weak form (:mod:`.weakform`), far-field data (:mod:`.farfield`), the condensed
surface operator (:mod:`.operator`) and the full fields for inspection (:mod:`.fields`). Needs
the ``fe`` extra (scikit-fem, meshio, gmsh)."""
from .layers import Layer
from .operator import FEOperator, FESettings, mesh_spec

__all__ = ["FEOperator", "FESettings", "Layer", "mesh_spec"]
