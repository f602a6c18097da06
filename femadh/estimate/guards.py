"""Guards: a state or a result the grid does not resolve is refused, never reported converged.

- **lattice trapping**: a node whose surface-force softening -P'(h_k) exceeds its own
  stiffness K_kk can snap on its own; the answer then depends on the mesh (a trigger for
  refinement where femadh chooses the grid);
- **the analysis radius**: a contact reaching it does not fit the analysed disk;
- **proven bounds**: a result outside what is proven for it (e.g. the load-controlled
  pull-off of a paraboloid above Derjaguin-Bradley's 2 pi R W) by more than its estimated
  error.
"""
import math

from ..errors import FemadhError

#: a node whose softening exceeds this multiple of its own stiffness snaps alone
TRAPPING_LIMIT = 1.0
#: the contact may reach this fraction of the analysis radius
EDGE_FRACTION = 0.9


class GuardError(FemadhError):
    """A state or result outside the model's validity: names the quantity, its value and the
    setting to change."""


class TrappingError(GuardError):
    """Lattice trapping: a node's softening beyond its own stiffness (``ratio``); a trigger
    for refinement where femadh chooses the grid."""

    def __init__(self, msg, ratio):
        super().__init__(msg)
        self.ratio = ratio


def trapping_message(ratio, limit=TRAPPING_LIMIT):
    """The words for a node softening ratio -P'(h)/K_kk above ``limit`` (None at or below)."""
    if not ratio > limit:
        return None
    return (f"a node's surface-force softening -P'(h)/K_kk = {ratio:.2f} > {limit:g}: single "
            "nodes snap on their own (lattice trapping)")


def outside_bounds(value, error, lower=-math.inf, upper=math.inf, rel=1e-9):
    """True if ``value`` lies outside [lower, upper] by more than its estimated ``error``
    (and a relative round-off margin ``rel`` of the bound)."""
    return (value + error < lower * (1 - math.copysign(rel, lower))
            or value - error > upper * (1 + math.copysign(rel, upper)))


def check_state(problem, state, scene=None):
    """Refuse a state whose contact reaches the analysis radius (GuardError) or whose nodes
    snap alone (TrappingError, with the setting to change)."""
    a = problem.grid.radius
    if state.r_c > EDGE_FRACTION * a or (state.active.size and state.active[-1]):
        raise GuardError(
            f"the contact reaches the analysis radius at d = {state.d * 1e9:.4g} nm (r_c = "
            f"{state.r_c * 1e6:.4g} um of a = {a * 1e6:.4g} um): the sphere's load does not "
            "fit the analysed disk; grow [solver] analysis_radius (e.g. delta) or stop the "
            "sweep earlier")
    ratio = problem.node_softening_ratio(state.h)
    why = trapping_message(ratio)
    if why:
        raise TrappingError(f"at d = {state.d * 1e9:.4g} nm {why} and the result depends on "
                            f"the mesh; {_finer_advice(problem, ratio)}", ratio=ratio)


def _finer_advice(problem, ratio):
    """What to change for a grid whose band nodes snap alone at this softening ratio."""
    g = problem.grid
    if g.fine_radius is None:
        return f"use [solver] nodes >= {int(math.ceil(g.n * ratio / 0.5))}"
    return (f"use [solver.grid] spacing <= {float(g.nodes[1]) * 0.5 / ratio:.3g} m "
            "(or leave the grid to femadh)")
