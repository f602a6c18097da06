"""The nonlinear surface problem: gap laws + the sigma-gap constraint + an elastic surface
operator, its solvers and continuation.

- :mod:`.problem` - ContactProblem (operator, sphere, laws, constraint), energy and Hessian
- :mod:`.constraints` - the sigma-gap (eq 8) and its contact models
- :mod:`.complementarity` - semismooth Newton for h >= sigma, p_c >= 0, p_c (h - sigma) = 0
- :mod:`.closure` - the paper's Hertz closure (eq 9), contact radius a continuous unknown
- :mod:`.stability` - the energy Hessian's inertia
- :mod:`.stepping`, :mod:`.landing` - continuation in d with folds and landings
- :mod:`.arclength`, :mod:`.curve` - pseudo-arclength continuation through folds, paths
- :mod:`.sigma_arclength` - the same for the sigma-gap: pieces of fixed active set, events
- :mod:`.forces` - force integration (paper 1 eqs 11-13 with area weights)
"""
from .constraints import AsperityGap, CONTACT_MODELS
from .problem import ContactProblem
from .solve import solve_state, trace
from .state import State
from .stepping import Jump, Sweep

__all__ = ["AsperityGap", "CONTACT_MODELS", "ContactProblem", "State", "solve_state", "trace",
           "Jump", "Sweep"]
