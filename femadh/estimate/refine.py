"""Accuracy on demand: refine until the error estimate meets the request, within a budget.

One loop for the contact runner (:mod:`femadh.runner.accuracy`: a scene's nodes and analysis
radius) and the regime map (:mod:`femadh.studies.regime`: a band spacing): each attempt is
solved and judged by its own a-posteriori estimate; an attempt that is not resolved (a guard
refused it) or whose estimate misses the target is refined - the caller says how, or that no
refinement addresses the failure - until the target is met or the budget (refinements,
nodes) is spent. The budget is an explicit setting; running out of it is an outcome, never a
silent stop.
"""
from dataclasses import dataclass, field
import math

# Node limits: one per discretisation path, each set by what a node costs there. Every path
# solves on a dense N x N surface operator (memory 8 N^2 bytes per copy; a few copies: the
# operator, the stiffness, the factorisation), so what limits N is the time per state:
# N^3 / 3 per LU factorisation of the stepping corrector, N^2 per Krylov iteration of the
# arclength corrector.

#: largest uniform N of accuracy mode (:mod:`femadh.runner.accuracy`): accuracy mode doubles
#: N from the scene's nodes (200 by default), and 3200 is four doublings; its sweeps
#: factorise at every corrector step, measured 3.5 s for 3 states at N = 3200
#: (:mod:`femadh.scene.resources`, whose unreachable-accuracy refusal quotes this budget)
UNIFORM_MAX_NODES = 3200
#: largest member of a banded grid family (:class:`femadh.discretisation.GridFamily`), the
#: adaptive run's node budget (:mod:`femadh.runner.adaptive`): the family puts its nodes in
#: the band (the Fig 4 scene meets 1e-3 with ~500, README "Accuracy"), so a member needing
#: more is a request to refuse; the dense operator of 4000 nodes is 128 MB per copy
BANDED_MAX_NODES = 4000
#: node budget of the regime map's refinements (:mod:`femadh.studies.regime`): its arclength
#: continuation runs a Krylov solve at every point of a curve of hundreds of points, each
#: iteration ~N^2, so 1600 nodes cost ~10x 500 per point (a map of 20-40 points stays
#: within minutes)
CONTINUATION_MAX_NODES = 1600

#: a refinement aims at this fraction of the target where the estimate is far from it (from
#: about 3.7x the target on; nearer it :func:`femadh.runner.adaptive._safety` aims closer),
#: and a tail above it grows the disk (the sweep's loop and the edge route alike)
SAFETY = 0.6


@dataclass(frozen=True)
class Budget:
    """What an accuracy request may spend.

    Attributes
    ----------
    max_refinements : int
        Refinements after the first attempt.
    max_nodes : int
        Largest node count of an attempt (a dense operator costs ~N^2 per solve).
    """

    max_refinements: int
    max_nodes: int

    def __post_init__(self):
        if not (self.max_refinements >= 0 and self.max_nodes > 0):
            raise ValueError(f"budget needs max_refinements >= 0 and max_nodes > 0, got "
                             f"{self.max_refinements}, {self.max_nodes}")


@dataclass
class Outcome:
    """How an accuracy request ended.

    Attributes
    ----------
    met : bool
        The last attempt is resolved and its estimated error meets the target.
    setting, result : object
        The last attempt's setting and result.
    error : float
        Its estimated relative error (inf where it has none).
    why : str or None
        Why it is not resolved (a guard's message), or None.
    stop : str
        "met", "refinements" (the budget's refinements spent), "nodes" (the next refinement
        would exceed the budget's nodes) or "no refinement" (none addresses the failure).
    steps : list of dict
        Per attempt: its setting, error and why (the caller keeps anything else it needs).
    """

    met: bool
    setting: object
    result: object
    error: float
    why: str | None
    stop: str
    steps: list = field(default_factory=list)


def refine_until_met(setting, attempt, refine, target, budget, nodes):
    """Attempt ``setting``, refine and attempt again until the estimate meets ``target``.

    Parameters
    ----------
    setting : object
        The first discretisation (the caller's type).
    attempt : callable(setting) -> (result, error, why)
        Solves and judges one setting: its estimated relative error (inf where none) and why
        it is not resolved (None: it is).
    refine : callable(setting, result, error, why) -> setting or None
        The next setting, or None where no refinement addresses the failure.
    target : float
        Requested relative accuracy (> 0).
    budget : Budget
    nodes : callable(setting, result, next_setting) -> int
        Node count of ``next_setting`` (predicted from the attempt just made).

    Returns
    -------
    Outcome
    """
    if not target > 0:
        raise ValueError(f"accuracy must be > 0, got {target}")
    steps = []
    for i in range(budget.max_refinements + 1):
        result, error, why = attempt(setting)
        steps.append({"setting": setting, "error": error, "why": why})
        if why is None and error <= target:
            return Outcome(True, setting, result, error, None, "met", steps)
        if i == budget.max_refinements:
            return Outcome(False, setting, result, error, why, "refinements", steps)
        nxt = refine(setting, result, error, why)
        if nxt is None:
            return Outcome(False, setting, result, error, why, "no refinement", steps)
        if nodes(setting, result, nxt) > budget.max_nodes:
            return Outcome(False, setting, result, error, why, "nodes", steps)
        setting = nxt
    raise AssertionError("unreachable")   # pragma: no cover


def worst_relative(values, errors, floors=None):
    """(name, relative error) of the number furthest from its accuracy: errors[k] / |values[k]|
    (or / max(|values[k]|, floors[k])); names without a value or an error are skipped.
    (None, 0.0) when none has both."""
    worst = (None, 0.0)
    for k, e in errors.items():
        v = values.get(k)
        if e is None or v is None:
            continue
        ref = max(abs(v), (floors or {}).get(k, 0.0))
        rel = abs(e) / ref if ref > 0 else math.inf
        if rel > worst[1]:
            worst = (k, rel)
    return worst
