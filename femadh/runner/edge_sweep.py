"""The sweep of a routed run (:mod:`femadh.runner.edge_route`): the outputs every contact run
gives - the approach with its jump-in, the retract at the sweep's separations with its
jump-out and landing, curve.csv, fields.csv, jumps.csv - written through the run's
:class:`~femadh.runner.sink.Sink` like any run's.

- The approach is the sweep's own (:func:`femadh.runner.tracing.trace_steps` with the
  approach alone), on the adaptive grid's first member (its static band, or the band that
  follows the edge where the scene's would), its jump-in located and landed by the stepping
  solver.
- The retract's states at the sweep's separations from its deepest up to the pull-off fold
  are states of the branch traced in its edge radius (the family's finest member,
  :mod:`femadh.contact.sigma_edge`): each placed at its separation on its own scaled grid
  (:func:`~femadh.contact.sigma_edge.state_at_separation`) and polished there by the runner's
  corrector (:func:`~femadh.contact.sigma_edge.runner_state`: a solution of the runner's
  equations with its convergence and stability flags), committed with the grid exchanged to
  it (fields.csv's r column says which).
- The jump-out: from the runner's state at the fold's separation d_f the surface is landed by
  :func:`femadh.contact.landing.land` (energy descent, polished by Newton) at d_f + the
  stepping solver's resolution (MIN_STEP_FRACTION of the sweep's step), on the fold's scaled
  grid; the rest of the retract is stepped from that landing on that grid by the stepping
  solver (its own folds located and landed as on any run).

Where the runner's stability test rejects the branch's state at a sweep separation before
the fold (the retract would leave the branch there, displacement-controlled; never seen on
the stiction map's points, validation/results/sigma_edge.md), the route stops: off its
branch the retract unzips node by node on a fixed grid, the cost the route exists to avoid,
and the run fails saying so ([solver] route = "grid" sweeps it).

A stopped routed run keeps the states it committed (every file row is whole: the writer
appends curve.csv last); its summary says that --resume starts the route over.
"""
import math

from ..contact import Jump, trace
from ..contact.landing import land
from ..contact.sigma_edge import (as_runner_state, extend_deep, runner_state,
                                   state_at_separation)
from ..contact.stepping import MIN_STEP_FRACTION
from ..errors import ConvergenceError
from ..io.progress import phase


def approach_problem(scene, trial):
    """(approach-only scene, its problem) on the adaptive grid's member ``trial`` (a
    :class:`~femadh.runner.adaptive.Trial`)."""
    from ..scene import build_problem
    from .estimates import variant

    if trial is None or trial.operator is None:
        raise ValueError("edge route: the adaptive grid's first member exceeds the node "
                         "limit: no grid for the approach")
    tsc = variant(scene, grid=trial.grid(), radius=trial.family.radius)
    tsc = tsc.replace({"sweep.directions": ["approach"]})
    return tsc, build_problem(tsc, operator=trial.operator)


def trace_approach(tsc, problem, sink):
    """The approach of the sweep into ``sink`` (the stepping solver on the adaptive grid;
    its jump-in located and landed). Returns the last state's problem (a band following
    the edge exchanges grids)."""
    from .tracing import trace_steps

    with phase("approach"):
        trace_steps(tsc, problem, sink, None)
    return sink.problem


def _on_grid(sink, problem):
    """The sink and its writer on ``problem``'s grid from here on."""
    sink.problem = problem
    if sink.writer is not None:
        sink.writer.problem = problem


def trace_retract_sweep(scene, sink, br, retract):
    """The retract at the sweep's separations into ``sink`` (see the module docstring) from
    the family's finest member ``br`` and its traced :class:`~femadh.contact.sigma_edge.
    Retract`. Returns a dict: ``lost`` (the separation (m) where the runner's test rejected
    the branch's state, or None), ``departed`` (the d (m) of the state the jump-out left
    from, or None without a jump-out in the sweep), ``landing`` (its State) and ``states``
    (how many were committed from the branch)."""
    d_all = sorted(float(x) for x in scene.d_values)
    tol, max_iter = scene.tolerance, scene.max_iter
    step = min(abs(b - a) for a, b in zip(d_all, d_all[1:])) if len(d_all) > 1 else 0.0
    with phase("retract (edge branch)"):
        stable = extend_deep(br, retract, d_all[0])
    fold = retract.fold
    on_branch = [d for d in d_all if d <= fold.d]
    beyond = [d for d in d_all if d > fold.d]
    sink.plan("retract", len(d_all))
    out = {"lost": None, "departed": None, "landing": None, "states": 0}
    with phase("retract (edge branch)"):
        for d in on_branch:
            bst = state_at_separation(br, stable, d)
            if bst is None:
                raise ConvergenceError(f"edge route: no branch state at d = {d * 1e9:.6g} nm "
                                       "on the retract's stable part", d=d,
                                       residual=math.nan, n_iter=0)
            pb, st = runner_state(bst, d, tol, max_iter)
            if not st.converged:
                raise ConvergenceError(f"edge route: the runner's corrector did not converge "
                                       f"from the branch state at d = {d * 1e9:.6g} nm "
                                       f"(edge radius {bst.c * 1e6:.6g} um)", d=d,
                                       residual=st.residual, n_iter=st.n_iter)
            if not st.stable:
                out["lost"] = d
                break
            _on_grid(sink, pb)
            sink.state("retract", st)
            out["states"] += 1
    if out["lost"] is not None:
        # the retract leaves the branch before its fold: off the branch the surface unzips
        # node by node on a fixed grid (hundreds of micro-folds, the cost the route avoids;
        # measured 388 s on a 681-node scaled grid of the small test scene): not followed
        return out
    if not beyond:
        return out                    # the sweep ends in contact: no jump-out
    # the fold itself: the runner's state at its separation on its scaled grid, taken as
    # it is (the runner's Jacobian at fixed d is singular at the fold, its Newton need not
    # converge there: 40 iterations without, measured once, 31 to converge another time;
    # and its stability is marginal - the branch's smallest stiffness vanishes there, the
    # test reads it either way by round-off; the branch's states up to it passed the
    # runner's test)
    pb, before = as_runner_state(fold, tol)
    if not before.converged:
        raise ConvergenceError(f"edge route: the fold's state (d = {fold.d * 1e9:.6g} nm) "
                               f"does not meet the runner's tolerance on its grid",
                               d=fold.d, residual=before.residual, n_iter=before.n_iter)
    d_fold = fold.d
    resolution = MIN_STEP_FRACTION * step
    # (within the sweep's first separation beyond the fold: one that lay between the fold
    # and the landing would get no state)
    d_land = min(d_fold + resolution, min(beyond))
    with phase("retract (landing)"):
        after = land(pb, d_land, before.w, tol=tol, max_iter=max_iter)
    if not (after.converged and after.stable):
        raise ConvergenceError(f"edge route: the jump-out's landing at d = {d_land * 1e9:.6g} "
                               "nm did not reach a stable state", d=d_land,
                               residual=after.residual, n_iter=after.n_iter)
    _on_grid(sink, pb)
    # (the resolution is where the landing is: |d_land - d_fold|, as the stepping runner's)
    sink.jump(Jump("retract", d_fold, d_land, d_land - d_fold, before, after))
    if d_land == min(beyond):
        sink.state("retract", after)  # the landing is that separation's state
    out["departed"], out["landing"] = d_fold, after
    rest = [d for d in d_all if d > d_land]
    if rest:
        first = [True]

        def on_state(st):
            if first[0]:              # the landing: a jump's record, not a sweep state
                first[0] = False
                return
            sink.state("retract", st)
        with phase("retract (separated)"):
            trace(pb, [d_land] + rest, branch="retract", tol=tol, start=after,
                  max_iter=max_iter, on_state=on_state, on_jump=sink.jump)
    return out
