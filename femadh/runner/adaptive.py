"""The adaptive grid: a contact run whose nodes follow the contact and answer to the estimate.

A scene that fixes neither ``[solver] nodes`` nor ``[solver.grid]`` (Green method,
complementarity sigma-gap or smooth laws) gets a banded grid planned from its laws and sweep
(:func:`femadh.discretisation.plan_grid`: the band where the gaps reach the laws' features,
an analysis radius whose tail is negligible), its band spacing capped so that neither it nor
the coarser members of its estimate are lattice-trapped - a sigma-gap Lennard-Jones request
at or below 1e-3 starting across its Maugis-Dugdale cohesive zone (:func:`first_trial`,
:func:`cohesive_spacing`) - and then refined by the estimate until the headline numbers
meet ``[solver] accuracy`` (default 1e-3):

    h <- h * clamp((s * target / error)^(1/p), MIN_FACTOR, MAX_FACTOR)

with p the order the estimate showed between the last two converged runs of the same family
(clamped to ORDER_BOUNDS; the assumed FIRST_ORDER for the first refinement) and s the aim, SAFETY
far from the target, closer to AIM the nearer the estimate is to it (:func:`_safety`;
measured on every adaptive row of validation/accuracy.py: validation/results/adaptive_order.md).

A failed solve (a node snapping on its own, a stalled continuation, a landing after a fold
that Newton cannot polish) halves h, a contact reaching the analysis radius doubles the
disk, a feature that left the band widens the band, and members that all fail refine h:
each while the budget (MAX_TRIALS runs, MAX_NODES nodes) lasts. Which remedy a failure gets
is decided by its kind (``result.failure_kind``, the type of the exception that ended the
run, :func:`femadh.estimate.guards.failure_kind`), never by the words of its message; a run
stopped by a signal or its time limit ends the loop. The runs are the attempts of the
shared refine-until-met loop (:func:`femadh.estimate.refine.refine_until_met`), one
:class:`Trial` each. The result says what was chosen and every trial
(``result.accuracy``), or fails naming the accuracy reached, the nodes it used, the time and
about how many nodes the request would need (where the force beyond the analysis radius is
what falls short: about what radius it would need).

The band is static by default: a band that follows the contact edge
(``[solver.grid] follow``) was measured against it on the Fig 3, Fig 4 and slider + meniscus
scenes (validation/results/adaptive_follow.md) and did not pay: at the same band spacing it
has 1/3-1/4 of the nodes, but its estimate (the coarser members follow the edge on their own
grids) is 3-5x larger and erratic, so the loop refines once more, and each of its runs
carries the state across a dozen grid exchanges. A sigma-gap scene whose static member at
the trapping-safe spacing alone would exceed FOLLOW_NODES (a cohesive zone of tens of nm at
an edge travelling microns: the stiction map's sigma = 0.3 nm column, 1831-3545 nodes) runs
on a band that follows the edge instead (:func:`_follow_trial`, validation/results/
sigma03_follow.md).
"""
from dataclasses import dataclass
import contextlib
import math
import time

import numpy as np

from ..discretisation import GridFamily, plan_grid
from ..discretisation.family import MAX_NODES
from ..discretisation.plan import safe_spacing
from ..elastic.grid import NodeBudgetError
from ..estimate.refine import SAFETY, Budget, refine_until_met
from .accuracy import REFINE_RADIUS
from .result import STOPPED

#: runs (refinements + 1) an adaptive run may make
MAX_TRIALS = 5
#: assumed convergence order of the headline numbers in the band spacing (local orders
#: 1.2-2.2 on the Fig 3 scene's family; the estimate's envelope order): the first member's
#: plan for a request other than REFERENCE_ACCURACY, and the order where the estimate did not
#: fall between two runs
ORDER = 1.5
#: the order the first refinement sizes its member with (no earlier run of the family shows
#: one): the median of the estimate's order between the first two runs, measured on the five
#: requests of validation/accuracy.py's scenes that refine (validation/results/fig4solve.md):
#: Fig 3 at 2e-3 1.43, Fig 4 at 1e-3 1.80, Fig 3 at 3e-3 1.99, the slider + meniscus at
#: 1e-2 4.10, Fig 4 at 2e-3 7.09. The near aim (:func:`_safety`) covers a true order down to
#: ORDER_SPREAD x FIRST_ORDER = 1.74; the lowest, 1.43, sized so from its 1.58x lands at
#: 0.86 of the target. With ORDER here (1.5) Fig 4 at 1e-3 asked for 595 nodes; now 493
#: (estimate 7.7e-4). The estimate is not smooth in h: neighbouring members differ by up to
#: 4x (Fig 3 at 116 and 118 nodes: 4.1e-3 and 1.85e-3), so Fig 3 at 3e-3 now takes a third
#: run (87, 109, 150 nodes: its estimate at 109 did not fall) where 118 met
FIRST_ORDER = 2.0
#: limits of one refinement factor of h
MIN_FACTOR, MAX_FACTOR = 0.3, 0.8
#: range an order observed between two runs of one family is clamped to (outside it the two
#: estimates say more about their noise than about the spacing: the estimate's orders between
#: consecutive runs, measured on the adaptive rows of validation/accuracy.py, spread 0.3-7.1,
#: validation/results/adaptive_order.md). A second run that missed the target was sized with
#: an order its estimate did not reach (unless MIN_FACTOR limited its step), so the order
#: observed then is the lower one: the third member is finer than the assumed order would
#: make it, never coarser
ORDER_BOUNDS = (0.5, 4.0)
#: the aim near the target: the next member is sized so that even an order ORDER_SPREAD x
#: the one it is sized with lands the estimate at AIM x the target (ORDER_SPREAD measured on
#: Fig 4 at 1e-3: its estimate's order 1.29 between the 279- and 631-node runs against the
#: assumed 1.5); AIM leaves room for the estimate's jitter about its power law, up to 1.31x
#: measured between consecutive runs (a stiction-map point, sigma 1.43 nm, p/psat 0.55: 1.17e-3
#: -> 1.10e-3 on a step promising 1.40x; with AIM 0.9 it needed a third run), AIM = 1 / 1.31.
#: Far from the target this needs a safety below SAFETY, which then holds
ORDER_SPREAD, AIM = 0.87, 0.76
#: the accuracy the plan's BAND_NODES are sized for; the fewest nodes across any band
REFERENCE_ACCURACY, MIN_BAND_NODES = 1e-3, 48
#: a feature beyond this fraction of the band radius widens the band
BAND_FILL = 0.97
#: a sigma-gap stepping scene whose static member, at the trapping-safe spacing alone,
#: would have more than this many nodes runs on a band that follows the contact edge instead
#: ([solver.grid] follow, :class:`~femadh.discretisation.moving.EdgeBand`; None: never).
#: Only the trapping cap decides it, not the accuracy's refinement: a static band that pays
#: at the scene's defaults (the bundled scenes, 161-632 nodes) stays static; the stiction
#: map's sigma = 0.3 nm column needs 1831-3545 static nodes for its cohesive zone
#: (validation/results/sigma03_landing.md)
FOLLOW_NODES = 1000
#: half-width of that band (beyond the cohesive zone it always spans) and its grading length,
#: in band spacings of the member: the zone (25-80 nm on the sigma = 0.3 nm column) plus a
#: margin of ~40 nm at 1.8 nm, then the spacing grows by ~1/8 per node to the analysis radius
FOLLOW_HALF_SPACINGS, FOLLOW_GRADING_SPACINGS = 24, 8
#: half-width of a follow band over the static band's radius where FOLLOW_NODES forces one
#: on a scene whose static member is small (tests: FOLLOW_NODES = 0)
FOLLOW_HALF = 1 / 6


def _feature_radius(res, problem_shape, gap):
    """Largest radius (m) where a kept surface profile's gap is at most ``gap``."""
    out = 0.0
    for prof in res.profiles.values():
        for i, (d, w) in enumerate(zip(prof["d_m"], prof["w_m"])):
            nodes = np.asarray(prof["r_m"][i], float) if "r_m" in prof else res.nodes
            h = d + problem_shape(nodes) - w
            close = np.flatnonzero(h <= gap)
            if close.size:
                out = max(out, float(nodes[close[-1]]))
    for c in res.branches.values():
        if len(c.get("r_c_m", ())):
            out = max(out, float(np.max(c["r_c_m"])))
    return out


def _member(family, spacing, follow):
    """The family's member of band spacing h (m): the static band, or (``follow``, its
    half-width in m) the band that follows the edge, as its trace starts (centred on r = 0,
    as :func:`femadh.scene.build.discretisation_grid` builds it)."""
    if follow:
        from ..discretisation.moving import follow_family

        return follow_family(family.radius, follow, family.grading, 0.0).member(spacing)
    return family.member(spacing)


def _follows(scene, family, spacing):
    """The follow band's half-width (m) for this member, or None (a static band): only a
    sigma-gap stepping scene follows its edge (:func:`femadh.runner.tracing.trace_steps`),
    and only where its static member would exceed FOLLOW_NODES."""
    if FOLLOW_NODES is None or scene.gap is None or scene.continuation == "arclength" or \
            getattr(scene.gap, "contact_model", "complementarity") != "complementarity":
        return None
    if FOLLOW_NODES != 0:
        return None             # the trapping cap decides (:func:`_follow_trial`)
    return FOLLOW_HALF * family.band


def _capped(scene, family, spacing, follow=None):
    """(spacing, operator, problem) with the spacing capped below the trapping-safe one of
    the family (two passes: the ratio is measured on the member itself)."""
    from ..elastic import GreenOperator
    from ..scene import build_problem

    op = problem = None
    for _ in range(3):
        op = GreenOperator(_member(family, spacing, follow), scene.e_star)
        problem = build_problem(scene, operator=op)
        safe = safe_spacing(problem)
        if spacing <= safe:
            break
        spacing = 0.98 * safe
    return spacing, op, problem


@dataclass
class Trial:
    """One setting of the refine loop: a member of a family, as it is run.

    Attributes
    ----------
    family : GridFamily
    spacing : float
        The band spacing h (m) the member uses: the one asked for, capped below the
        trapping-safe spacing (:func:`_capped` may shrink it).
    asked : float
        The band spacing (m) asked for, before the cap.
    nodes : int
        The member's node count; above the node limit where the member was refused.
    operator : GreenOperator or None
        The member's operator until it has been run (then dropped: the loop keeps every
        setting); None where the member would exceed the family's node limit
        (:data:`~femadh.discretisation.family.MAX_NODES`).
    follow : float or None
        Half-width (m) of a band that follows the contact edge (None: the static band).
    """

    family: GridFamily
    spacing: float
    asked: float
    nodes: int
    operator: object = None
    follow: float | None = None

    def grid(self):
        """The member's [solver.grid] table (SI)."""
        out = self.family.as_dict(self.spacing)
        if self.follow:
            out["follow"] = self.follow
        return out


def _follow_trial(scene, family, spacing):
    """The :class:`Trial` on a band following the contact edge, or None (a static band):
    where the static member at the trapping-safe spacing would exceed FOLLOW_NODES. Probed on
    the follow member itself (a few hundred nodes, never the static one): the static cap
    :func:`~femadh.discretisation.plan.safe_spacing` decides, the follow band's own
    :func:`~femadh.discretisation.plan.follow_safe_spacing` (the summed softening at the
    edge, so that its coarsest member does not unzip node by node) caps its spacing; half
    width and grading scale with that spacing (FOLLOW_HALF_SPACINGS,
    FOLLOW_GRADING_SPACINGS)."""
    from ..discretisation.moving import follow_family
    from ..discretisation.plan import follow_safe_spacing
    from ..elastic import GreenOperator
    from ..scene import build_problem

    if FOLLOW_NODES is None or FOLLOW_NODES == 0 or scene.gap is None or \
            scene.continuation == "arclength" or \
            getattr(scene.gap, "contact_model", "complementarity") != "complementarity":
        return None
    def member(h):
        fam = GridFamily(family.radius, family.band, FOLLOW_GRADING_SPACINGS * h)
        half = FOLLOW_HALF_SPACINGS * h
        op = GreenOperator(follow_family(fam.radius, half, fam.grading, 0.0).member(h),
                           scene.e_star)
        return fam, half, op, build_problem(scene, operator=op)

    h = spacing
    fam, half, op, problem = member(h)
    # the trapping cap alone decides, never the accuracy's refinement (at 1e-4 the bundled
    # Fig 4's static band passes 1000 nodes by refinement, where adaptive_follow.md measured
    # the follow band not to pay)
    if family.count(0.98 * safe_spacing(problem)) <= FOLLOW_NODES:
        return None
    for _ in range(3):
        safe = follow_safe_spacing(problem)
        if h <= safe:
            break
        h = 0.98 * safe
        fam, half, op, problem = member(h)      # the trial is the member at the h it names
    return Trial(fam, h, spacing, op.grid.n, op, half)


def _trial(scene, family, spacing):
    """The :class:`Trial` of ``family`` at band spacing ``spacing`` (m), capped."""
    try:
        ft = _follow_trial(scene, family, spacing)
    except NodeBudgetError:
        ft = None
    if ft is not None:
        return ft
    follow = _follows(scene, family, spacing)
    try:
        h, op, _ = _capped(scene, family, spacing, follow)
    except NodeBudgetError:     # the member would exceed MAX_NODES (only that refusal: any
        # other ValueError of the member, its operator or its problem is raised as it is)
        return Trial(family, spacing, spacing, max(family.count(spacing), MAX_NODES + 1),
                     None, follow)
    return Trial(family, h, spacing, op.grid.n, op, follow)


#: nodes across the Lennard-Jones cohesive zone (its Maugis-Dugdale width at pull-off) that
#: the first member of a sigma-gap request at or below 1e-3 gets (:func:`cohesive_spacing`).
#: Measured on the Fig 4 family (sigma 0.42-0.7 nm, R 1-4 mm, lambda 0.83-2.73): the band
#: spacing that meets 1e-3 (the estimate's power law between the last two runs of each
#: request) puts 7.6-15.5 spacings across the zone, 10.9-13.5 on six of the eight
#: (validation/results/first_member.md); the largest is taken with a margin. The estimate
#: itself jitters by up to 2x between neighbouring members (the slider at sigma 0.489 nm,
#: p/psat 0.45: 1.3e-3 on 289 nodes, 2.1e-3 on 299), so no start this close to the target
#: can be sharper than that
CZ_NODES = 16


def _lj_laws(scene):
    """{name: law} of the scene's Lennard-Jones laws."""
    from ..laws.lj import LennardJones

    return {k: e for k, e in scene.effects.items() if isinstance(e, LennardJones)}


def cohesive_zone(scene):
    """(lambda, width in m) of the Lennard-Jones cohesive zone of a sigma-gap contact at its
    pull-off, or None (no such law or no gap; see :func:`cohesive_spacing`)."""
    from ..discretisation.plan import work_of_adhesion
    from ..reference.maugis import maugis_length_units, maugis_pull_off_state

    gap = scene.gap
    if gap is None or getattr(gap, "contact_model", "complementarity") != "complementarity":
        return None
    lj = _lj_laws(scene)
    if not lj:
        return None
    w_lj = work_of_adhesion(lj, gap.sigma)
    h = gap.sigma * np.logspace(0.0, 2.0, 2000)
    sigma0 = float(np.max(sum(e.pressure(h) for e in lj.values())))
    if not (w_lj > 0 and sigma0 > 0):
        return None
    k = 4.0 * scene.e_star / 3.0
    lam = 2.0 * sigma0 * (scene.sphere.radius / (math.pi * w_lj * k * k)) ** (1.0 / 3.0)
    m, a, _ = maugis_pull_off_state(lam)
    return lam, (m - 1.0) * a * maugis_length_units(scene.sphere.radius, scene.e_star, w_lj)[0]


def cohesive_spacing(scene, target):
    """Band spacing (m) that resolves the Lennard-Jones cohesive zone of a sigma-gap contact
    for ``target`` (relative, <= REFERENCE_ACCURACY), or None (no such law or no gap).

    The zone is Maugis-Dugdale's at the load-controlled pull-off (the largest adhesion):
    lambda = 2 sigma0 (R / (pi W K^2))^(1/3), K = 4 E* / 3, with W = -U_LJ(sigma) and sigma0
    the law's largest pressure at h >= sigma, its width (m - 1) a
    (:func:`cohesive_zone`, :func:`femadh.reference.maugis.maugis_pull_off_state`). CZ_NODES
    spacings across it put the LJ part of the largest adhesion at ~1e-3; its share of the
    whole adhesion, W / W_all (a condensed meniscus adds to W_all), and the order 2 of the
    estimate's fall (FIRST_ORDER) scale that to the request:
    h = width / CZ_NODES (target / (1e-3 share))^(1/2). The width also sets the
    trapping-safe spacing (both scale as E* delta / sigma0), so where that cap binds the
    plan's spacing says nothing of the accuracy, this does."""
    from ..discretisation.plan import work_of_adhesion

    zone = cohesive_zone(scene)
    if zone is None:
        return None
    lj = _lj_laws(scene)
    w_all = work_of_adhesion(scene.effects, scene.gap.sigma)
    if not w_all > 0:
        return None
    # (another law repulsive at sigma makes W_all < W_LJ: the LJ zone is then the whole)
    share = min(1.0, work_of_adhesion(lj, scene.gap.sigma) / w_all)
    return zone[1] / CZ_NODES * (target / (REFERENCE_ACCURACY * share)) ** (1 / FIRST_ORDER)


def first_trial(scene, plan, target):
    """The :class:`Trial` the adaptive loop starts from: the member for REFERENCE_ACCURACY
    (BAND_NODES across the band, at least MIN_BAND_NODES, capped below the trapping-safe
    spacing by :func:`_trial`), its spacing scaled by (target / REFERENCE_ACCURACY)^(1/ORDER)
    for another request (``plan``: :func:`~femadh.discretisation.plan_grid`'s).

    For a finer request the scaling starts from the capped 1e-3 member: where the trapping
    cap binds, the cohesive zone is narrower than BAND_NODES resolve (its width and the safe
    spacing both scale as E* delta / sigma0: :func:`cohesive_spacing`), so the plan's spacing
    says nothing about the accuracy there. And a sigma-gap Lennard-Jones request at or below
    1e-3 starts no coarser than :func:`cohesive_spacing` (CZ_NODES spacings across the law's
    cohesive zone). A start the node budget refuses (MAX_NODES) falls back to the next
    coarser of these (zone, capped, plan's): the loop then refines from it and says what the
    request needs, where a refused start would end the request before any solve. A band
    following the edge keeps its own cap (:func:`_follow_trial`): its spacing is scaled from
    the plan's.

    Measured (validation/results/first_member.md, CPU seconds at load ~5): the Fig 4 scene
    (sigma = 0.5 nm) at 1e-4 went 871 + 2791 nodes, 73.0 s (the plan's 39.3 nm scaled) ->
    1341 + 1765, 32.1 s (the capped 25.6 nm scaled) -> 1765 in one run, 21.3 s (the zone);
    at 1e-3 279 + 493 -> 540 nodes, 1.8 -> 1.6 s. On the other 1e-3 and 3e-4 requests
    measured (sigma variants of Fig 4, seven stiction-map points) the estimate's jitter
    decides single requests either way: Fig 4 at 3e-4 2.5 -> 6.9 s (624 -> 986 nodes), the
    slider at sigma 0.489 nm, p/psat 0.25 14.8 -> 22.3 s and p/psat 0.35 22.8 -> 4.8 s; the
    eleven together 54.5 -> 48.3 s, and 31.7 -> 43.5 s without the last."""
    family = plan.family
    top = family.band / MIN_BAND_NODES
    scale = (target / REFERENCE_ACCURACY) ** (1.0 / ORDER)
    # the starts, finest first; the last is the plan's
    starts = [_plan_start(plan, target)]
    follows = False
    if scale < 1.0:
        ref = _trial(scene, family, min(plan.spacing, top))
        follows = ref.follow is not None
        if ref.operator is not None and not follows and ref.spacing < ref.asked:
            starts.insert(0, min(ref.spacing * scale, top))
        ref.operator = None         # (the probe's operator: the member is built at its own h)
    hz = None if follows else _zone_start(scene, target, starts[0])
    if hz is not None:
        starts.insert(0, hz)
    for h in starts:
        tr = _trial(scene, family, h)
        if tr.follow is not None and h != starts[-1]:
            # a band following the edge: its own cap, from the plan's spacing
            return _trial(scene, family, starts[-1])
        if tr.operator is not None:
            return tr
    return tr           # (every start refused: the loop says what the request needs)


def _plan_start(plan, target):
    """The plan's start (m): BAND_NODES across the band (at least MIN_BAND_NODES) scaled by
    (target / REFERENCE_ACCURACY)^(1/ORDER), before the trapping cap."""
    return min(plan.spacing * (target / REFERENCE_ACCURACY) ** (1.0 / ORDER),
               plan.family.band / MIN_BAND_NODES)


def _zone_start(scene, target, coarser):
    """The cohesive zone's start (m, :func:`cohesive_spacing`) where it is finer than
    ``coarser`` (m), else None. Only for a request at or below 1e-3: a looser one keeps the
    trapping cap, which already over-resolves it (the Fig 4 scene at 3e-3 estimates 2.2e-3
    on the capped member)."""
    if target > REFERENCE_ACCURACY:
        return None
    hz = cohesive_spacing(scene, target)
    return hz if hz is not None and math.isfinite(hz) and 0 < hz < coarser else None


def reference_trial(scene):
    """The :class:`Trial` the loop would start from at REFERENCE_ACCURACY whatever the
    scene's request (the edge route's trap measure,
    :func:`femadh.runner.edge_route.edge_trap_ratio`)."""
    return first_trial(scene, _plan(scene, REFERENCE_ACCURACY), REFERENCE_ACCURACY)


def _plan(scene, target):
    """The scene's grid plan for ``target`` (:func:`~femadh.discretisation.plan_grid`)."""
    return plan_grid(scene.effects, None if scene.gap is None else scene.gap.sigma,
                     scene.sphere, scene.analysis_radius, scene.d_values, target)


def planned_first_nodes(scene):
    """About how many nodes :func:`first_trial` starts ``scene`` (an adaptive contact scene)
    on, and how many its coarsest start needs, read off the plan without building an
    operator (``femadh check``'s time estimate and its refusal of a request the node budget
    cannot start): (nodes, coarsest) - the zone's start where it fits the budget, else the
    plan's scaled spacing (the trapping cap, measured on a built member, can only make
    either finer)."""
    target = scene.target_accuracy
    plan = _plan(scene, target)
    h = _plan_start(plan, target)
    coarsest = plan.family.count(h)
    hz = _zone_start(scene, target, h)
    if hz is not None and plan.family.count(hz) <= MAX_NODES:
        return plan.family.count(hz), coarsest
    return coarsest, coarsest


def _too_many_nodes(trial):
    return (f"the grid would need more than {MAX_NODES} nodes (band spacing "
            f"{trial.asked * 1e9:.3g} nm over {trial.family.band * 1e6:.3g} um)")


def run_adaptive(scene, out_dir, *, run, figures=True, progress=None, overwrite=False,
                 resume=False, estimate=True):
    """Run ``scene`` on its adaptive grid (see the module docstring) with ``run``
    (:func:`femadh.runner.run.run`); with ``estimate`` not True, one run on the planned
    member (its accuracy unjudged).

    The runs are the attempts of :func:`femadh.estimate.refine.refine_until_met` (budget
    MAX_TRIALS - 1 refinements, MAX_NODES nodes): each attempt runs one :class:`Trial` and
    decides from its result what the next would be (:func:`_decide`), the loop's refine
    step builds that member (capped)."""
    from ..io.progress import phase
    from ..scene import scene_id
    from .estimates import deferring, judged_errors, variant

    t0 = time.perf_counter()
    target = scene.target_accuracy
    plan = _plan(scene, target)
    family = plan.family
    mode = {"overwrite": overwrite, "resume": resume}
    steps = []
    # what the last attempt decided: the next (family, spacing) asked for, or None with the
    # failure that ends the request (None: none, e.g. a stop or an unjudged run)
    ahead = {"next": None, "failure": None, "refused": None, "trial": None}

    def attempt(tr):
        i = len(steps)
        if ahead.get("res") is not None:
            # the last trial is superseded: its deferred rest is never made, and its closure
            # would hold its problem, sink and member problems alive through this one
            ahead["res"].pending_estimate = None
        trial = variant(scene, grid=tr.grid(), radius=tr.family.radius)
        ahead["trial"] = trial
        with phase(f"{'refinement ' + str(i) if i else 'grid'} ({tr.nodes} nodes)"):
            # (a trial whose judged numbers miss the target defers the rest of its
            # estimate: completed below if the loop keeps it)
            with deferring(target if estimate is True else None):
                res = run(trial, out_dir, figures=False, progress=progress,
                          estimate=estimate, operator=tr.operator,
                          folder_id=scene_id(scene), **mode)
        tr.operator = None            # run: its dense operator need not outlive it
        ahead["res"] = res
        mode.update(overwrite=True, resume=False)     # later trials replace earlier ones
        grid_e, tail_e = (judged_errors(res) if res.status == "converged" and estimate is True
                          else (math.nan, math.nan))
        steps.append({"nodes": tr.nodes, "spacing_m": tr.spacing,
                      "band_m": tr.family.band, "analysis_radius_m": tr.family.radius,
                      "status": res.status, "grid_rel_error": grid_e,
                      "tail_rel_error": tail_e, "wall_time_s": res.wall_time})
        if tr.follow:
            steps[-1]["follow_m"] = tr.follow
        why = _decide(scene, tr, res, estimate, steps[-1], plan, target, ahead, steps[:-1])
        return res, (grid_e + tail_e if why is None else math.inf), why

    def refine(tr, res, error, why):
        if ahead["next"] is None:
            return None
        nxt = _trial(scene, *ahead["next"])
        if nxt.operator is None:
            ahead["refused"] = nxt
        return nxt

    out = None
    first = first_trial(scene, plan, target)
    if estimate is True:
        # a grid that would follow the edge: a sigma-gap retract that unzips node by node;
        # where its pilot finds a fold, the branch in its edge radius instead (edge_route)
        from .edge_route import route_for, run_edge_route

        # (a resumed folder of the sweep's path keeps that path: the route would start over)
        pil = (None if resume and holds_sweep_run(out_dir)
               else route_for(scene, first.follow is not None,
                              member=lambda: (first if target == REFERENCE_ACCURACY
                                              else reference_trial(scene))))
        if pil is not None:
            return run_edge_route(scene, out_dir, pil, trial=first, figures=figures,
                                  overwrite=overwrite, resume=resume,
                                  folder_id=scene_id(scene), progress=progress)
    if first.operator is None:
        failure = _too_many_nodes(first)
    else:
        out = refine_until_met(first, attempt, refine, target,
                               Budget(MAX_TRIALS - 1, MAX_NODES),
                               nodes=lambda tr, res, nxt: nxt.nodes)
        # (a failure decided on the last run ends the request even where the budget of
        # runs ended it as well: it says why more runs would not help)
        failure = (_too_many_nodes(ahead["refused"]) if out.stop == "nodes"
                   else ahead["failure"])
    res = out.result if out is not None else None
    ahead["res"] = None
    raised = None
    if res is not None:
        from .estimates import complete_estimate

        try:
            # (a phase of the display only where there is a deferred rest to make)
            with phase("estimate") if getattr(res, "pending_estimate", None) is not None \
                    else contextlib.nullcontext():
                complete_estimate(res)          # the kept trial's estimate made whole
        except BaseException as exc:
            # a bug while completing: res is "failed" with its error (complete_estimate);
            # the summary is written below, then the exception raised again, as a run's
            # lifecycle does
            raised = exc
    family = out.setting.family if out is not None else family
    met = bool(out is not None and out.met and estimate is True)
    if res is None:
        from .result import ContactResult

        res = ContactResult(scene.name, scene, status="failed")
    last = steps[-1] if steps else {}
    res.accuracy = {"target": target, "met": met, "adaptive": True,
                    "nodes": last.get("nodes"), "spacing_m": last.get("spacing_m"),
                    "band_m": last.get("band_m"),
                    "analysis_radius_m": last.get("analysis_radius_m"), "steps": steps,
                    "feature_gap_m": plan.feature_gap,
                    "wall_time_s": time.perf_counter() - t0}
    if failure and res.status == "converged" or failure and not steps:
        res.status, res.error = "failed", f"accuracy {target:g} not met: {failure}"
        res.failure_kind = "accuracy"
    elif not met and res.status == "converged" and estimate is True and \
            last.get("members_failed"):
        res.status, res.failure_kind = "failed", "accuracy"
        res.error = (f"accuracy {target:g} not judged: no coarser member of the grid family "
                     f"converged after {len(steps)} runs (last: {last['nodes']} nodes, band "
                     f"spacing {last['spacing_m'] * 1e9:.3g} nm); see the warnings")
    elif not met and res.status == "converged" and estimate is True:
        reached = last["grid_rel_error"] + last["tail_rel_error"]
        res.status, res.failure_kind = "failed", "accuracy"
        said = (f"accuracy {target:g} not met: estimated relative error {reached:.2g} "
                f"with {last['nodes']} nodes after {len(steps)} runs "
                f"({res.accuracy['wall_time_s']:.3g} s)")
        if last["tail_rel_error"] > SAFETY * target:
            # the force beyond the analysis radius is what falls short (the loop was growing
            # the disk, _decide): a finer spacing would not help, a count of nodes misleads
            res.error = (f"{said}, {last['tail_rel_error']:.2g} of it the force beyond the "
                         f"analysis radius {last['analysis_radius_m'] * 1e6:.4g} um; the "
                         f"request needs {_radius_needed(steps, SAFETY * target)} (budget: "
                         f"{MAX_TRIALS} runs)")
        else:
            need = _nodes_needed(family, last["spacing_m"], reached, target)
            res.error = (f"{said}; the request needs about {need} nodes (budget: "
                         f"{MAX_TRIALS} runs, {MAX_NODES} nodes)")
    res.timings["adaptive_total_s"] = time.perf_counter() - t0
    trial = ahead["trial"]
    if out_dir is not None and trial is not None:
        from ..io.run_folder import RunFolder
        from .result import contact_summary as summary

        # the last trial's outputs stay; its summary gains the accuracy record, its figures
        with RunFolder(out_dir, scene_id(scene), scene.name, "amend",
                       given=scene.as_given) as folder:
            if figures and raised is None and res.status in ("converged", "failed") \
                    and res.branches and any(
                    len(next(iter(b.values()))) for b in res.branches.values()):
                from .figures import draw_figures

                # a signal stops the figures at once: the run ends "interrupted"
                with phase("figures"):
                    draw_figures(res, folder)
            folder.write_summary(summary(res))
    if raised is not None:
        raise raised
    return res


def holds_sweep_run(out_dir):
    """Whether ``out_dir`` holds a run of the sweep's path (its summary names no edge route):
    a resume continues it there."""
    import json
    from pathlib import Path

    path = Path(out_dir) / "summary.json" if out_dir is not None else None
    if path is None or not path.is_file():
        return False
    try:
        grid = json.loads(path.read_text()).get("grid") or {}
    except (OSError, ValueError):
        return True             # unreadable: the sweep's own resume says what is wrong
    return grid.get("route") != "edge-branch"


def _decide(scene, tr, res, estimate, step, plan, target, ahead, history=()):
    """Judge one trial's result and decide the next member: sets ``ahead["next"]`` (the
    (family, band spacing) to run next, or None) and ``ahead["failure"]`` (why the request
    ends, or None), records the reason in ``step``; returns why the trial is not resolved
    (None: it is, and its estimate is its error).

    The failure's kind (``res.failure_kind``, its exception's type), never its words, picks
    the remedy: a contact at the analysis radius doubles the disk, any other failure of the
    discretisation (a node snapping on its own, a stalled continuation, a landing Newton
    could not polish after a fold) halves h; a stopped run (signal, time limit) or an
    unjudged one (``estimate`` not True) ends the loop. An estimate above the target sizes
    the next member with the order the estimate showed between this run and the last
    converged one of the same family (``history``, the earlier steps; :func:`_order`), the
    assumed FIRST_ORDER without one, aiming closer the nearer the target it is (:func:`_safety`)."""
    family, h = tr.family, tr.spacing
    ahead["next"] = ahead["failure"] = None
    if res.status in STOPPED:
        return res.status
    if estimate is not True:
        return "not estimated"
    if res.status != "converged":
        if res.failure_kind == "budget":
            # a grid the run had to build exceeded the node budget: a finer member needs
            # more (the loop ends; the trial's own error says where)
            step["refined_for"] = res.failure_kind
            return res.error or res.status
        if res.failure_kind == REFINE_RADIUS:
            # the contact reached the disk's edge: a larger disk, the same band spacing
            ahead["next"] = (GridFamily(2 * family.radius, family.band, family.grading), h)
        else:
            # lattice trapping, a stalled continuation, a landing Newton could not polish
            # after a fold: the discretisation's failures, which a finer member resolves
            ahead["next"] = (family, 0.5 * h)
        step["refined_after"] = res.error or ""
        step["refined_for"] = res.failure_kind
        return res.error or res.status
    edge = _feature_radius(res, scene.sphere.shape, plan.feature_gap)
    if edge > BAND_FILL * family.band and family.band < family.radius:
        # the feature left the band: widen it (the spacing stays)
        ahead["next"] = (GridFamily(family.radius, min(family.radius, 1.2 * edge / BAND_FILL),
                                    family.grading), h)
        step["band_left_m"] = edge
        return "the feature left the band"
    if len(res.grid.get("members", ())) == 0:
        # no coarser member converged (a stalled landing at a meniscus edge, trapping):
        # the grid error is unknown, so the result cannot be called converged; a finer
        # family has finer members
        step["members_failed"] = True
        ahead["next"] = (family, h * MAX_FACTOR)
        return "no coarser member converged"
    grid_e, tail_e = step["grid_rel_error"], step["tail_rel_error"]
    err = grid_e + tail_e
    if err <= target:
        return None
    if tail_e > SAFETY * target:
        # the force beyond the disk: a finer spacing cannot help, a larger disk can -
        # unless it would reach the sphere's own size (eq 4's paraboloid is a sphere only
        # for r << R; a small tip keeps its tail as F_tail and this part of the estimate)
        cap = (0.5 if scene.sphere.profile == "sphere" else 1.0) * scene.sphere.radius
        if 2 * family.radius < cap:
            ahead["next"] = (GridFamily(2 * family.radius, family.band, family.grading), h)
            step["tail_grew_radius"] = True
            return None
        ahead["failure"] = (f"the force beyond the analysis radius alone is {tail_e:.2g} "
                            f"relative and the radius cannot grow (it would reach the "
                            f"sphere's radius {scene.sphere.radius * 1e9:.4g} nm); the grid "
                            f"part is {grid_e:.2g}")
        return None
    order = _order(step, history)
    safety = _safety(err / target)
    step["order_used"], step["safety"] = order, safety
    factor = (safety * target / err) ** (1.0 / order) if err > 0 else MIN_FACTOR
    ahead["next"] = (family, h * min(MAX_FACTOR, max(MIN_FACTOR, factor)))
    return None


def _order(step, history):
    """The order the next member is sized with: the estimate's observed order between
    ``step`` and the latest earlier converged step of the same family (band, analysis radius,
    a static band or one following the edge) at another spacing, p = log(e0 / e1) /
    log(h0 / h1), clamped to ORDER_BOUNDS; FIRST_ORDER where there is none, ORDER where the
    estimate did not fall with the spacing (its order says nothing then)."""
    h1, e1 = step["spacing_m"], step["grid_rel_error"] + step["tail_rel_error"]
    for prev in reversed(history):
        if (prev.get("status") != "converged" or prev.get("members_failed")
                or prev.get("band_m") != step["band_m"]
                or prev.get("analysis_radius_m") != step["analysis_radius_m"]
                or ("follow_m" in prev) != ("follow_m" in step)):
            continue
        h0 = prev["spacing_m"]
        e0 = prev["grid_rel_error"] + prev["tail_rel_error"]
        if not (math.isfinite(e0) and math.isfinite(e1) and e1 > 0 and h0 > h1 > 0):
            continue
        if e0 <= e1:
            return ORDER
        p = math.log(e0 / e1) / math.log(h0 / h1)
        return min(ORDER_BOUNDS[1], max(ORDER_BOUNDS[0], p))
    return FIRST_ORDER


def _safety(ratio):
    """The fraction of the target the next member aims at, for an estimate ``ratio`` x the
    target: with the spacing scaled by (s / ratio)^(1/p) and a true order q = ORDER_SPREAD p,
    the estimate lands at ratio (s / ratio)^ORDER_SPREAD x the target; s is the largest that
    keeps this at AIM, s = AIM^(1/c) ratio^(-(1 - c)/c), c = ORDER_SPREAD, within [SAFETY,
    AIM] (SAFETY from about 3.7x the target on: the old aim)."""
    c = ORDER_SPREAD
    s = AIM ** (1.0 / c) * ratio ** (-(1.0 - c) / c) if ratio > 0 else AIM
    return min(AIM, max(SAFETY, s))


def _radius_needed(steps, tail_target):
    """What analysis radius brings the tail's relative error to ``tail_target``: from its
    observed decay over the last two runs on different radii (tail ~ a^-p), "an analysis
    radius of about X um"; without two such runs or with a tail that did not fall, "a larger
    analysis radius"."""
    last = steps[-1]
    a1, t1 = last["analysis_radius_m"], last["tail_rel_error"]
    for prev in reversed(steps[:-1]):
        a0, t0 = prev.get("analysis_radius_m"), prev.get("tail_rel_error", math.nan)
        if a0 and a0 < a1 and t0 > t1 > 0 and math.isfinite(t0):
            p = math.log(t0 / t1) / math.log(a1 / a0)
            return (f"an analysis radius of about {a1 * (t1 / tail_target) ** (1 / p) * 1e6:.3g}"
                    f" um (the tail fell as a^-{p:.2g} over the last runs)")
    return "a larger analysis radius"


def _nodes_needed(family, spacing, reached, target):
    """About how many nodes the family's member meeting ``target`` has (order ORDER)."""
    if not (reached > 0 and math.isfinite(reached)):
        return "an unknown number of"
    h = spacing * (target / reached) ** (1.0 / ORDER)
    return str(family.count(h))
