"""The error machinery: one home for the runner and the regime map.

- :mod:`~femadh.estimate.richardson`: the discretisation error of a number from the coarser
  members of its grid family (Richardson extrapolation at an assumed or observed order, the
  envelope where the members oscillate);
- :mod:`~femadh.estimate.guards`: the a-posteriori guards that refuse a state or a result the
  grid does not resolve (lattice trapping, a contact at the analysis radius, a result outside
  its proven bounds);
- :mod:`~femadh.estimate.refine`: the refine-until-met loop, its budget (refinements, nodes)
  an explicit setting.

The contact runner (:mod:`femadh.runner.estimates`, :mod:`femadh.runner.accuracy`) and the
regime map (:mod:`femadh.studies.regime`) both use it; what differs between them (the
quantities, the family's order, how a grid is refined) is passed in.
"""
from .guards import (EDGE_FRACTION, FAILURE_KINDS, SMOOTH_EDGE_FRACTION, TRAPPING_LIMIT,
                     AnalysisRadiusError, BoundError, GuardError, TrappingError, check_state,
                     failure_kind, outside_bounds, trapping_message)
from .refine import (BANDED_MAX_NODES, CONTINUATION_MAX_NODES, UNIFORM_MAX_NODES, Budget,
                     Outcome, refine_until_met, worst_relative)
from .richardson import (DECAY_ORDER, ENVELOPE_ORDER, MAX_ORDER, ORDER, discretisation,
                         observed_order, richardson)

__all__ = ["AnalysisRadiusError", "BANDED_MAX_NODES", "BoundError", "Budget",
           "check_state", "CONTINUATION_MAX_NODES", "DECAY_ORDER", "discretisation",
           "EDGE_FRACTION", "ENVELOPE_ORDER", "failure_kind", "FAILURE_KINDS", "GuardError",
           "MAX_ORDER",
           "observed_order", "ORDER", "Outcome", "outside_bounds", "refine_until_met",
           "richardson", "SMOOTH_EDGE_FRACTION", "TRAPPING_LIMIT", "trapping_message",
           "TrappingError", "UNIFORM_MAX_NODES", "worst_relative"]
