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
from .guards import (EDGE_FRACTION, TRAPPING_LIMIT, GuardError, TrappingError, check_state,
                     outside_bounds, trapping_message)
from .refine import Budget, Outcome, refine_until_met, worst_relative
from .richardson import (ENVELOPE_ORDER, MAX_ORDER, ORDER, discretisation, observed_order,
                         richardson)

__all__ = ["Budget", "EDGE_FRACTION", "ENVELOPE_ORDER", "GuardError", "MAX_ORDER", "ORDER",
           "Outcome", "TRAPPING_LIMIT", "TrappingError", "check_state", "discretisation",
           "observed_order", "outside_bounds", "refine_until_met", "richardson",
           "trapping_message", "worst_relative"]
