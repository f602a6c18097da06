"""Guards: a state or a result the grid does not resolve is refused, never reported converged.

- **lattice trapping**: a node whose surface-force softening -P'(h_k) exceeds its own
  stiffness K_kk can snap on its own; the answer then depends on the mesh (a trigger for
  refinement where femadh chooses the grid);
- **the analysis radius**: a contact reaching it does not fit the analysed disk;
- **proven bounds**: a result outside what is proven for it (e.g. the load-controlled
  pull-off of a paraboloid above Derjaguin-Bradley's 2 pi R W) by more than its estimated
  error.

Each guard raises its own type, and :func:`failure_kind` names the kind of any run's failure
(``result.failure_kind``): the refine loops (:mod:`femadh.runner.adaptive`,
:mod:`femadh.runner.accuracy`) choose a refinement by that kind, never by the words of a
message.
"""
import math

from ..errors import ConvergenceError, FemadhError, Interrupted, TimeLimitReached

#: a node whose softening exceeds this multiple of its own stiffness snaps alone
TRAPPING_LIMIT = 1.0
#: the contact (sigma-gap: nodes at the floor, r_c) may reach this fraction of the analysis
#: radius: beyond the contact the cohesive zone (sigma .. 10^(1/2) sigma for LJ) must still
#: fit inside the disk, whose force beyond a is taken on the undeformed contour (F_tail).
#: A guard, not a tuned value: the bundled scenes reach at most 0.59 (measured, Fig 4
#: coated and Fig 3 FE on the paper's 10-nm disk), the adaptive grid's disks 0.15-0.26
EDGE_FRACTION = 0.9
#: the same for a smooth law's contact edge (the outermost r where the gap is at most the
#: law's edge gap, :mod:`femadh.studies.smooth_sphere`; the regime map's guard): that edge
#: is not a node held at a floor, and the cohesive zone beyond it (~0.7 ell wide, the
#: regime map's band note) is not bounded by one, so the edge is kept further inside. Set
#: with the regime map's guard, not tuned; a different quantity from EDGE_FRACTION's r_c
SMOOTH_EDGE_FRACTION = 0.8


class GuardError(FemadhError):
    """A state or result outside the model's validity: names the quantity, its value and the
    setting to change."""

    #: what the refine loops read (:func:`failure_kind`)
    kind = "guard"


class AnalysisRadiusError(GuardError):
    """The contact reaches the analysis radius: the load does not fit the analysed disk (a
    larger disk, not a finer spacing, resolves it)."""

    kind = "analysis_radius"


class TrappingError(GuardError):
    """Lattice trapping: a node's softening beyond its own stiffness (``ratio``); a trigger
    for refinement where femadh chooses the grid."""

    kind = "trapping"

    def __init__(self, msg, ratio):
        super().__init__(msg)
        self.ratio = ratio


class BoundError(GuardError):
    """A result outside its proven bounds by more than its estimated error (the largest
    adhesion above Derjaguin-Bradley's 2 pi R W): the discretisation is too coarse."""

    kind = "bound"


class BudgetError(GuardError):
    """A grid the run must build (a band following the contact edge) would exceed the node
    budget: a finer member needs more, so refining cannot help."""

    kind = "budget"


#: the kinds of a run's failure (``result.failure_kind``), by the exception that ended it:
#: the guards' own kinds, a solve that did not converge (a stalled continuation, a landing
#: Newton could not polish), the run's stops, and any other fault
FAILURE_KINDS = ("analysis_radius", "trapping", "bound", "budget", "guard", "convergence",
                 "time_limit", "interrupted", "error")


def failure_kind(exc):
    """The kind (one of :data:`FAILURE_KINDS`) of the failure ``exc`` ended a run with."""
    if isinstance(exc, GuardError):
        return exc.kind
    if isinstance(exc, ConvergenceError):
        return "convergence"
    if isinstance(exc, TimeLimitReached):
        return "time_limit"
    if isinstance(exc, Interrupted):
        return "interrupted"
    return "error"


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
    """Refuse a state whose contact reaches the analysis radius (AnalysisRadiusError) or whose
    nodes snap alone (TrappingError, with the setting to change)."""
    a = problem.grid.radius
    if state.r_c > EDGE_FRACTION * a or (state.active.size and state.active[-1]):
        raise AnalysisRadiusError(
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
