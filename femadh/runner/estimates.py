"""Error estimates of a contact run's headline numbers, the guards that refuse silent garbage,
and accuracy on demand.

Each headline number gets an a-posteriori estimate made of
- **discretisation**: the same scene on the coarser members of its grid family (N/2 and N/4
  nodes of a uniform grid, spacings r h and r^2 h of a banded one; FE runs: also the FE body
  against the exact Green function on the same nodes, or for a layered body, which has
  none, against the next coarser mesh of its family with
  Richardson at the P2 body's order 3 and the size ratio the two meshes actually have), the
  fine grid's error estimated by Richardson with the order observed over the three levels
  (clamped to [1, 1.5]), or by the envelope of both differences where they oscillate. A
  banded member is solved only at the states its numbers are read at, from the fine run's
  (:mod:`femadh.runner.members`); the forces at the deepest separation take members placed
  so that the contact edge sits at the fine grid's fraction of a spacing (Richardson over
  their uneven ratios) - on a uniform grid too, members uniform to the analysis radius at
  those spacings;
- **resolution in d**: the largest adhesion is the peak of the curve F_ex(d), located between
  the grid separations by a bounded scalar search on fresh states (its bracket is its error);
  a fold is located to 2^-10 of the grid step (the jump's resolution);
- **truncation at the analysis radius**: the force the laws exert beyond it on the undeformed
  far field, -2 pi R U(b(a; d)) per law (exact for the paraboloid), reported as ``F_tail``;
- **solver tolerance**: the force a change of the displacements by the tolerance makes,
  sum_k area_k |P'(h_k)| tol.
The total is the sum of their magnitudes (each is a bound or a conservative estimate of its
part; the signed parts are kept in the breakdown).

Guards (a state or a result that would be garbage is refused, not reported "converged"):
- the contact reaches the analysis radius (the disk is too small for the load);
- a node softens beyond its own stiffness (-P'(h_k) > K_kk: it snaps on its own, lattice
  trapping - the answer then depends on the mesh);
- the largest adhesion exceeds the Derjaguin-Bradley bound 2 pi R W of the scene's own work of
  adhesion W (by more than its estimated error): for smooth laws and the complementarity
  sigma-gap an elastic sphere's load-controlled pull-off lies between JKR's 1.5 and this bound.

Accuracy on demand (``[solver] accuracy``): the run doubles N (and grows the analysis radius
when the tail dominates) until the estimated error of the largest adhesion and of the force at
the deepest separation is below the target, within a budget; it says what it chose, or that
the target cannot be met.
"""
from contextlib import contextmanager
import contextvars
import math

import numpy as np

from ..contact.forces import tail_force
from .members import deepest_locked, reduced_member
# fresh states between grid states and the peak search: their own home (members and the
# instrument use them too)
from .peak import peak_adhesion
# the error machinery's one home (Richardson, the guards), re-exported for the runner
from ..estimate.guards import (EDGE_FRACTION, TRAPPING_LIMIT, BoundError,  # noqa: F401
                               GuardError, TrappingError, check_state, outside_bounds)
from ..estimate.richardson import _finite  # noqa: E402 (one home)
from ..estimate.richardson import (DECAY_ORDER, ENVELOPE_ORDER, MAX_ORDER, ORDER,  # noqa: F401
                                   discretisation)

#: convergence order of the P2 FE body in the headline forces under element-size halving
#: (observed 3.0-3.6 on layered stacks, validation/results/layered_fe.md; 3.3 homogeneous)
FE_ORDER = 3
#: the largest N accuracy mode may choose
from ..estimate.refine import UNIFORM_MAX_NODES as MAX_NODES  # noqa: E402 (its one home)
#: refinements accuracy mode may make
MAX_REFINEMENTS = 5
#: the coarser members solve only the states the headline numbers are read at, from the fine
#: run's (femadh.runner.members); False traces every member whole (the reference the reduced
#: members are tested against)
REDUCED_MEMBERS = True
#: where the members placed by the deepest state's contact edge give the forces there, the
#: family's reduced members do not solve that state (its grid part would be replaced: one
#: solve less per member); False: they solve it anyway (as before)
LOCKED_DEEPEST_ONLY = True
#: a refine loop's trial (:func:`estimate_errors` with ``defer``: the adaptive grid's) solves
#: its reduced members' folds and zero-force radii only when it is kept: where the judged
#: numbers' estimate (the largest adhesion, the forces at the deepest separation:
#: :func:`judged_errors`) misses the request, the loop refines and that
#: trial is replaced - Fig 4 at 1e-3's first trial: its estimate 0.19 -> 0.06 s. The
#: kept trial's estimate, once completed, is the same bit for bit (its grid record adds
#: ``judged_deferred``: the loop judged it on its judged numbers' breakdown). The loop's
#: decisions are those of the undeferred loop but for one case: a member whose judged part
#: reduces and whose rest does not (the rest fails and the member is traced whole) - the
#: undeferred loop traced it whole before judging, this one judges the trial on the reduced
#: member's numbers instead (counted 0 of
#: 16 reducing judged parts on the bundled scenes, validation/results/pace.md). False:
#: every trial's estimate whole
DEFER_UNJUDGED = True


def variant(scene, **changes):
    """The scene with solver changes, validated: nodes=N, method="green" (drops the FE mesh
    table), coarse_mesh=True (FE element sizes doubled), delta=... (analysis radius by its
    gap), radius=... (analysis radius, m), grid={spacing, band, grading} (a banded member,
    m)."""
    from ..scene import apply_overrides, scene_from_dict

    raw = apply_overrides(scene.raw, {})
    solver = raw.setdefault("solver", {})
    if "nodes" in changes:
        solver["nodes"] = int(changes["nodes"])
    if changes.get("method") == "green":
        solver["method"] = "green"
        solver.pop("mesh", None)
        raw.setdefault("output", {})["vtk"] = False
    if changes.get("coarse_mesh"):
        # the next coarser FE mesh of the family: element sizes doubled
        fs = scene.fe_settings
        mesh = solver.setdefault("mesh", {})
        mesh["growth"] = min(2.0, 2 * fs.growth)
        mesh["surface_fraction"] = min(1.0, 2 * fs.surface_fraction)
    if "delta" in changes:
        solver["analysis_radius"] = {"delta": f"{changes['delta']!r} m"}
    if "radius" in changes:
        solver["analysis_radius"] = f"{changes['radius']!r} m"
    if "grid" in changes:
        # a banded member (lengths in m): replaces the uniform nodes
        solver.pop("nodes", None)
        solver["grid"] = {k: f"{float(v)!r} m" for k, v in changes["grid"].items()
                          if v is not None}        # (follow: None is a static band)
    solver.pop("accuracy", None)
    raw.pop("study", None)
    out = scene_from_dict(raw, scene.path, bare_numbers=True)
    out.given = scene.as_given          # (its run folder is the user's scene's)
    return out


def refine_peak(scene, res, problem, sink):
    """The largest adhesion between the grid states (see :func:`peak_adhesion`), into the
    headline; returns the half-width of its d bracket (0 without a bracket)."""
    hl = res.headline
    if sink.peak is None or sink.peak[2] is None or sink.peak[4] is None:
        return 0.0
    branch, f_grid, prev, best, nxt = sink.peak
    F, d, half = peak_adhesion(getattr(sink, "peak_problem", problem), prev, best, nxt, scene)
    hl["max_adhesion_grid_N"] = f_grid
    hl["max_adhesion_N"], hl["d_at_max_adhesion_m"] = F, d
    hl["max_adhesion_branch"] = branch     # (the searched piece's: a fold state may lead)
    sink.peak_fold = fold_end_error(sink, res, branch, prev, best, nxt, d)
    return half


def fold_end_error(sink, res, branch, prev, best, nxt, d):
    """(resolution_m, force_N) when the refined maximum is a fold's last state (the last
    state found stable before a recorded jump), else None.

    The fold itself lies up to the jump's ``resolution_m`` beyond that state, and the
    branch's F_ex rises on to it: d_at_max_adhesion is uncertain by the resolution, and
    max_adhesion by the rise over it. Near a fold (saddle-node) F = F_f - c sqrt(d_f - d):
    dF/dd diverges there, so the secant's slope times the resolution would understate the
    rise. With the fold delta <= r beyond the state ``best`` and the grid step D to ``prev``,
    F_best - F_prev = c (sqrt(D + delta) - sqrt(delta)) >= c (sqrt(D + r) - sqrt(r)), so the
    rise c sqrt(delta) <= (F_best - F_prev) sqrt(r) / (sqrt(D + r) - sqrt(r)) (~ the secant
    times sqrt(r D): larger than the secant times r for r < D)."""
    if d != best.d or nxt.d != best.d or prev.d == best.d:
        return None                         # not at a fold's last state
    folds = getattr(sink, "pieces", {}).get(branch, [])
    k = next((i for i, (_, before, _) in enumerate(folds) if before is best), None)
    js = [j for j in res.jumps if j["branch"] == branch]
    if k is None or k >= len(js):
        return None
    r = float(js[k]["resolution_m"])
    if not r > 0:                           # (an arclength fold: located exactly)
        return None
    step = abs(best.d - prev.d)
    rise = abs(best.f_ex - prev.f_ex) * math.sqrt(r) / (math.sqrt(step + r) - math.sqrt(r))
    return r, float(rise)


def _mesh_size_ratio(scene, coarse):
    """h_coarse / h_fine of a layered scene's FE mesh and its coarser variant, from their
    triangle counts (2D: h ~ n^(-1/2)); 1.0 when the meshes are the same.

    The doubled growth and surface fraction coarsen the body's depth and far field, but not
    its loaded surface: the grid's nodes and annulus edges are mesh vertices, and thin
    layers keep their radial resolution. The measured ratio (~1.3-1.6, not 2) is what the
    Richardson factor must use; the surface part is in the grid estimate (N/2, N/4 coarsen
    those vertices)."""
    from ..elastic import RadialGrid
    from ..elastic.fe.layers import as_layer
    from ..elastic.fe.mesh import cached_mesh, read_mesh
    from ..elastic.fe.operator import mesh_spec

    def spec_and_count(sc):
        spec = mesh_spec(RadialGrid.uniform(sc.analysis_radius, sc.nodes), sc.fe_settings,
                         tuple(as_layer(x) for x in sc.layers), sc.disk)
        return spec, len(read_mesh(cached_mesh(spec))[1])

    (s_f, n_f), (s_c, n_c) = spec_and_count(scene), spec_and_count(coarse)
    return 1.0 if s_f == s_c else math.sqrt(n_f / n_c)


#: the accuracy the adaptive loop judges the trial being run by (:func:`deferring`)
_DEFER = contextvars.ContextVar("femadh_defer_estimate", default=None)


@contextmanager
def deferring(target):
    """Within the block, a contact run's :func:`estimate_errors` gets ``defer`` = ``target``
    (an adaptive loop's trial: :mod:`femadh.runner.adaptive`; None: the whole estimate at
    once). The run reads it once (:func:`deferred_target`) and runs its members without it."""
    token = _DEFER.set(target)
    try:
        yield
    finally:
        _DEFER.reset(token)


def deferred_target():
    """The ``defer`` of the run being made (:func:`deferring`), or None."""
    return _DEFER.get()


def judged_errors(res):
    """(grid-like relative error, tail relative error) of the headline forces an adaptive
    trial is judged by - the largest adhesion and the forces at the deepest separation -
    relative to each (floored at 1e-3 of the largest); (inf, inf) where a part could not be
    estimated. The refine loop's criterion (femadh.runner.accuracy, .adaptive) and the
    deferred estimate's (:func:`estimate_errors`) - one home, here."""
    hl, est = res.headline, res.estimates
    scale = max(abs(hl.get("max_adhesion_N", 0.0)), abs(hl.get("F_ex_deepest_N", 0.0)),
                abs(hl.get("F_LJ_deepest_N", 0.0)), 1e-300)
    grid, tail = 0.0, 0.0
    for q in ("max_adhesion_N", "F_ex_deepest_N", "F_LJ_deepest_N"):
        comp = est.get(q, {})
        if not all(math.isfinite(comp.get(part, 0.0)) for part in ("total", "tail")):
            # a part that could not be estimated: the error is unknown, never "met" (max()
            # would drop a NaN silently)
            return math.inf, math.inf
        ref = max(abs(hl.get(q, 0.0)), 1e-3 * scale)
        grid = max(grid, (comp.get("total", 0.0) - comp.get("tail", 0.0)) / ref)
        tail = max(tail, comp.get("tail", 0.0) / ref)
    return grid, tail


def estimate_errors(scene, res, problem, sink, half=0.0, *, run, defer=None):
    """Fill ``res.headline`` with ``<quantity>_error`` entries and return the breakdown
    {quantity: {component: value}} (see the module docstring); ``half`` is the peak's d
    bracket (:func:`refine_peak`); ``run`` runs the coarser members
    (:func:`femadh.runner.run.run`).

    ``defer``: the relative accuracy a refine loop judges this run by
    (:func:`judged_errors`: the largest adhesion and the forces at the
    deepest separation), or None. With it (and DEFER_UNJUDGED), the reduced members first
    solve only what those numbers need (:meth:`~femadh.runner.members.ReducedMember.judged`);
    where their estimate already misses ``defer``, the loop refines or fails, and the rest
    (the members' folds, hysteresis and zero-force radii) is left to
    ``res.pending_estimate``, which :func:`complete_estimate` runs for the run the loop
    keeps: the same numbers and breakdown, bit for bit, as without ``defer`` (and
    ``res.grid["judged_deferred"]``). The loop's judgement of such a trial can differ from
    one without ``defer`` only where a member's judged part reduces and its rest does not
    (traced whole on completion, where without ``defer`` the trial is judged on the whole
    trace: see :data:`DEFER_UNJUDGED`). Where the estimate meets ``defer`` the rest is done
    at once."""
    import time
    import warnings

    from ..errors import MeshResolutionWarning
    t0 = time.perf_counter()
    _run_quiet = run

    def run(*a, **kw):
        # the coarser members are coarse on purpose: their resolution warnings are noise
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", MeshResolutionWarning)
            return _run_quiet(*a, **kw)

    hl = res.headline
    parts = {}
    if half:
        parts.setdefault("d_at_max_adhesion_m", {})["resolution"] = half
    fold = getattr(sink, "peak_fold", None)
    if fold is not None:
        # the maximum at a fold's last state: the fold (and the branch's F_ex on to it) lies
        # within the jump's resolution beyond it (:func:`fold_end_error`)
        parts.setdefault("d_at_max_adhesion_m", {})["fold_resolution"] = fold[0]
        parts.setdefault("max_adhesion_N", {})["fold_resolution"] = fold[1]
    # a largest adhesion read off the sweep's peak where a sub-grid step's cohesive zone acts
    # at the contact edge (on the peak's problem): the run says that the sigma-edge branch
    # ([solver] route = "peak") reads the same limit. No part is added for the edge's
    # node-release sawtooth: its tips are the branch's states, and the coarser members bound
    # the sweep's error (:func:`cohesive_edge`; issue 21's lattice part was refuted and
    # deleted: validation/results/effectivity.md, session 11)
    if "max_adhesion_N" in hl and getattr(sink, "peak", None) is not None \
            and cohesive_edge(getattr(sink, "peak_problem", problem)):
        res.warnings.append(COHESIVE_NOTE)
    # discretisation: the coarser members of the grid family (and, for FE, the exact Green;
    # a layered body has none: its mesh part is the difference to the next coarser mesh,
    # Richardson with the P2 body's observed order 3 - validation/results/layered_fe.md)
    fine_hl = dict(hl)
    layered = bool(getattr(scene, "layers", ()))
    green = {"method": "green"} if scene.method == "fe" and not layered else {}
    if scene.method == "fe":
        other = variant(scene, **(green or {"coarse_mesh": True}))
        ratio = _mesh_size_ratio(scene, other) if layered else None
        if ratio is not None and ratio < 1.1:
            res.warnings.append("FE mesh estimate: the next coarser mesh of the family is "
                                "(nearly) the scene's own ([solver.mesh] growth and "
                                "surface_fraction at their caps): its mesh error is not "
                                "estimated")
            g = None
        else:
            _part("Green function" if green else "coarser mesh")
            g = run(other, progress=False, estimate="peak")
        _stop_if_stopped(g)
        if g is not None and g.status == "converged":
            # layered: Richardson at the P2 body's order over the meshes' size ratio (the
            # error machinery's one Richardson); else the exact Green function's difference
            mesh = (discretisation(hl, g.headline, ratio=ratio, order=FE_ORDER) if layered
                    else fe_against_green(hl, g.headline))
            for k, v in mesh.items():
                parts.setdefault(k, {})["fe_mesh"] = v
            if not layered:
                fine_hl = dict(g.headline)       # the grid part: the Green function's in N
        elif g is not None:
            other_run = "coarser-mesh run" if layered else "Green-function run on the same nodes"
            res.warnings.append(f"{NOTE}the {other_run} did not converge "
                                f"({_short(g.error)}); the FE mesh part of the error is not "
                                "estimated: the stated errors lack it")
    ratio, members, ratio2 = coarser_members(scene, problem, green)
    decay = decay_order(problem, ratio * (ratio2 or ratio))
    # the forces at the deepest separation: members placed by its contact edge (the same
    # fraction of a spacing as the fine grid's), where they can be; the family's reduced
    # members then skip that state (its grid part would be replaced)
    locked = deepest_locked(scene, problem, sink, ratio, variant) \
        if REDUCED_MEMBERS and members else None
    deepest = locked is None or not LOCKED_DEEPEST_ONLY

    def assemble(parts, levels, solved, since=t0):
        """The breakdown from the members' headline ``levels`` (the parts above, the grid
        part, the folds' resolution, the tail, the tolerance), ``res.grid``'s member record
        and the headline's ``_error`` entries."""
        res.grid["member_solves"] = solved
        res.grid["member_ratio"] = ratio
        if ratio2 is not None:
            res.grid["member_ratio2"] = ratio2
        res.grid["members"] = [lb for lb, _ in members][:len(levels)]
        if scene.grid is not None:
            res.grid["member_spacings_m"] = [m.grid["spacing"]
                                             for _, m in members][:len(levels)]
        if levels:
            for k, v in discretisation(fine_hl, levels[0],
                                       levels[1] if len(levels) > 1 else None,
                                       ratio=ratio, ratio2=ratio2, decay_order=decay).items():
                parts.setdefault(k, {})["grid"] = v
        if locked is not None and levels:
            (h1, h2), (lv1, lv2) = locked
            h0 = float(problem.grid.nodes[1])
            for k, v in discretisation({k: fine_hl[k] for k in lv1 if k in fine_hl}, lv1, lv2,
                                       ratio=h1 / h0, ratio2=h2 / h1,
                                       decay_order=decay_order(problem, h2 / h0)).items():
                parts.setdefault(k, {})["grid"] = v
            if scene.grid is not None:
                res.grid["deepest_member_spacings_m"] = [h1, h2]
                res.grid["deepest_members"] = [lv1, lv2]
            else:
                # a uniform grid's record is the scene's N, state-free: the placed members
                # follow the deepest state (a resume re-solves it to the tolerance), so only
                # that they were used is recorded
                res.grid["deepest_members_placed"] = True
        # folds: located to the jump's resolution
        for name, branch in (("jump_in_d_m", "approach"), ("jump_out_d_m", "retract")):
            js = [j for j in res.jumps if j["branch"] == branch]
            if js and name in hl:
                parts.setdefault(name, {})["resolution"] = float(js[0 if branch == "approach"
                                                                    else -1]["resolution_m"])
        # truncation at the analysis radius and the solver tolerance, for the forces
        for name, d_key in (("max_adhesion_N", "d_at_max_adhesion_m"),
                            ("F_ex_deepest_N", "d_deepest_m"),
                            ("F_LJ_deepest_N", "d_deepest_m")):
            if name in hl and d_key in hl:
                # the missing attraction beyond a: the exact value exceeds the truncated one
                parts.setdefault(name, {})["tail"] = tail_force(problem, hl[d_key])
                parts[name]["tolerance"] = float(problem.areas.sum() * scene.tolerance
                                                 * np.max(np.abs(problem.dpressure(
                                                     np.full(1, _contact_gap(problem))))))
        # the instrument's readout between the computed states (femadh.instrument.readout)
        if res.instrument is not None:
            for name, v in res.instrument["resolution"].items():
                if f"instrument_{name}" in hl:
                    parts.setdefault(f"instrument_{name}", {})["resolution"] = float(v)
        parts = {k: v for k, v in parts.items() if k in QUANTITIES and k in hl}
        for k, comp in parts.items():
            # the parts are signed estimates of Q_exact - Q (grid, fe_mesh, tail) or bounds
            # (resolution, tolerance); they are added in magnitude: the grid and tail
            # estimates can cancel where the true errors do not, so the total is an upper
            # estimate
            comp["total"] = float(sum(abs(v) for v in comp.values()))
            hl[f"{k}_error"] = comp["total"]
        # the error estimate alone (the members, the tail, ...): estimate_s also holds the
        # peak search, which locates the headline's largest adhesion itself
        res.timings["error_estimate_s"] = time.perf_counter() - since
        return parts

    if defer is not None and DEFER_UNJUDGED and REDUCED_MEMBERS and members:
        return _deferred(scene, res, problem, sink, members, deepest, defer, parts, run,
                         assemble)
    levels = []
    solved = []
    for i, (label, member) in enumerate(members):
        _part(_member_label(i, members))
        # the member solved only where the headline numbers are read, from the fine run's
        # states (femadh.runner.members); traced whole where it cannot stand in
        hl_m, how = (reduced_member(scene, member, problem, sink, res, deepest=deepest)
                     if REDUCED_MEMBERS else (None, "reduced members off"))
        if hl_m is not None:
            levels.append(hl_m)
            solved.append({"member": label, "reduced": True, "solves": how})
            continue
        r = run(member, progress=False, estimate="peak")
        _stop_if_stopped(r)
        solved.append({"member": label, "reduced": False, "why": how})
        if r.status != "converged":
            res.warnings.append(member_note(label, r.error, _fine_label(scene, problem),
                                            [lb for lb, _ in members[:i]]))
            res.grid["failed_member"] = {"member": label, "error": r.error}
            break
        levels.append(dict(r.headline))
    return assemble(parts, levels, solved)


def _deferred(scene, res, problem, sink, members, deepest, target, parts, run, assemble):
    """:func:`estimate_errors`' members with ``defer`` = ``target``: each member's judged
    numbers first (:meth:`~femadh.runner.members.ReducedMember.judged`; traced whole where it
    cannot stand in, as without ``defer``), the breakdown of those, and the rest where the
    judged estimate meets ``target``; else ``res.pending_estimate`` holds the rest (see
    :func:`complete_estimate`). Returns the breakdown (the partial one where deferred)."""
    import copy
    import time
    from types import SimpleNamespace

    records = []
    for i, (label, member) in enumerate(members):
        r = rm = None
        _part(_member_label(i, members))
        hl_m, how = reduced_member(scene, member, problem, sink, res, deepest=deepest,
                                   rest=False)
        if hl_m is None:
            r = run(member, progress=False, estimate="peak")
        else:
            rm, how = how, None
        _stop_if_stopped(r)
        records.append((label, member, rm, how, r))
        if r is not None and r.status != "converged":
            break                       # as without defer: no member after a failed one

    def settle(judged_only):
        """(levels, solved) as :func:`estimate_errors`' loop makes them, in its order: a
        reduced member's rest (unless ``judged_only``), else its whole trace; a failed whole
        trace ends the members (its note only with the rest: the judged-only breakdown
        is a refined trial's, replaced)."""
        levels, solved = [], []
        for i, (label, member, rm, how, r) in enumerate(records):
            if rm is not None:
                if not judged_only:
                    # (the judged numbers alone are at hand: nothing solved, nothing shown)
                    _part(_member_label(i, members))
                hl_m, how = ((rm.hl, rm.m.solves) if judged_only else
                             reduced_member(scene, member, problem, sink, res,
                                            deepest=deepest, resume=rm))
                if hl_m is None:
                    r = run(member, progress=False, estimate="peak")
                if hl_m is not None:
                    levels.append(hl_m)
                    solved.append({"member": label, "reduced": True, "solves": how})
                    continue
                _stop_if_stopped(r)
            solved.append({"member": label, "reduced": False, "why": how})
            if r.status != "converged":
                if not judged_only:
                    res.warnings.append(member_note(label, r.error,
                                                    _fine_label(scene, problem),
                                                    [lb for lb, _ in members[:i]]))
                    res.grid["failed_member"] = {"member": label, "error": r.error}
                break
            levels.append(dict(r.headline))
        return levels, solved

    # what the rest starts from, as estimate_errors' loop would: the parts before the
    # members, the headline without its errors, the grid record without the members'
    start = copy.deepcopy(parts), dict(res.headline), dict(res.grid)

    def complete(spent=None):
        """The whole breakdown (the headline's and the grid record's entries replaced);
        ``spent``: the seconds the estimate took before (None: completed at once)."""
        t1 = time.perf_counter()
        parts0, hl0, grid0 = start
        res.headline.clear()
        res.headline.update(hl0)
        res.grid.clear()
        res.grid.update(grid0)
        out = assemble(copy.deepcopy(parts0), *settle(False),
                       **({} if spent is None else {"since": t1}))
        if spent is not None:
            res.timings["error_estimate_s"] += spent
            # the loop judged this trial on its judged numbers' breakdown (DEFER_UNJUDGED:
            # where a member's rest is traced whole, not as the undeferred loop judges it)
            res.grid["judged_deferred"] = True
        return out

    partial = assemble(copy.deepcopy(parts), *settle(True))
    grid_e, tail_e = judged_errors(SimpleNamespace(headline=res.headline, estimates=partial))
    if not grid_e + tail_e > target or all(rm is None for _, _, rm, _, _ in records):
        # met (or nothing to defer): the run may be kept, its estimate is made whole now
        return complete()
    spent = res.timings["error_estimate_s"]

    def abandon():
        """The result as a run stopped in its members leaves it: no breakdown, no
        ``_error`` entries, no member record."""
        parts0, hl0, grid0 = start
        res.headline.clear()
        res.headline.update(hl0)
        res.grid.clear()
        res.grid.update(grid0)
        res.estimates = {}

    def pending():
        return complete(spent)
    pending.abandon = abandon
    res.pending_estimate = pending
    return partial


#: the warning of a kept adaptive trial whose deferred estimate was not completed
NOT_COMPLETED = ("error estimate not completed ({why}): the coarser members' folds, "
                 "hysteresis and zero-force radii were deferred (the trial's judged numbers "
                 "missed the request) and the run ended before they were solved; no error "
                 "estimate is stated")


def complete_estimate(res):
    """Complete ``res``'s deferred estimate (:func:`estimate_errors` with ``defer``), if it
    has one: the run a refine loop keeps (its last) gets the estimate it would have had
    without ``defer`` (bit for bit where each reduced member's rest reduces as its judged
    part did, see :data:`DEFER_UNJUDGED`). This runs outside the run's lifecycle
    (:mod:`femadh.runner.lifecycle`), so it ends ``res`` itself:

    - ``res`` not "converged" or "failed" (stopped after its estimate): nothing is solved;
    - a stop (signal, time limit: :class:`~femadh.errors.Interrupted`) while completing:
      ``res`` is stopped (status, error, exit code as the lifecycle sets them); one that
      arrived after the completion's last safe point stops it too, its estimate kept (as
      the lifecycle's last check leaves a run's);
    - any other exception: ``res`` "failed", ``error`` "Type: message", and the exception
      is raised again (the caller writes the summary first).

    Where the estimate is not completed, ``res`` is left as a run stopped in its members
    leaves it (``estimates`` empty, no ``_error`` entries in the headline, no member
    record) with a warning (:data:`NOT_COMPLETED`). The completion's seconds are added to
    ``timings["estimate_s"]`` and ``["total_s"]``. Returns ``res``."""
    import time

    pending = getattr(res, "pending_estimate", None)
    if pending is None:
        return res
    res.pending_estimate = None
    from ..errors import Interrupted

    def abandon(why):
        undo = getattr(pending, "abandon", None)
        if undo is not None:
            undo()
        else:
            res.estimates = {}
            for k in [k for k in res.headline if k.endswith("_error")]:
                del res.headline[k]
        res.warnings.append(NOT_COMPLETED.format(why=why))

    if res.status not in ("converged", "failed"):
        abandon(f"the run was {res.status} before it")
        return res
    from .. import interrupt

    t0 = time.perf_counter()
    done = False
    try:
        res.estimates = pending()
        done = True
        # a signal that arrived after the completion's last safe point is still a stop
        # (as the lifecycle's last check: never "converged" once the user asked to stop;
        # it was lost - a Ctrl-C after the last member's rest ended the run as if unsent)
        interrupt.check()
    except Interrupted as exc:
        res.stop(exc)
        if not done:
            abandon(res.error)
    except BaseException as exc:
        # a bug, a full disk: the summary must not say "converged" (as the lifecycle's)
        res.fail(f"{type(exc).__name__}: {exc}" if str(exc) else type(exc).__name__)
        abandon(res.error)
        raise
    finally:
        spent = time.perf_counter() - t0
        for key in ("estimate_s", "total_s"):
            res.timings[key] = res.timings.get(key, 0.0) + spent
    return res


def cohesive_edge(problem):
    """True where a sub-grid step law (the capillary condensate, :mod:`femadh.contact.subgrid`)
    has its edge just above the sigma floor and softens, by its secant across that edge
    (:meth:`~femadh.laws.step.SmoothStepLaw.edge_softening`: a Dugdale cohesive zone at the
    contact edge), more than every collocated law does at its steepest
    (:meth:`~femadh.contact.problem.ContactProblem.surface_force_stiffness`).

    There the contact edge's node releases make F_ex(d) a sawtooth (each release a
    micro-fold: the tip is the state where the edge node's multiplier vanishes, the trough
    after the landing) and the peak search reads a tooth's tip. Measured on the stiction
    map's sigma = 0.3 + 1.7/9 nm, p/psat 0.15 point (secant 9.8e17 Pa/m against LJ's
    2.77e17; validation/results/sigma_edge_limits.md): the tips are the sigma-edge branch's
    states on the fixed grid (the junctions, to 5 digits of the error or a scan step below)
    wherever the edge sits in a cell (f = 0, 1/4, 1/2, 3/4 of a 4.04-nm cell: the branch's
    maximum the same to 3e-6 of the force, the troughs 8.5e-4 below), so the sweep's maximum
    converges with the branch's: both grid families converge at order 2, their limits
    within ~2e-5 of the force of each other (1.5e-6 or 1.6e-5, by which three of the sweep
    family's members are extrapolated), and on that point the coarser members alone bounded the sweep's error:
    effectivity 1.68, 1.34, 2.45, 1.47, 1.31 at band spacings 8.08 ... 2.02 nm (one point's
    measurements, and scattered: ulp-level changes of its input move the 4.04-nm value
    between 1.56 and 2.45, 2.50 before the Green operator's AGM kernel)."""
    from ..laws.step import SmoothStepLaw

    if problem.sigma is None:
        return False
    steps = [law for law in problem.effects.values()
             if isinstance(law, SmoothStepLaw) and getattr(law, "SUBGRID", False)]
    if not steps:
        return False
    secant = max(law.edge_softening(problem.sigma) for law in steps)
    return secant > 0 and secant > problem.surface_force_stiffness()[2]


def fe_against_green(fe, green):
    """{name: Q_Green - Q_FE}: the FE body's error of each number where the exact Green
    function on the same nodes gives the body without its mesh (finite floats only)."""
    return {k: green[k] - v for k, v in fe.items()
            if _finite(v) and _finite(green.get(k))}


def _stop_if_stopped(member):
    """A member stopped by a signal or the time limit stops the run: its estimate would be
    degraded, and the run must end "interrupted" (exit 130/143), never "converged" with a
    warning."""
    if member is None or member.status not in ("interrupted", "time limit"):
        return
    from ..errors import Interrupted, TimeLimitReached

    code = getattr(member, "exit_code", 130)
    if member.status == "time limit":
        from ..interrupt import time_limit

        raise TimeLimitReached(time_limit() or 0.0)
    raise Interrupted(code - 128)


def _part(label):
    """The run's progress display names this part of its estimate phase (a no-op when none
    is shown): the estimate is one phase of the run (:func:`femadh.runner.contact._finish`,
    a deferred rest's :func:`femadh.runner.adaptive.run_adaptive`), its members parts of it,
    so the line does not fall back to the grid's sweep between them."""
    from ..io.progress import part

    part(label)


def _member_label(i, members):
    """"member 2/2 (spacing 61.87 nm)": the i-th (0-based) of the estimate's members."""
    return f"member {i + 1}/{len(members)} ({members[i][0]})"


def _fine_label(scene, problem):
    """The run's own grid as the members are labelled: "N = 200" or "spacing 25.1 nm"."""
    g = problem.grid
    if g.fine_radius is None:
        return f"N = {g.n}"
    return f"spacing {float(g.nodes[1]) * 1e9:.4g} nm"


#: the prefix report.py prints as "note:" (see femadh.runner.report.NOTE)
NOTE = "error estimate: "

#: what a run where :func:`cohesive_edge` holds says (a note: normal output)
COHESIVE_NOTE = (
    f"{NOTE}a sub-grid step's cohesive zone acts at the contact edge: the sweep reads the "
    "largest adhesion on the node-release sawtooth of the contact edge, whose tips are the "
    "sigma-edge branch's states on this grid; [solver] route = \"peak\" traces that branch in "
    "the edge radius and reads the same limit (checked on one point, the stiction map's "
    "sigma = 0.48889 nm (0.3 + 1.7/9), p/psat 0.15: both converge at order 2 to one value, "
    "where the coarser members' estimate covered the sweep's error; "
    "validation/results/sigma_edge_limits.md)")


def _short(error):
    """The first clause of a solver error (what stopped, without the numbers)."""
    why = str(error).split(":")[0].split(";")[0].strip()
    return why if len(why) <= 60 else why[:57].rstrip() + "..."


def member_note(label, error, fine, used):
    """What a failed coarse member means for the estimate, in plain words: which member did
    not converge (the first clause of its error), where the grid part of the error comes
    from instead, and whether the stated error still holds."""
    why = _short(error)
    head = f"{NOTE}the {label} member did not converge ({why})"
    if used:
        return (f"{head}; the grid error is taken from {fine} and {' and '.join(used)} "
                "at first order (the cautious order when no third member shows the observed "
                "one)")
    return (f"{head}; no coarser member converged, so the stated errors lack the grid part "
            "(tail, resolution and tolerance only): treat them as lower bounds")


def _contact_gap(problem):
    return problem.sigma if problem.sigma is not None else 0.5e-9


def guard_bounds(res, problem):
    """Refuse a largest adhesion beyond the Derjaguin-Bradley bound 2 pi R W (by more than its
    estimated error) where that bound holds: smooth laws or the complementarity sigma-gap
    without eq 20 on the contact set."""
    hl = res.headline
    if problem.contact_model == "hertz-closure" or (problem.gap is not None
                                                    and problem.gap.adhesion):
        return
    if "max_adhesion_N" not in hl or "dmt_pull_off_N" not in hl:
        return
    F, bound, err = hl["max_adhesion_N"], hl["dmt_pull_off_N"], hl.get("max_adhesion_N_error", 0)
    if outside_bounds(F, err, upper=bound):
        raise BoundError(
            f"the largest adhesion {F:.6g} N (estimated error {err:.2g} N) exceeds the "
            f"Derjaguin-Bradley bound 2 pi R W = {bound:.6g} N of the scene's work of "
            f"adhesion W = {hl['work_of_adhesion_J_per_m2']:.4g} J/m^2: the discretisation is "
            "too coarse for these surface forces; raise [solver] nodes (or set [solver] "
            "accuracy)")


#: a uniform grid whose N/4 member would soften beyond the plan's TRAP_SAFE (its softening
#: ratio 4x the run's own) takes members at N/sqrt2 and N/2 instead of N/2 and N/4
#: (:func:`uniform_member_nodes`). False: N/2 and N/4 always (as before)
UNIFORM_SQRT2_MEMBERS = True


def decay_order(problem, spread):
    """DECAY_ORDER where the coarser difference may bound the finest
    (:func:`femadh.estimate.richardson.discretisation`), else None. Two conditions:

    - a sigma-gap contact (``problem.sigma``): its nodes join and leave the contact one at a
      time, so a number read off a fixed grid carries a sawtooth in the spacing, and a finest
      difference far below the coarser one is its phase, not a fast order (Fig 3 and the
      slider, validation/results/effectivity_spread.md). The paper's Hertz closure (its
      contact radius continuous, no node-release sawtooth) is a sigma-gap model too and keeps
      the bound on measurement: Fig 3 at N = 200, F_ex at the deepest state 3x its error with
      it, 0.1x without (session 14's review). Without a sigma-gap the numbers are smooth
      and may converge faster than second order: the AFM tip of validation/paper2_afm.py
      (R = 20 nm, p/psat 0.8, LJ without sigma) falls by 15.6 and 11.9 per halving from
      N = 120 to 480 (order ~3.7), and the bound made its pull-off's estimate 210x its error
      instead of 6x;
    - the coarsest member (spacing ``spread`` x the run's) softens no more than TRAP_SAFE of
      a node's stiffness (a member's trapping ratio grows like its spacing,
      :func:`uniform_member_nodes`), i.e. it is inside the asymptotic range: the plan keeps a
      banded family's coarsest member there; an explicit grid's may not be (the Fig 4
      scene's N = 200 has its N/2 member at 0.48).

    Measured on uniform grids (validation/results/effectivity_spread_uniform.md): the slider
    at N = 100 (sigma-gap, N/4 at 0.27) read F_LJ at the deepest state at 0.06x its error
    without the bound."""
    if problem.sigma is None:
        return None
    return DECAY_ORDER if member_safe(problem, spread) else None


def member_safe(problem, spread):
    """Whether a member of the run's family at ``spread`` x its spacing softens no more
    than TRAP_SAFE of a node's stiffness: a member's trapping ratio
    (:func:`femadh.discretisation.plan.trapping_ratio`) grows like its spacing. The one
    test of an estimate's coarsest member (:func:`uniform_member_nodes`,
    :func:`decay_order`)."""
    from ..discretisation.plan import TRAP_SAFE, trapping_ratio

    return trapping_ratio(problem) * spread <= TRAP_SAFE


def uniform_member_nodes(problem, n):
    """(N1, N2) of a uniform grid's two coarser members: N/2 and N/4, or round(N/sqrt2) and
    N/2 where the N/4 member would soften beyond TRAP_SAFE.

    A member's trapping ratio (:func:`femadh.discretisation.plan.trapping_ratio`) grows like
    its spacing, a / (N - 1/2): the Fig 4 scene's N = 200 run (0.24) has its N = 100 and
    N = 50 members at 0.48 and 0.96 of a node's own stiffness; they land micro-jump after
    micro-jump and made the largest adhesion's grid part 3.2x its error and the pull-off's 6
    lattice steps (validation/results/effectivity.md, sec 3-4). The plan keeps a banded
    family's coarsest member below TRAP_SAFE (:func:`~femadh.discretisation.plan.safe_spacing`);
    an explicit N gets the finer pair where its N/4 would not be."""
    quarter_safe = n // 4 >= 1 and member_safe(problem, (n - 0.5) / (n // 4 - 0.5))
    if UNIFORM_SQRT2_MEMBERS and not quarter_safe:
        return int(round(n / 2**0.5)), n // 2
    return n // 2, n // 4


def coarser_members(scene, problem, green=None):
    """(ratio r, [(label, scene)], ratio2) of the two coarser members of the scene's grid
    family; ratio2 is the second member's spacing over the first's where it differs from r
    (else None).

    Uniform grids: N/2 and N/4 (r = 2), or N/sqrt2 and N/2 where N/4 would be near-trapped
    (:func:`uniform_member_nodes`; r and ratio2 the spacings' actual ratios,
    (N - 1/2) / (N1 - 1/2) and (N1 - 1/2) / (N2 - 1/2)). Banded grids: spacings r h and r^2 h
    of the same family (same band, grading and radius), r = sqrt 2
    (:func:`femadh.discretisation.plan.member_ratio`): members that stay asymptotic and,
    with the adaptive plan's spacing cap, below the trapping limit (a lattice-trapped member
    lands fold after fold and makes the estimate pessimistic: the Fig 4 scene's uniform
    N = 50 and 100 members, effectivity 9.8)."""
    green = green or {}
    if scene.grid is None:
        n = scene.nodes
        n1, n2 = uniform_member_nodes(problem, n)
        out = [(f"N = {k}", variant(scene, nodes=k, **green)) for k in (n1, n2) if k >= 8]
        if n1 == n // 2:
            return 2.0, out, None
        return (n - 0.5) / (n1 - 0.5), out, (n1 - 0.5) / (n2 - 0.5)
    from ..discretisation.plan import member_ratio

    r = member_ratio(problem)
    g = scene.grid
    out = []
    for k in (1, 2):
        h = g["spacing"] * r**k
        if h > g["band"] / 8:
            break
        out.append((f"spacing {h * 1e9:.4g} nm", variant(scene, grid={**g, "spacing": h})))
    return r, out, None


QUANTITIES = ("max_adhesion_N", "F_LJ_deepest_N", "F_ex_deepest_N", "jump_in_d_m",
              "jump_out_d_m", "hysteresis_J", "r_c_at_zero_force_approach_m",
              "r_c_at_zero_force_retract_m", "d_at_max_adhesion_m",
              "instrument_pull_off_N", "instrument_snap_off_N", "instrument_jump_in_d_m",
              "instrument_jump_in_z_m", "instrument_jump_out_d_m", "instrument_jump_out_z_m",
              "instrument_hysteresis_J")
