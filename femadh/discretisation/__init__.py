"""Where the nodes go: grid families that follow the contact, and the error-steered choice of
their resolution.

Every Green-path contact solve asks this package for its nodes (unless the scene fixes
``[solver] nodes``, the uniform override). A family is one spacing function scaled by one
parameter (the spacing h in the band that holds the features), so its members are refinements
of one mesh density: the coarser members of an error estimate have the same band relative to
the features as the fine one (never lattice-trapped by a coarser edge resolution), and
Richardson extrapolation applies (:mod:`femadh.discretisation.family`). Which band, which
analysis radius and which h a scene needs is planned from its laws and sweep and then steered
by the a-posteriori estimate (:mod:`femadh.discretisation.plan`).
"""
from .family import GridFamily
from .plan import (GridPlan, band_radius, feature_gap, plan_grid, tail_delta,
                   trapping_spacing)

__all__ = ["GridFamily", "GridPlan", "band_radius", "feature_gap", "plan_grid", "tail_delta",
           "trapping_spacing"]
