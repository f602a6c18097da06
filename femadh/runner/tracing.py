"""Tracing a contact scene's branches into a :class:`~femadh.runner.sink.Sink`: stepping
(with a band that follows the contact edge where the scene asks for one) or pseudo-arclength
through the folds."""
import math

import numpy as np

from ..contact import Jump, State, trace
from ..contact.forces import state_forces
from ..errors import ConvergenceError
from ..scene import build_problem
from .. import interrupt
from .checkpoint import load_checkpoint


def branch_plan(scene):
    d = scene.d_values
    if "approach" in scene.directions:
        plan = [("approach", d)]
        if "retract" in scene.directions:
            plan.append(("retract", d[::-1]))
        return plan
    return [("retract", d)]


class _Regrid(Exception):
    """Raised from a trace's callback: the contact edge left the middle of the band that
    follows it; the sweep goes on from ``state`` (the last state, carried to ``problem``'s
    grid) through ``remaining`` separations (the first is the state's own)."""

    def __init__(self, problem, state, remaining):
        super().__init__("regrid")
        self.problem, self.state, self.remaining = problem, state, remaining


def _follower(scene, problem):
    """The :class:`~femadh.discretisation.moving.EdgeBand` of a scene whose [solver.grid]
    sets ``follow`` (its edges: the contact edge, the outermost node at sigma, and the
    outermost gap at the laws' largest feature gap: the cohesive zone's or the meniscus'
    outer end), else None."""
    g = scene.grid
    if not (g and g.get("follow")) or problem.sigma is None:
        return None
    from ..discretisation.moving import EdgeBand, zone_gap
    from ..discretisation.plan import reach_floor
    from ..elastic import GreenOperator

    def build(grid, first):
        return build_problem(scene, operator=GreenOperator(grid, scene.e_star))
    floor = reach_floor(problem.effects, problem.sigma)
    # the inner edge at sigma itself (a node held at the floor, to round-off), the outer at
    # the cohesive zone's end; the band leads the edges' travel over the next grid steps
    d = scene.d_values
    band = EdgeBand(problem.grid.radius, g["spacing"], g["follow"], g["grading"], build,
                    zone_gap(problem.effects, floor), floor * (1 + 1e-6),
                    step=abs(d[1] - d[0]) if len(d) > 1 else None)
    band.spans[id(problem)] = (0.0, 0.0)     # the scene's own first member (scene_grid)
    band.centers[id(problem)] = 0.0
    return band


def _regridded(band, sink, problem, state, scene, landed=False):
    """(new problem, the state carried to it) if the edge left the band's middle, else None.
    The sink and its writer write on the new grid from here on; the states the peak search
    and a branch's restart need are carried to it (their displacements interpolated: the
    search solves fresh states from them)."""
    from ..discretisation.moving import carry_state
    from ..elastic.grid import NodeBudgetError
    from ..estimate.guards import BudgetError

    try:
        new = band.regrid(problem, state.w, state.d, landed=landed)
    except NodeBudgetError as exc:
        # the band grew over the travelling edge past the node budget: a failed trial of the
        # discretisation (the adaptive loop ends on its budget, naming what it reached), not
        # a fault of femadh
        raise BudgetError(f"band following the contact edge at d = {state.d * 1e9:.6g} nm: "
                         f"{exc}; the laws' cohesive zone needs that spacing across the "
                         "edge's travel (check their parameters, e.g. the Hamaker "
                         "constant's unit)") from None
    if new is None:
        return None
    st = carry_state(problem, new, state, tol=scene.tolerance, max_iter=scene.max_iter)
    if not (st.converged and st.stable):
        raise ConvergenceError(
            f"grid exchange at d = {state.d * 1e9:.6g} nm (band following the contact edge): "
            "the state carried to the new grid did not converge to a stable state",
            d=state.d, residual=st.residual, n_iter=st.n_iter)
    exchange_grid(sink, problem, new)
    return new, st


def exchange_grid(sink, old, new):
    """The sink (and its writer) on ``new``'s grid from here on; the committed states the
    peak search and a branch's restart need carried to it (their displacements interpolated:
    the search solves fresh states from them)."""
    from ..discretisation.moving import interpolate_state

    from dataclasses import replace

    # a peak whose bracket is complete stays on the grid its states were solved on (the
    # search solves there: on the sweep's last grid the band may be far from the peak's
    # edge); one still waiting for its next state goes on with them to the new grid
    held = []
    for attr, grid_of in (("peak", "peak_problem"), ("_rival", "rival_problem")):
        x = getattr(sink, attr, None)
        if x is not None and x[4] is None:
            held += [s for s in x[2:4] if s is not None]
            setattr(sink, grid_of, new)
    kept = {id(s) for x in (sink.peak, getattr(sink, "_rival", None)) if x is not None
            for s in x[2:5] if s is not None} - {id(s) for s in held}
    copies = {}
    for b, s in list(sink.last.items()):
        if id(s) in kept:           # (a restart's copy, the peak's own left as it is)
            sink.last[b] = copies[id(s)] = replace(s)
    # the next peak candidate's previous neighbour (a state before the exchange) goes on to
    # the new grid with it: the last committed state's copy, or a fold's landing (never in
    # sink.last) - else a later peak's bracket spans two grids (state_between interpolates
    # node by node: a ValueError on different counts, mismatched nodes on equal ones)
    moved = held + list(sink.last.values())
    prev = getattr(sink, "_prev", None)
    if prev is not None:
        s = prev[1]
        if id(s) in copies:
            sink._prev = (prev[0], copies[id(s)])
        elif not any(s is x for x in moved):
            # (a copy: the landing is also a fold record - sink.pieces, sink.folds - and
            # maybe a completed peak's state, each on its own grid)
            sink._prev = (prev[0], replace(s))
            moved.append(sink._prev[1])
    snaps = moved
    for snap in {id(x): x for x in snaps}.values():
        if getattr(snap, "w", None) is not None and np.ndim(snap.w) == 1 and \
                snap.w.size == old.grid.n:
            snap.w, snap.active = interpolate_state(old, new, snap.d, snap.w)
    sink.problem = new
    if sink.writer is not None:
        sink.writer.problem = new
    sink.regrids = getattr(sink, "regrids", 0) + 1


def _widened(band, sink, problem, state, scene):
    """(the static-band problem, ``state`` carried to it): the scene's [0, band] at the
    follow band's spacing and grading (a landing's fallback, :func:`trace_steps`)."""
    from ..discretisation import GridFamily
    from ..discretisation.moving import carry_state

    g = scene.grid
    wide = band.build(GridFamily(band.radius, g["band"], band.grading).member(band.spacing),
                      False)
    band.spans[id(wide)] = (0.0, g["band"])
    band.centers[id(wide)] = 0.5 * g["band"]
    st = carry_state(problem, wide, state, tol=scene.tolerance, max_iter=scene.max_iter)
    if not (st.converged and st.stable):
        raise ConvergenceError(
            f"grid exchange at d = {state.d * 1e9:.6g} nm (to the static band after a failed "
            "landing): the carried state did not converge to a stable state", d=state.d,
            residual=st.residual, n_iter=st.n_iter)
    exchange_grid(sink, problem, wide)
    sink.widened = getattr(sink, "widened", 0) + 1
    sink.wide = wide
    return wide, st


def trace_steps(scene, problem, sink, resume):
    """Stepping continuation of every branch of the scene's plan, from the resume point.

    With a band that follows the contact edge ([solver.grid] ``follow``), the grid is
    exchanged after a committed state or a landing whose edge left the band's middle half
    (:class:`~femadh.discretisation.moving.MovingBand`): the state is carried to the new
    grid at its own separation and the sweep goes on from it. Every committed state is
    written on the grid it was solved on (fields.csv's r column)."""
    start, prev = None, None
    band = _follower(scene, problem)
    for branch, d_vals in branch_plan(scene):
        done = len(sink.rows.get(branch, []))
        skip_first = False
        if done >= len(d_vals):
            start, prev = None, branch
            continue
        total = len(d_vals)
        if done:                      # resume inside this branch
            start = restart_state(problem, scene, sink, branch)
            d_vals, skip_first = d_vals[done - 1:], True
        elif start is None and prev is not None:    # resume at the start of this branch
            start = restart_state(problem, scene, sink, prev)
        sink.plan(branch, len(d_vals) - skip_first, total)
        wide = None                   # where this branch last went to the static band
        while True:
            first = [skip_first]
            seen = [0]
            last = [start]            # the last committed state (on the current grid)
            jumped = [0]              # jumps recorded since it

            def on_state(st, branch=branch, d_vals=d_vals, first=first, seen=seen,
                         last=last, jumped=jumped):
                seen[0] += 1
                if first[0]:          # the resumed (or carried) start state is on disk
                    first[0] = False
                    return
                # the edge left the band's middle: the state is committed on the new grid
                # (every committed state on a grid whose band holds its edges)
                moved = band and _regridded(band, sink, sink.problem, st, scene)
                last[0], jumped[0] = (moved[1] if moved else st), 0
                sink.state(branch, last[0])
                if moved:
                    raise _Regrid(*moved, d_vals[seen[0] - 1:])

            def on_jump(jump, d_vals=d_vals, jumped=jumped):
                sink.jump(jump)
                jumped[0] += 1
                moved = band and _regridded(band, sink, sink.problem, jump.after, scene,
                                              landed=True)
                if moved:
                    # on from the landing: the separations beyond it
                    sign = math.copysign(1.0, d_vals[-1] - d_vals[0])
                    raise _Regrid(*moved, [jump.d_land] + [
                        d for d in d_vals if (d - jump.d_land) * sign > 0])
            try:
                sweep = trace(problem, d_vals, branch=branch, tol=scene.tolerance,
                              start=start, max_iter=scene.max_iter, on_state=on_state,
                              on_jump=on_jump)
            except _Regrid as rg:
                problem, start, d_vals, skip_first = rg.problem, rg.state, rg.remaining, True
                if len(d_vals) > 1:
                    continue
                sweep = None
            except ConvergenceError:
                # a fold whose landing failed on a follow grid (the surface snapped to where
                # the grid is coarse, e.g. the jump-in from no contact): the step once more
                # from the last committed state on the static band [0, band], which holds
                # wherever the edge can go; the next exchange returns to the follow band
                if band is None or jumped[0] or seen[0] == 0 or last[0] is None \
                        or wide == last[0].d or problem is getattr(sink, "wide", None) \
                        or not band.widen_affordable(scene.grid["band"]):
                    raise
                wide = last[0].d
                problem, start = _widened(band, sink, problem, last[0], scene)
                d_vals, skip_first = d_vals[seen[0] - 1:], True
                continue
            break
        start, prev = (sweep.states[-1] if sweep is not None else start), branch
    if band is not None:
        sink.result.grid.update(follow_m=band.half, regrids=getattr(sink, "regrids", 0),
                                widened=getattr(sink, "widened", 0),
                                nodes_last=sink.problem.grid.n)
    sink.close()


def restart_state(problem, scene, sink, branch):
    """The last committed state of a branch, re-solved from its saved surface (resume):
    Newton from the saved w converges in an iteration or two to the same state (to the
    tolerance)."""
    from ..contact import solve_state

    last = sink.last[branch]
    d, w = last.d, last.w
    if sink.writer is not None:
        # stopped by a signal or its time limit: the state was saved whole (bit for bit)
        st = load_checkpoint(sink.writer.dir, getattr(sink, "last_k", {}).get(branch), d)
        if st is not None:
            return st
    kw = {}
    if problem.contact_model == "hertz-closure":
        kw["r_c0"] = float(sink.result.branches[branch]["r_c_m"][-1]) or None
    elif problem.sigma is not None:
        kw["active0"] = np.abs(problem.contour(d) - w - problem.sigma) <= 1e-9 * problem.sigma
    st = solve_state(problem, d, w, tol=scene.tolerance, max_iter=scene.max_iter, **kw)
    if not (st.converged and st.stable):
        raise ConvergenceError("resume: the last saved state does not re-converge to a stable "
                               "state", d=d, residual=st.residual, n_iter=st.n_iter)
    return st


def _curve_state(problem, d, w, stable):
    """A State for a point of an arclength curve (smooth laws: no contact pressure)."""
    h = problem.contour(d) - w
    n = w.size
    res = float(np.max(np.abs(w - problem.C @ problem.pressure(h))))
    return State(d, w, h, {k: e.pressure(h) for k, e in problem.effects.items()}, np.zeros(n),
                 np.zeros(n, bool), 0.0, 0, res, True, stable)


def trace_arclength(scene, problem, sink):
    """Trace the scene's equilibrium curve by arclength (every point streamed to
    equilibrium_curve.csv), then its displacement-controlled paths as branches."""
    if problem.sigma is not None:     # the sigma-gap's piecewise curve (its own states)
        from ..contact.sigma_arclength import curve_state as make_state
        from ..contact.sigma_arclength import trace_sigma_curve as trace
    else:
        from ..contact.arclength import trace_curve as trace
        make_state = _curve_state
    d = scene.d_values
    step = abs(d[1] - d[0])
    curve_rows = []

    def on_point(i, point):
        st = make_state(problem, point.d, point.w, point.stable)
        curve_rows.append((i, point, st))
        if sink.writer:
            sink.writer.write_curve_point(i, point, st)
        interrupt.check()
    try:
        curve = trace(problem, d[0], d[-1], tol=scene.tolerance, scale=step, ds=1.0,
                            ds_max=1.0, on_point=on_point)
    finally:
        sink.result.equilibrium_curve = {
            "d_m": np.array([p.d for _, p, _ in curve_rows]),
            "h0_m": np.array([s.h0 for _, _, s in curve_rows]),
            "F_ex_N": np.array([state_forces(problem, s)[2] for _, _, s in curve_rows]),
            "stable": np.array([p.stable for _, p, _ in curve_rows], bool),
            "dd_ds": np.array([p.t_d for _, p, _ in curve_rows])}
    for branch in scene.directions:
        # a sigma-gap event state is on the curve twice (end and start of two pieces of the
        # active set, at one d): it is one state of the path
        path = _once(curve.branch(branch))
        sink.plan(branch, sum(kind != "fold" for kind, _, _ in path))
        before = None
        for kind, dk, wk in path:
            st = make_state(problem, dk, wk, True)
            if kind == "fold":
                before = st
                continue        # the fold state is the jump's 'before', not a grid state
            if kind == "land":  # (the fold first, as the stepping does: the peak's pieces)
                sink.jump(Jump(branch, dk, dk, 0.0, before, st))
            sink.state(branch, st)
    sink.close()


def _once(path):
    """A path without repeated consecutive points at the same d and w (a sigma-gap event)."""
    out = []
    for e in path:
        if out and e[0] == out[-1][0] == "point" and e[1] == out[-1][1] \
                and np.array_equal(e[2], out[-1][2]):
            continue
        out.append(e)
    return out
