"""The edge-branch route of a sigma-gap contact run: its max adhesion from the retract traced
in its edge radius (:mod:`femadh.contact.sigma_edge`), its error from a grid family of edge
grids and a guarded Richardson extrapolation (issue 21, goal 1).

Why a route of its own: on a sigma-gap complementarity scene whose cohesive zone is narrow
(the stiction map's sigma = 0.3 nm column, sigma = 0.489 nm at p/psat 0.15) the runner's
retract unzips node by node - hundreds of micro-folds, each bracketed, bisected and landed -
and its coarser members unzip along lattice paths of their own; 400-1500 s a point without
reaching 1e-3 (validation/results/sigma_edge.md). On a grid scaled with the contact radius
the same branch is a smooth function of c, every state a release point of the runner's
collocation problem (paper 1 eqs 6, 8) on its own grid; a family h, h/sqrt2, h/2 of such grids
converges at order 2.00 (effectivity 1.00 of the coarser triples' estimates, sigma_edge.md).

Which runs take it (:func:`route_for`): a scene that

- is sigma-gap complementarity without eq 20's adhesion on the contact set (the edge
  condition p_c,k = 0 needs a contact set that holds no tension);
- is on the Green operator of the homogeneous half-space (C = lam C^0 holds for it only: no
  FE body, no coating);
- is traced by stepping without an instrument (the route reads the displacement-controlled
  branch);
- is adaptive (femadh chooses the grid: an explicit ``nodes`` or ``[solver.grid]`` is a
  request for that grid and is honoured);
- and whose adaptive grid would follow the contact edge, i.e. whose static band at the
  trapping-safe spacing exceeds :data:`~femadh.runner.adaptive.FOLLOW_NODES` (the scenes
  whose retract unzips node by node; every bundled scene has a static band and keeps its
  path, numbers bit for bit), or whose static first member is trapped at the contact edge
  by a sub-grid meniscus step just above sigma (:func:`edge_trap_ratio`: the low-humidity
  points of the stiction map, whose sweep refines its static band to 700-1800 nodes and
  unzips there, 35-90+ s a point);

and then a pilot trace (< 1 s) decides: a fold of d(c) at a finite edge radius takes the
route, no fold (the contact shrinks to nothing without a jump, DMT's side: the largest force
is not on this branch) the present path.

What the route gives (:func:`run_edge_route`): the max adhesion (the finest member's largest
F_ex on the runner's analysis disk, where on the branch it is, its edge radius) and the
displacement-controlled pull-off (the fold's d, ``jump_out_d_m``), each with its estimated
error (Richardson of the family, the force beyond the analysis radius, the solver's
tolerance, as the runner's estimate has them); and the sweep's outputs
(:mod:`femadh.runner.edge_sweep`): the approach by the sweep on the adaptive grid's first
member with its jump-in, the retract's states at the sweep's separations on the finest
member's scaled grids (each polished by the runner's corrector), the jump-out landed from
the fold and the separated retract stepped - curve.csv, fields.csv, jumps.csv and the
figures as any run writes them. The numbers read off the approach and the jumps
(jump_in_d_m, hysteresis_J, the deepest forces) are computed, not estimated: the accuracy
record lists what is judged (``judged``), a note says so. ``[solver] route = "peak"`` asks
for the max adhesion and the pull-off alone (a study that reads only these: the stiction
map): no approach, the branch's own states as the curve "retract_edge_branch" (each on its
own scaled grid, from deep contact to the fold); so does a run whose accuracy the family
does not reach (it fails in one line before the sweep's outputs).

A stopped routed run keeps the states it committed (each row of the files whole) and says
so; --resume starts the route over (its family is not checkpointed).
"""
from dataclasses import dataclass, field
import math
import time

import numpy as np

from ..contact.edge_branch import edge_grid
from ..contact.sigma_edge import SigmaEdgeBranch, tail_between, trace_retract
from ..errors import ConvergenceError
from ..io.progress import phase

#: half-width and grading of the edge grids in units of the pilot's spacing h0 (fixed
#: across a family: one mesh density). The grading sets the spacing at the meniscus edge,
#: microns out in the graded far field: at 8 h0 the members' differences were erratic, at
#: 32 h0 they converge at order 2.00 (validation/results/sigma_edge.md)
HALF, GRADING = 24, 32
#: the family's analysis radius covers the runner's down to this fraction of the pilot's
#: fold edge radius (the family's fold may lie lower; sigma_edge.md)
LOW = 0.5
#: the pilot: edge node at c_ref = PILOT_FRACTION x the JKR contact radius at zero load
#: (Johnson 1985 eq 5.20 with P = 0: a^3 = 9 pi W R^2 / (2 E*), W the scene's work of
#: adhesion), spacing h0 = c_ref / PILOT_NODES, traced down to c_ref / PILOT_SPAN and up to
#: PILOT_SPAN_UP c_ref. (On the stiction map's slider c_ref ~ 1 um and h0 ~ 4 nm: the map
#: scan of validation/sigma_edge.py, 36 points traced, largest estimate 7.7e-4 on 3 members)
PILOT_FRACTION, PILOT_NODES, PILOT_SPAN, PILOT_SPAN_UP = 0.25, 250, 20, 8
#: the family traces up to this multiple of the pilot's c* (the largest force's edge radius)
C_HIGH = 3
#: members: at least MIN_LEVELS (Richardson needs three), at most MAX_LEVELS, the spacing
#: divided by sqrt 2 from one to the next
MIN_LEVELS, MAX_LEVELS = 3, 6
#: observed orders accepted for the extrapolation (the branch converges at 2: measured 2.00
#: on every clean family); outside - or when the last two differences change sign, which a
#: ratio of their sizes cannot see - the finest member is kept and its error bounded as if
#: the order were GUARD_ORDER: |f3 - f2| / (r^GUARD_ORDER - 1), 2.41 x the last difference
#: at r = sqrt 2. First order is the lowest the branch shows (d and F at fixed c in Hertz's
#: limit, tests/test_sigma_edge.py); a bound at a higher assumed order would under-read it
ORDER_RANGE, GUARD_ORDER = (1.5, 2.5), 1.0


def richardson(h, F):
    """(observed order, extrapolation, error estimate of the finest member) from the last
    three of F(h) (spacings in ratio r, sqrt 2 in the family). Differences of one sign with
    an order inside ORDER_RANGE extrapolate; anything else (an order outside, alternating or
    vanishing differences; the order is then nan unless one was observed) keeps the finest
    member with the bound max(|f3 - f2|, |f2 - f1| / r^q) / (r^q - 1), q = GUARD_ORDER (the
    earlier difference scaled down too, so that a last difference that happens to vanish
    does not read as no error)."""
    f1, f2, f3 = F[-3:]
    r = h[-2] / h[-1]
    q = r ** GUARD_ORDER
    bound = max(abs(f3 - f2), abs(f2 - f1) / q) / (q - 1)
    if not (f1 - f2) * (f2 - f3) > 0:
        return math.nan, f3, bound
    p = math.log((f1 - f2) / (f2 - f3)) / math.log(r)
    if not ORDER_RANGE[0] <= p <= ORDER_RANGE[1]:
        return p, f3, bound
    ext = f3 + (f3 - f2) / (r ** p - 1)
    return p, ext, abs(f3 - ext)


def branch_on(scene, c_ref, h, h0, a0):
    """The :class:`SigmaEdgeBranch` of ``scene`` on the edge grid with node k at c_ref (m),
    spacing h there, half-width HALF h0 and grading GRADING h0, analysis radius a0."""
    from ..discretisation.family import MAX_NODES
    from ..elastic import GreenOperator

    g, k = edge_grid(a0, c_ref, h, HALF * h0, GRADING * h0, max_nodes=MAX_NODES)
    op = GreenOperator(g, scene.e_star)
    return SigmaEdgeBranch(op, k, scene.sphere, scene.effects, scene.gap, scene.tolerance)


def runner_force(br, a_run):
    """F_ex (N) of a branch state on the runner's analysis disk of radius a_run: the scaled
    grid's minus the laws between a_run and the scaled analysis radius (on the undeformed
    paraboloid, :func:`~femadh.contact.sigma_edge.tail_between`)."""
    def value(st):
        return br.force(st) - tail_between(br.effects, br.sphere, st.d, a_run, br.radius(st))
    return value


def trace(scene, c_ref, h, h0, a0, a_run, c_low, c_high):
    """(branch, :class:`~femadh.contact.sigma_edge.Retract`, seconds): the retract of
    ``scene`` on the edge grid at c_ref, down to the fold (or c_low), up past the largest
    force (or c_high), the force read on the runner's disk a_run."""
    t0 = time.perf_counter()
    br = branch_on(scene, c_ref, h, h0, a0)
    res = trace_retract(br, c_ref, c_low, c_high, value=runner_force(br, a_run))
    return br, res, time.perf_counter() - t0


def work_of_adhesion(scene):
    """The scene's work of adhesion (J/m^2): minus the laws' energy at the gap sigma."""
    h = np.array([scene.gap.sigma])
    return float(-sum(np.asarray(e.energy(h))[0] for e in scene.effects.values()))


def pilot_radius(scene):
    """c_ref (m), the pilot's edge radius: PILOT_FRACTION x JKR's contact radius at zero
    load, a^3 = 9 pi W R^2 / (2 E*) (Johnson 1985 eq 5.20)."""
    W, R = work_of_adhesion(scene), scene.sphere.radius
    if not W > 0:
        raise ValueError("edge route: the scene's work of adhesion is not positive")
    return PILOT_FRACTION * (9 * math.pi * W * R * R / (2 * scene.e_star)) ** (1 / 3)


@dataclass
class Pilot:
    """The pilot trace: its edge grid's reference radius and spacing (m), the fold's and
    the largest force's edge radii (m), the retract, its seconds."""

    c_ref: float
    h0: float
    c_fold: float
    c_star: float
    retract: object
    seconds: float


def pilot(scene):
    """The pilot trace of ``scene``'s retract on the coarse edge grid (c_ref, h0 = c_ref /
    PILOT_NODES): a :class:`Pilot`, or None where d(c) has no fold down to c_ref /
    (PILOT_SPAN LOW) (the contact shrinks to nothing without a jump, or its fold lies too
    near the pilot's lowest edge radius c_ref / PILOT_SPAN for the family's traces, which
    reach down to LOW c_fold). Any other failure is raised."""
    a_run = scene.analysis_radius
    c_ref = pilot_radius(scene)
    h0 = c_ref / PILOT_NODES
    t0 = time.perf_counter()
    try:
        _, r, _ = trace(scene, c_ref, h0, h0, a_run * PILOT_SPAN, a_run, c_ref / PILOT_SPAN,
                        PILOT_SPAN_UP * c_ref)
    except ConvergenceError as exc:
        if "no fold of d(c)" in str(exc):
            return None
        raise
    if r.fold.c < c_ref / PILOT_SPAN / LOW:
        # the family traces down to LOW c_fold: a fold this near the pilot's lowest edge
        # radius was not bracketed with room below it (measured on the stiction map: at
        # sigma = 0.87-1.06 nm, p/psat 0.65-0.75 the pilot's fold at ~0.046 um is not a
        # fold of the finer members, whose traces end without one): not a fold the route
        # can stand on, the sweep decides
        return None
    return Pilot(c_ref, h0, r.fold.c, r.best.c, r, time.perf_counter() - t0)


def static_reasons(scene):
    """Why ``scene`` cannot take the edge route (a list of reasons; empty: it can, if its
    grid would follow the edge and its pilot finds a fold)."""
    out = []
    gap = scene.gap
    if gap is None or gap.contact_model != "complementarity" or gap.adhesion:
        out.append("not the sigma-gap with the complementarity model and no eq 20 adhesion")
    if scene.method != "green" or getattr(scene, "layers", ()):
        out.append("not the Green operator of the homogeneous half-space")
    if scene.continuation == "arclength" or getattr(scene, "instrument", None) is not None:
        out.append("not a displacement-controlled stepping sweep")
    if not getattr(scene, "adaptive", False):
        out.append("its grid is set by the scene ([solver] nodes or [solver.grid])")
    if "retract" not in scene.directions:
        out.append("no retract")
    if getattr(scene, "topography", None) is not None:
        out.append("a topography")
    return out


#: whether runs take the route at all (False: every run the present path; validation and
#: tests compare the two)
ENABLED = True

#: :func:`route_for`: how far the adaptive grid's first static member's band spacing may
#: exceed the spacing safe for the softening a node at the contact edge actually meets
#: (:func:`~femadh.discretisation.plan.follow_safe_spacing`: LJ and the meniscus step summed)
#: before "auto" asks the pilot. Measured on the stiction map's 25 foldable static-band
#: points (validation/results/stiction_map_auto.md, main's sweep at load 3-4.5): at a ratio
#: 1.22-2.52 (6 points) the first member's estimate was 4.4e-3-1.6e-2 and the sweep refined
#: its band 2.7-8.5x in nodes (to 604-1772): 16-90+ s on four (sigma 0.489 nm, p/psat 0.15
#: reached the map's 90-s limit in every run), 2-3 s on two; the route 3.3-5.0 s. At 1.14
#: and below (19 points) it met 1e-3 at the first member or refined at most 3.3x to <= 615
#: nodes, 0.3-6.6 s. The margin sits in that gap (1.14-1.22): a ratio just above 1 (the
#: estimate's coarsest member at the safe limit: 1.01-1.14 on the map's p/psat 0.35-0.65
#: points at sigma 0.489 nm) costs the sweep nothing
EDGE_TRAP_MARGIN = 1.2


def edge_trap_ratio(scene, member):
    """How far ``scene``'s adaptive first member for 1e-3 (``member``, the static band the
    sweep's loop runs first at that request: :func:`femadh.runner.adaptive.reference_trial`;
    the same member whatever the request) is trapped at the contact edge: its
    band spacing over the spacing safe for the softening a node at the edge meets, LJ and
    a sub-grid meniscus step summed (:func:`~femadh.discretisation.plan.follow_safe_spacing`).
    The static cap (:func:`~femadh.discretisation.plan.safe_spacing`) keeps the larger of
    the two and under-reads a meniscus edge just above sigma, which acts as a Dugdale
    cohesive zone of ~30-200 nm at the contact edge
    (:meth:`~femadh.laws.step.SmoothStepLaw.edge_softening`). On such a scene the sweep's
    estimate members unzip, its loop refines the static band by the accuracy (not by the
    trapping cap, so FOLLOW_NODES does not see it) and its retract unzips node by node on
    600-1800 nodes; the edge route traces the branch in its edge radius instead.

    Why the 1e-3 member whatever the request: the trap is the contact edge's, not the
    request's, and EDGE_TRAP_MARGIN was measured on it - the request's own first member
    shrinks as (target / 1e-3)^(1/ORDER), and at 3e-4 the ratio of sigma = 0.489 nm, p/psat
    0.15 fell to 1.11: not routed, its sweep reached the 90-s limit where the route converged
    in 6.1 CPU-s. Only a scene with a sub-grid step law (:func:`traps_at_edge`, the
    capillary condensate) is measured: without one the two softenings are one (the bundled
    Fig 3 and Fig 4 scenes: path and cost unchanged). 0 for a scene without one, or whose
    member follows the edge (the route's other test) or is refused by the node limit (the
    sweep's loop reports that)."""
    from ..discretisation.plan import follow_safe_spacing
    from ..scene import build_problem

    if not traps_at_edge(scene) or member is None or member.operator is None \
            or member.follow is not None:
        return 0.0
    problem = build_problem(scene, operator=member.operator)
    return member.spacing / follow_safe_spacing(problem)


def traps_at_edge(scene):
    """Whether ``scene`` has a sub-grid step law (a condensed meniscus) with a sigma-gap: the
    scenes :func:`edge_trap_ratio` measures."""
    return scene.gap is not None and any(getattr(law, "SUBGRID", False)
                                         for law in scene.effects.values())


def route_for(scene, follows, member=None):
    """The :class:`Pilot` that sends ``scene`` down the edge route, or None (the present
    path). ``follows``: whether the scene's adaptive grid would follow the contact edge
    (:func:`femadh.runner.adaptive._follow_trial` chose a follow band); ``member``: a
    callable giving the adaptive loop's first member for 1e-3 (built only where it is
    measured, :func:`traps_at_edge`), or None. The scene's
    ``[solver] route``: "grid" never, "auto" where its grid follows the edge or that member
    is trapped at the edge beyond EDGE_TRAP_MARGIN (:func:`edge_trap_ratio`), "edge"
    wherever it can;
    the pilot then decides. A scene the route cannot carry (:func:`static_reasons`) keeps the sweep
    whatever its route: the adaptive loop's trials and the estimate's members are such
    scenes (a grid of their own) and inherit the key."""
    route = getattr(scene, "route", "auto")
    if not ENABLED or route == "grid" or static_reasons(scene):
        return None
    if route == "auto" and not (follows or (
            member is not None and traps_at_edge(scene)
            and edge_trap_ratio(scene, member()) > EDGE_TRAP_MARGIN)):
        return None
    # ("edge" and "peak" pilot wherever the route can carry the scene)
    try:
        with phase("edge route: pilot"):
            pil = pilot(scene)
    except (ConvergenceError, ValueError):
        # a pilot that cannot be traced says nothing about the route: the sweep decides
        return None
    if pil is not None and min(scene.d_values) >= pil.retract.best.d:
        # the sweep never presses in to the largest force's contact radius: its max
        # adhesion is another state of its own curve, which only the sweep computes
        return None
    return pil


@dataclass
class EdgeFamily:
    """The family of edge grids at the pilot's c*: spacings (m), nodes, the members'
    retracts, and Richardson's order, extrapolation and error of the finest member for the
    max adhesion and the fold's d; ``met`` whether the max adhesion's relative error (grid
    part, or with ``other`` the grid part with the tail and tolerance) is within the target;
    ``stop`` why the family stopped growing."""

    h: list = field(default_factory=list)
    nodes: list = field(default_factory=list)
    runs: list = field(default_factory=list)
    seconds: list = field(default_factory=list)
    order: float = math.nan
    value: float = math.nan
    extrapolation: float = math.nan
    error: float = math.inf
    fold_order: float = math.nan
    fold_extrapolation: float = math.nan
    fold_error: float = math.inf
    met: bool = False
    stop: str = ""

    @property
    def finest(self):
        """(branch, retract) of the finest member."""
        return self.runs[-1]


def family(scene, pil, target, max_levels=None, max_nodes=None, on_member=None, other=None,
           tail_stops=True):
    """Grow the family h0 / sqrt2^j (node k at the pilot's c*, analysis radius a_run c* /
    (LOW c_fold)) until Richardson's relative error of the max adhesion is at most
    ``target``: MIN_LEVELS members at least, ``max_levels`` (default MAX_LEVELS) at most,
    no member above
    ``max_nodes`` (default the family's node limit). ``on_member(j, branch, retract)`` after
    each member. ``other(fam)``, where given, is the (tail, tolerance) parts (N) of the
    finest member: the grid part then has the target less those (the run is judged on
    their sum, as the sweep's loop refines while grid + tail exceed the target), and a tail
    above SAFETY of the target stops the family where ``tail_stops`` (``stop`` "tail": the
    disk, not the grid, falls short, and it can still grow); tail and tolerance that leave
    the grid no share stop it too. Returns an :class:`EdgeFamily` (``met`` False and ``stop`` saying why
    where the budget ended first)."""
    from ..estimate.refine import SAFETY

    from ..discretisation.family import MAX_NODES

    max_nodes = MAX_NODES if max_nodes is None else max_nodes
    max_levels = MAX_LEVELS if max_levels is None else max_levels
    a_run = scene.analysis_radius
    c_star, c_fold, h0 = pil.c_star, pil.c_fold, pil.h0
    a0 = a_run * c_star / (LOW * c_fold)
    fam = EdgeFamily()
    for j in range(max_levels):
        h = h0 / math.sqrt(2) ** j
        if j and _nodes_of(a0, c_star, h, h0) > max_nodes:
            fam.stop = f"the next member would exceed {max_nodes} nodes"
            break
        with phase(f"edge route: grid {j + 1} ({_nodes_of(a0, c_star, h, h0)} nodes)"):
            br, r, sec = trace(scene, c_star, h, h0, a0, a_run, LOW * c_fold, C_HIGH * c_star)
        fam.h.append(h)
        fam.nodes.append(br.n)
        fam.runs.append((br, r))
        fam.seconds.append(sec)
        if on_member is not None:
            on_member(j, br, r)
        if len(fam.h) >= MIN_LEVELS:
            F = [x.max_adhesion for _, x in fam.runs]
            fam.order, fam.extrapolation, fam.error = richardson(fam.h, F)
            fam.value = F[-1]
            fam.fold_order, fam.fold_extrapolation, fam.fold_error = richardson(
                fam.h, [x.fold.d for _, x in fam.runs])
            allowed = target * abs(fam.value)
            if other is not None:
                tail, tolerance = (abs(v) for v in other(fam))
                if tail_stops and tail > SAFETY * allowed:
                    fam.stop = "tail"
                    break
                allowed -= tail + tolerance
                if allowed <= 0:
                    fam.stop = "the tail and the solver tolerance leave the grid no share"
                    break
            if fam.error <= allowed:
                fam.met = True
                fam.stop = "met"
                break
    else:
        fam.stop = f"{max_levels} members (the family's budget)"
    return fam


def _nodes_of(a0, c, h, h0):
    """Node count of the edge grid (without building its operator)."""
    from ..discretisation.family import MAX_NODES

    g, _ = edge_grid(a0, c, h, HALF * h0, GRADING * h0, max_nodes=10 * MAX_NODES)
    return g.n


#: the prefix that makes a result's warning a note (printed "note: ..."; the report's NOTE):
#: what the route computes and judges is normal output, not a warning
NOTE = "error estimate: "
#: what the route judges, said in the result's notes
JUDGED = (NOTE + "edge route: the max adhesion and the pull-off separation (jump_out_d_m) are "
          "judged by the family of edge grids; the approach (jump_in_d_m, the deepest "
          "forces) is the sweep's on the adaptive grid's first member and the hysteresis "
          "is read off both jumps: computed, not estimated")


#: the curve's name for the branch's own states (each on its own scaled grid; not the
#: sweep's separations): the curve of a run that asks for the max adhesion alone
#: ([solver] route = "peak") or whose accuracy the family does not reach
CURVE = "retract_edge_branch"
#: what such a run does not give, said in the result's notes
MISSING = (NOTE + "edge route, max adhesion alone ([solver] route = 'peak', or an accuracy "
           "the family does not reach): the curve is "
           "the retract's branch traced in its edge radius (its own states, each on its own "
           "scaled grid, from deep contact to the pull-off fold); the approach, the jump-in, "
           "the jump-out's landing and the separated retract beyond it, and the surface "
           "fields are not computed: the headline numbers read from them (jump_in_d_m, "
           "hysteresis_J, the deepest forces) are absent")


def _curve(br, r, a_run):
    """(curve columns, the first state the runner's stability test rejects or None): the
    retract's states on the stable part in its order (c decreasing from deep contact, d
    increasing), up to the fold or to the last state before one that is not an energy
    minimum with its contact set held (:meth:`SigmaEdgeBranch.stable`: under displacement
    control the retract leaves the branch there, before its fold)."""
    states = [r.fold] + [s for s in r.states if s.c > r.fold.c]
    if r.best is not r.fold and all(s is not r.best for s in states):
        states.append(r.best)
    states.sort(key=lambda s: -s.c)
    force = runner_force(br, a_run)
    cols = {"d_m": [], "h0_m": [], "F_ex_N": [], "r_c_m": [], "n_iter": [],
            "residual_m": [], "converged": [], "stable": []}
    lost = None
    for s in states:
        if not br.stable(s):
            lost = s
            break
        cols["d_m"].append(s.d)
        cols["h0_m"].append(float(s.h[0]))
        cols["F_ex_N"].append(force(s))
        cols["r_c_m"].append(s.c)
        cols["n_iter"].append(s.n_iter)
        cols["residual_m"].append(s.residual)
        cols["converged"].append(True)
        cols["stable"].append(True)
    return {k: np.asarray(v, bool if k in ("converged", "stable") else
                          int if k == "n_iter" else float) for k, v in cols.items()}, lost


def _tolerance_part(br, scene):
    """The solver tolerance's share of a force error (N), as the runner's estimate has it:
    the analysis disk's area x tolerance x the largest law stiffness at the gap sigma."""
    P1 = np.abs(br._ref.dpressure(np.full(br.n, scene.gap.sigma)))
    return float(math.pi * scene.analysis_radius ** 2 * scene.tolerance * P1.max())


def _peak_only(scene, res, br, r, value):
    """The headline and curve of a run of the max adhesion alone ([solver] route = "peak"):
    the branch's own states to the fold or to the last one the runner's stability test
    keeps (:func:`_curve`), the jump-out at the fold where the sweep reaches it."""
    from .headline import headline

    best = r.best
    res.nodes = br.nodes0 * best.lam
    res.branches[CURVE], lost = _curve(br, r, scene.analysis_radius)
    if lost is not None and lost.c >= best.c:
        raise ConvergenceError(
            f"edge route: the largest force's state (c = {best.c:.6g} m, d = "
            f"{best.d * 1e9:.6g} nm) lies beyond where the branch stops being stable (c = "
            f"{lost.c:.6g} m): it is not the retract's", d=best.d, residual=math.nan,
            n_iter=0)
    _below_sweep(scene, best)
    hl = res.headline = headline(res, br._ref)
    for k in [k for k in hl if k.startswith("r_c_at_zero_force")]:
        del hl[k]
    _max_adhesion(hl, value, best, CURVE)
    if lost is None and r.fold.d > max(scene.d_values):
        _fold_beyond(scene, res, r)
    elif lost is None:
        hl["jump_out_d_m"] = float(r.fold.d)
    else:
        res.warnings.append(
            f"edge route: the branch stops being stable (the runner's test, contact set "
            f"held) at c = {lost.c * 1e6:.4g} um, d = {lost.d * 1e9:.5g} nm, before its fold "
            f"(d = {r.fold.d * 1e9:.5g} nm): the retract jumps out between d = "
            f"{res.branches[CURVE]['d_m'][-1] * 1e9:.5g} nm and that; jump_out_d_m is not "
            "given")
    res.warnings.append(MISSING)


def _full_sweep(scene, res, br, r, sink, value):
    """The headline of a routed run with the sweep's outputs: the retract at the sweep's
    separations into ``sink`` (:func:`femadh.runner.edge_sweep.trace_retract_sweep`, after
    the approach), the headline read off both branches and their jumps, the max adhesion
    and the jump-out the family's."""
    from .edge_sweep import trace_retract_sweep
    from .headline import headline

    best = r.best
    t1 = time.perf_counter()
    info = trace_retract_sweep(scene, sink, br, r)
    res.timings["retract_s"] = time.perf_counter() - t1
    if info["lost"] is not None and info["lost"] <= best.d:
        raise ConvergenceError(
            f"edge route: the largest force's state (c = {best.c:.6g} m, d = "
            f"{best.d * 1e9:.6g} nm) lies beyond where the branch stops being stable (the "
            f"runner's test at d = {info['lost'] * 1e9:.6g} nm): it is not the retract's",
            d=best.d, residual=math.nan, n_iter=0)
    _below_sweep(scene, best)
    hl = res.headline = headline(res, br._ref)
    _max_adhesion(hl, value, best, "retract")
    hl.pop("jump_out_d_m", None)
    if info["lost"] is not None:
        raise ConvergenceError(
            f"edge route: the branch stops being stable (the runner's test) at d = "
            f"{info['lost'] * 1e9:.6g} nm, before its fold (d = {r.fold.d * 1e9:.6g} nm): the "
            "retract leaves the branch there and unzips on a fixed grid, which the route "
            "does not follow; [solver] route = 'grid' sweeps it (the family's max adhesion, "
            f"on the stable side: {value:.6g} N at d = {best.d * 1e9:.6g} nm)",
            d=info["lost"], residual=math.nan, n_iter=0)
    if info["departed"] is None:
        _fold_beyond(scene, res, r)
    else:
        hl["jump_out_d_m"] = float(r.fold.d)
    res.warnings.append(JUDGED)
    return info["states"]


def _below_sweep(scene, best):
    if best.d <= min(scene.d_values):
        raise ConvergenceError(
            f"edge route: the largest force's state (d = {best.d * 1e9:.6g} nm) lies below "
            f"the sweep's deepest separation ({min(scene.d_values) * 1e9:.6g} nm): not a state "
            "the sweep reaches", d=best.d, residual=math.nan, n_iter=0)


def _max_adhesion(hl, value, best, branch):
    """Where the family's max adhesion ``value`` (N) is, into the headline ``hl`` (the value
    itself: :func:`_route`, once the branch's part is done)."""
    hl["d_at_max_adhesion_m"] = float(best.d)
    hl["max_adhesion_branch"] = branch
    hl["r_c_at_max_adhesion_m"] = best.c


def _fold_beyond(scene, res, r):
    res.warnings.append(
        f"{NOTE}edge route: the retract's fold (d = {r.fold.d * 1e9:.4g} nm) lies beyond the "
        f"sweep's end ({max(scene.d_values) * 1e9:.5g} nm): the sweep ends in contact, "
        "jump_out_d_m is not given")


def run_edge_route(scene, out_dir, pil, *, trial=None, figures=True, overwrite=False,
                   resume=False, folder_id=None, progress=False):
    """Run ``scene`` by the edge route (see the module docstring) from its pilot ``pil``:
    the approach on the adaptive grid's member ``trial`` (:mod:`femadh.runner.edge_sweep`),
    the family to the scene's target accuracy (``scene.target_accuracy``), the retract at
    the sweep's separations on the finest member's scaled grids with its jump-out landed,
    the headline numbers with their errors; written to ``out_dir`` (summary.json,
    curve.csv, fields.csv, jumps.csv, figures) as they are computed. Returns a
    ContactResult: "converged" where the estimate meets the target, else "failed" with one
    line saying what the family reached (failure kind "accuracy"). A failed trace ends the
    run "failed" naming the step; a stopped one keeps the states it committed."""
    from ..scene import scene_id
    from .edge_sweep import approach_problem, trace_approach
    from .lifecycle import lifecycle
    from .result import ContactResult, contact_summary
    from .sink import Sink

    t0 = time.perf_counter()
    target = scene.target_accuracy
    short = None
    res = ContactResult(scene.name, scene)
    # the route is recorded from the start (a run stopped in it says which it took)
    res.grid = {"kind": "edge-branch", "route": "edge-branch"}
    folder = None
    if out_dir is not None:
        from ..io.run_folder import RunFolder

        mode = "overwrite" if (overwrite or resume) else "new"
        folder = RunFolder(out_dir, folder_id or scene_id(scene), scene.name, mode,
                           given=scene.as_given)
        folder.__enter__()
        res.out_dir = str(folder.path)

    def write(status=None):
        if folder is not None:
            folder.write_summary(contact_summary(res, status))
    try:
        from .estimates import GuardError

        with lifecycle(res, write, failures=(ConvergenceError, GuardError, ValueError),
                       t0=t0) as life:
            t1 = time.perf_counter()
            user = scene
            scene, fam, grown = _grown_family(scene, pil, target)
            res.timings["family_s"] = time.perf_counter() - t1
            res.timings["pilot_s"] = pil.seconds
            if getattr(scene, "route", "auto") == "peak" or not _met(scene, fam, target):
                # the max adhesion alone (asked so, or the accuracy asked is out of the
                # family's reach: the run fails in one line before the sweep's outputs)
                short = _route(scene, res, pil, target, None, fam, grown)
                if folder is not None:
                    res.to_csv(folder.path / "curve.csv")
            else:
                t1 = time.perf_counter()
                tsc, problem = approach_problem(user, trial)
                res.nodes = problem.grid.nodes.copy()
                writer = None
                if folder is not None:
                    from ..io.writers import ContactWriter

                    writer = ContactWriter(folder, problem, vtk=scene.vtk,
                                           run_id=scene_id(scene))
                    life.cleanup(writer.close)
                sink = Sink(problem, res, writer, progress)
                trace_approach(tsc, problem, sink)
                res.timings["approach_s"] = time.perf_counter() - t1
                short = _route(scene, res, pil, target, sink, fam, grown)
                sink.close()
        if short is not None and res.status == "converged":
            # the estimate does not support the request: one line, what was reached
            res.status, res.error, res.failure_kind = "failed", short, "accuracy"
            write()
        if res.status in ("interrupted", "time limit"):
            res.warnings.append(
                "resume: the edge route keeps no states of a stopped run of the max adhesion "
                "alone (route 'peak'); --resume traces its pilot and family again"
                if getattr(scene, "route", "auto") == "peak" else
                "resume: the states the edge route committed before the stop are in the "
                "folder's files (each row whole); --resume starts the route over (its "
                "family is not checkpointed)")
            write()
        if (figures and folder is not None and res.status in ("converged", "failed")
                and any(len(b.get("d_m", ())) for b in res.branches.values())):
            from .figures import draw_figures

            # every run comes with its figure, as on the sweep path (runner/adaptive.py: a
            # signal stops them at once)
            with phase("figures"):
                draw_figures(res, folder)
            write()
    finally:
        if folder is not None:
            folder.__exit__(None, None, None)
    return res


def _error_parts(scene, fam):
    """The max adhesion's error parts (N): the family's Richardson (grid), the force beyond
    the analysis radius on the undeformed paraboloid at the largest force's d (tail: the
    runner's F_ex is read on its disk, as here) and the solver's tolerance."""
    br, r = fam.finest
    R, a_run = scene.sphere.radius, scene.analysis_radius
    h_a = np.array([r.best.d + scene.sphere.shape(a_run)])
    tail = float(-2 * math.pi * R * sum(np.asarray(e.energy(h_a))[0]
                                        for e in scene.effects.values()))
    return {"grid": fam.error, "tail": tail, "tolerance": _tolerance_part(br, scene)}


#: doublings of the analysis radius the route may make where the force beyond it is what
#: falls short (the sweep's adaptive loop doubles it likewise, runner/adaptive.py _decide)
MAX_DISK_DOUBLINGS = 3


def _grown_family(scene, pil, target):
    """(scene, family, radii grown through): the family on the scene's analysis radius, and
    where the force beyond it exceeds the share of the target the adaptive loop allows it
    (its SAFETY), on twice that radius - as the sweep's loop grows its disk - while it stays
    below half the sphere's radius (eq 4's paraboloid is a sphere only for r << R; the
    whole radius for a paraboloid profile) and at most MAX_DISK_DOUBLINGS times."""
    from ..estimate.refine import SAFETY
    from .estimates import variant

    def other(fam, scene):
        parts = _error_parts(scene, fam)
        return parts["tail"], parts["tolerance"]

    grown = []
    cap = (0.5 if scene.sphere.profile == "sphere" else 1.0) * scene.sphere.radius

    def can_grow(scene):
        # a tail stops the family only where the disk can still grow: else the grid may
        # still meet what the tail leaves
        return len(grown) < MAX_DISK_DOUBLINGS and 2 * scene.analysis_radius < cap

    fam = family(scene, pil, target, other=lambda fam: other(fam, scene),
                 tail_stops=can_grow(scene))
    while len(grown) < MAX_DISK_DOUBLINGS:
        tail = abs(_error_parts(scene, fam)["tail"])
        a = scene.analysis_radius
        if tail <= SAFETY * target * abs(fam.value) or not 2 * a < cap:
            break
        scene = variant(scene, radius=2 * a)
        grown.append(2 * a)
        with phase(f"edge route: analysis radius {2 * a * 1e6:.3g} um"):
            fam = family(scene, pil, target, other=lambda fam, sc=scene: other(fam, sc),
                         tail_stops=can_grow(scene))
    return scene, fam, grown


def _met(scene, fam, target):
    """Whether the max adhesion's estimated relative error (its parts added in magnitude)
    is within ``target``."""
    return sum(abs(v) for v in _error_parts(scene, fam).values()) <= target * abs(fam.value)


def _route(scene, res, pil, target, sink, fam, grown=()):
    """Fill ``res`` (retract, headline, estimates, grid, accuracy) from the family ``fam``
    and the retract's sweep into ``sink`` (None: the branch's own curve, the max adhesion
    alone); ``scene`` with the analysis radius the family was read on (``grown``: the radii
    it grew through, :func:`_grown_family`). Returns the one-line failure where the
    estimate does not meet ``target`` (else None)."""
    from .headline import work_of_adhesion as W_of

    a_run = scene.analysis_radius
    br, r = fam.finest
    best = r.best
    if sink is None:
        _peak_only(scene, res, br, r, fam.value)
        committed = None
    else:
        committed = _full_sweep(scene, res, br, r, sink, fam.value)
    hl = res.headline
    hl["max_adhesion_N"] = fam.value
    W = W_of(br._ref)
    hl["work_of_adhesion_J_per_m2"] = W
    # the errors (:func:`_error_parts`) added in magnitude, as the runner's estimate adds
    # its parts
    parts = {"max_adhesion_N": _error_parts(scene, fam),
             "jump_out_d_m": {"grid": float(fam.fold_error)}}
    parts = {k: v for k, v in parts.items() if k in hl}
    for k, comp in parts.items():
        comp["total"] = float(sum(abs(v) for v in comp.values()))
        hl[f"{k}_error"] = comp["total"]
    res.estimates = parts
    rel = hl["max_adhesion_N_error"] / abs(fam.value)
    res.grid = {"kind": "edge-branch", "route": "edge-branch", "nodes": fam.nodes[-1],
                "analysis_radius_m": float(br.radius(best)),
                "runner_analysis_radius_m": a_run, "edge_node": br.k,
                "analysis_radius_grown_m": list(grown),
                "approach_nodes": None if committed is None else int(res.nodes.size),
                "retract_branch_states": committed,
                "family_spacings_m": fam.h, "family_nodes": fam.nodes,
                "family_seconds": fam.seconds, "observed_order": fam.order,
                "extrapolation_N": fam.extrapolation, "fold_order": fam.fold_order,
                "fold_extrapolation_m": fam.fold_extrapolation,
                "pilot": {"c_ref_m": pil.c_ref, "spacing_m": pil.h0,
                          "c_fold_m": pil.c_fold, "c_star_m": pil.c_star,
                          "seconds": pil.seconds},
                "worst_complementarity": list(r.worst_complementarity)}
    res.accuracy = {"target": target, "met": bool(rel <= target), "adaptive": True,
                    "route": "edge-branch", "nodes": fam.nodes[-1], "members": len(fam.h),
                    "estimated_rel_error": rel, "stop": fam.stop,
                    "judged": sorted(parts)}
    # the largest adhesion within the smooth laws' bounds, as every run's (a GuardError)
    from .estimates import guard_bounds

    guard_bounds(res, br._ref)
    if rel > target:
        comp = parts["max_adhesion_N"]
        big = max(("grid", "tail", "tolerance"), key=lambda n: abs(comp[n]))
        # the family grows only the grid part's resolution: say which part is too large
        why = {"grid": f"stopped: {fam.stop}",
               "tail": (f"the largest part is the force beyond the analysis radius "
                        f"({abs(comp['tail']):.3g} N; the grid part {fam.error:.3g} N) of "
                        f"{a_run:.3g} m" + (f" (grown {len(grown)} times)" if grown else "")
                        + f": the route grows the disk at most {MAX_DISK_DOUBLINGS} times "
                        + ("and below half the sphere's radius" if scene.sphere.profile ==
                           "sphere" else "and below the sphere's radius")
                        + "; a wider [solver] "
                        "analysis_radius would reduce it"),
               "tolerance": (f"the largest part is the solver tolerance's "
                             f"({abs(comp['tolerance']):.3g} N): a tighter [solver] tolerance "
                             "would reduce it")}[big]
        return (f"accuracy {target:g} not met on the edge route: estimated relative error "
                f"{rel:.2g} of the max adhesion with {len(fam.h)} members ({fam.nodes[0]}-"
                f"{fam.nodes[-1]} nodes, {sum(fam.seconds) + pil.seconds:.3g} s); {why}")
    return None
