"""Continuation of the closure in d: predictor, step halving, folds, and the landing scan
in r_c (see the package docstring for the rules)."""
from dataclasses import dataclass
import math
import time

import numpy as np
from scipy import linalg

from ...errors import ConvergenceError
from ..stepping import Jump, Sweep
from .newton import _lu_sign, _newton_contact, _newton_free
from .states import _contact_state, _free_state, solve_closure_state
from .system import ClosureSystem

#: smallest continuation step as a fraction of the grid step: folds are located to this
MIN_STEP_FRACTION = 2.0**-10
#: solves allowed between two requested separations (healthy steps need a handful, a fold ~12)
MAX_SOLVES_PER_STEP = 200
#: a corrector moving any gap by more than this fraction of it away from the prediction has
#: left the branch (jumped), even if it converged
MAX_CORRECTION_FRACTION = 0.25
#: ratio of successive contact radii in the landing scan, and its largest step in node spacings
SCAN_RATIO, SCAN_MAX_NODES = 1.12, 4.0
#: iteration budget (times max_iter) of the scan's first point
ENTRY_BUDGET = 5


def _predict(cs, state, d):
    """Tangent predictor (w, r_c) at d from a converged state. (A curvature term from the
    previous state's tangent saved only 3 % of the Newton iterations: the branch is jagged at
    the node scale, see drc_dd, so it is left out.)"""
    dd = d - state.d
    dw = state.diagnostics.get("dw_dd")
    w = state.w + (dw * dd if dw is not None else 0.0)
    if state.r_c > 0:
        r = state.r_c + state.diagnostics.get("drc_dd", 0.0) * dd
        if r <= 2 * cs.r_floor:
            r = None    # the predictor closes the contact: start without it
    else:
        r = None
    return w, r


def _close_to_prediction(cs, new, w_pred, r_pred):
    """The corrector stayed on the predicted branch: no gap moved by more than
    MAX_CORRECTION_FRACTION of itself and, on a contact branch, r_c by no more than that
    fraction plus two node spacings. Entering or leaving contact (predicted or new r_c = 0)
    only the gaps are checked: r_c goes like sqrt(d_touch - d) there, faster than any
    predictor, while a snap (sigma = 0.5 nm) moves the gaps by far more than the fraction."""
    h_pred = new.h + (new.w - w_pred)
    if not np.all(np.abs(new.w - w_pred) <= MAX_CORRECTION_FRACTION * np.maximum(h_pred, 0)
                  + 1e-15):
        return False
    if r_pred is None or new.r_c == 0:
        return True
    return abs(new.r_c - r_pred) <= (MAX_CORRECTION_FRACTION * max(r_pred, new.r_c)
                                     + 2 * cs.nodes[1])


@dataclass
class BranchPoint:
    """A point of the contact branch parametrised by r_c (landing scan)."""

    r_c: float
    d: float
    w: np.ndarray


def _scan_branch(cs, start_w, start_d, r_from, direction, d_target, *, tol, max_iter,
                 stop_at_first=True, r_to=None):
    """Scan the contact branch d*(r_c) from r_from in ``direction`` (+1 up, -1 down).

    Returns (points, landing state or None, crossings [(r_c, stable)]). At each r_c the
    closure is solved for (w, d) (border "d"): regular through the folds in d.
    """
    pts, crossings = [], []
    w, d, r = np.array(start_w, float), float(start_d), float(r_from)
    dr_node = float(cs.nodes[1])
    # down: to half a node spacing (the approach scan's entry point), then the free surface
    r_end = r_to if r_to is not None else (0.5 * dr_node if direction < 0 else 0.98 * cs.r_max)
    prev = None
    for k in range(400):
        # the first point may start far from the branch (a free surface entering contact):
        # a larger budget for it, the predictor keeps the others close
        res = _newton_contact(cs, d, w, r, border="d", tol=tol,
                              max_iter=max_iter * (ENTRY_BUDGET if k == 0 else 1))
        if not res.ok:
            raise _ScanFailure(pts, r, res.reason)
        p = BranchPoint(r, res.d, res.w)
        pts.append(p)
        if prev is not None and (prev.d - d_target) * (p.d - d_target) <= 0 and prev.d != p.d:
            t = (d_target - prev.d) / (p.d - prev.d)
            r_x = prev.r_c + t * (p.r_c - prev.r_c)
            w_x = prev.w + t * (p.w - prev.w)
            land = _newton_contact(cs, d_target, w_x, r_x, border="r_c", tol=tol,
                                   max_iter=max_iter)
            st = _contact_state(cs, land, tol) if land.ok else None
            crossings.append((r_x, bool(st is not None and st.stable)))
            if st is not None and st.stable and stop_at_first:
                return pts, st, crossings
        if (direction > 0 and r >= r_end) or (direction < 0 and r <= r_end):
            return pts, None, crossings
        # next r_c: geometric, at most SCAN_MAX_NODES node spacings; secant predictor in r_c
        r_next = r * SCAN_RATIO if direction > 0 else r / SCAN_RATIO
        r_next = (min(r_next, r + SCAN_MAX_NODES * dr_node) if direction > 0
                  else max(r_next, r - SCAN_MAX_NODES * dr_node))
        r_next = min(r_next, r_end) if direction > 0 else max(r_next, r_end)
        if prev is not None and p.r_c != prev.r_c:
            s = (r_next - p.r_c) / (p.r_c - prev.r_c)
            w, d = p.w + s * (p.w - prev.w), p.d + s * (p.d - prev.d)
        else:
            w, d = p.w, p.d
        prev, r = p, r_next
    return pts, None, crossings


class _ScanFailure(Exception):
    def __init__(self, pts, r, reason):
        super().__init__(reason)
        self.pts, self.r, self.reason = pts, r, reason


def _scan_evidence(pts, crossings, d_target):
    if not pts:
        return "the scan found no contact state at all"
    ds = np.array([p.d for p in pts]) * 1e9
    rs = np.array([p.r_c for p in pts]) * 1e6
    txt = (f"contact branch scanned over r_c = {rs.min():.4g}..{rs.max():.4g} um reaches "
           f"d = {ds.min():.6g}..{ds.max():.6g} nm (target {d_target * 1e9:.6g} nm)")
    if crossings:
        txt += "; crossings at r_c = " + ", ".join(
            f"{r * 1e6:.4g} um ({'stable' if s else 'unstable'})" for r, s in crossings)
    else:
        txt += "; d*(r_c) - d has no sign change"
    return txt


def land_closure(problem, departing, d_land, *, branch, tol, max_iter=40, system=None):
    """The state the surface snaps to at d_land after the branch of ``departing`` folded.

    Rule (module docstring): scan the contact branch in r_c from the departing contact radius,
    upwards on approach and downwards on retract; land on the first stable state at d_land; on
    retract, below the smallest contact the free surface (r_c = 0) is the landing if it is a
    stable state with h >= sigma.

    Raises
    ------
    ConvergenceError
        When no stable landing exists, with the scanned d*(r_c) range and its crossings.
    """
    cs = system or ClosureSystem(problem)
    direction = 1 if branch == "approach" else -1
    dr_node = float(cs.nodes[1])
    if departing.r_c > 0:
        r0, w0, d0 = departing.r_c, departing.w, departing.d
    else:
        # the contact branch is entered at its smallest contact; from the departing surface
        r0, w0, d0 = 0.5 * dr_node, departing.w, departing.d
    try:
        pts, st, crossings = _scan_branch(cs, w0, d0, r0, direction, d_land, tol=tol,
                                          max_iter=max_iter)
    except _ScanFailure as exc:
        raise ConvergenceError(
            f"landing after the fold at d = {departing.d * 1e9:.6g} nm: the r_c scan failed at "
            f"r_c = {exc.r * 1e6:.4g} um ({exc.reason}); "
            + _scan_evidence(exc.pts, [], d_land), d=d_land) from None
    if st is not None:
        st.diagnostics["landing_scan"] = _scan_evidence(pts, crossings, d_land)
        return st
    if direction < 0:
        free = _newton_free(cs, d_land, np.zeros(cs.n), tol=tol, max_iter=max_iter)
        if free.ok and np.min(d_land + cs.shape - free.w) >= cs.sigma:
            fs = _free_state(cs, free)
            if fs.stable:
                fs.diagnostics["landing_scan"] = _scan_evidence(pts, crossings, d_land)
                return fs
    raise ConvergenceError(
        f"no stable closure state at d = {d_land * 1e9:.6g} nm to land on after the fold at "
        f"d = {departing.d * 1e9:.6g} nm: " + _scan_evidence(pts, crossings, d_land), d=d_land)


def _first_state(cs, problem, d, tol, max_iter):
    st = solve_closure_state(problem, d, np.zeros(cs.n), tol=tol, max_iter=max_iter, system=cs)
    if not (st.converged and st.stable):
        raise ConvergenceError(f"closure: first state not found ({st.diagnostics.get('failure', 'unstable')})",
                               d=d, residual=st.residual if math.isfinite(st.residual) else None,
                               n_iter=st.n_iter)
    return st


def trace_closure(problem, d_values, *, branch, tol, start=None, max_iter=40, on_state=None,
                  on_jump=None):
    """Follow the closure's stable branch through the separations ``d_values`` (m).

    Continuation in d: tangent predictor (w, r_c), Newton corrector, step halving down to
    MIN_STEP_FRACTION of the grid step. A step is accepted when the state converged, is stable
    (module docstring) and stayed within MAX_CORRECTION_FRACTION of the predicted gaps. When the
    smallest step fails, the branch has folded at the last stable d (snap-in on approach,
    snap-out on retract; located to |grid step| * MIN_STEP_FRACTION) and the surface lands by
    :func:`land_closure` one smallest step beyond.

    Parameters
    ----------
    problem : ContactProblem
    d_values : sequence of float
        Separations (m) in the order visited.
    branch : str
        ``"approach"`` or ``"retract"`` (sets the landing direction).
    tol : float
        Residual tolerance (m).
    start : State, optional
        A converged state at d_values[0] (e.g. the approach's last); else solved from w = 0.
    on_state : callable(State), optional
        Called with every state at a requested separation.
    on_jump : callable(Jump), optional
        Called with each fold and its landing as soon as it is found.

    Returns
    -------
    Sweep
        States at the requested d, ``jumps`` (Jump objects), ``n_solves``, ``wall_time``.

    Raises
    ------
    ConvergenceError
        With the partial sweep as ``exc.sweep``: no stable landing (evidence in the message),
        the step budget exhausted, or a non-finite value (named).
    """
    t0 = time.perf_counter()
    cs = ClosureSystem(problem)
    sweep = Sweep(branch)
    d_values = [float(x) for x in d_values]
    if start is not None and not (start.converged and start.stable):
        raise ValueError("start must be a converged, stable state (e.g. a sweep's last)")
    try:
        state = start if start is not None else _first_state(cs, problem, d_values[0], tol,
                                                             max_iter)
        sweep.n_solves += 0 if start is not None else 1
        sweep.states.append(state)
        if on_state:
            on_state(state)
        for d_next in d_values[1:]:
            state = _advance(cs, problem, state, d_next, sweep, branch, tol, max_iter,
                             on_jump)
            sweep.states.append(state)
            if on_state:
                on_state(state)
    except ConvergenceError as exc:
        exc.sweep = sweep
        sweep.wall_time = time.perf_counter() - t0
        raise
    sweep.wall_time = time.perf_counter() - t0
    return sweep


def _onset_is_stable(cs, free, tol, max_iter):
    """Is the contact branch stable where it leaves the free surface ``free``?

    Solves the closure at the smallest contact (half a node spacing) for (w, d) from the free
    state and tests the stability rule there. Stable: the contact grows continuously from
    touch-down (sigma = 1 nm). Unstable: d*(r_c) first rises with r_c (e.g. eq 20's pull over
    the contact), so touch-down is a fold and entering or leaving contact is a snap.
    """
    res = _newton_contact(cs, free.d, free.w, 0.5 * cs.nodes[1], border="d", tol=tol,
                          max_iter=max_iter * ENTRY_BUDGET)
    if not res.ok:
        return False
    lu = linalg.lu_factor(cs.add_jacobian(res.ev).jacobian("r_c"), check_finite=False)
    return _lu_sign(lu) < 0


def _continuous_transition(cs, old, new, tol, max_iter):
    """A step between the free surface and contact is continuous only if the contact branch
    is stable at its onset (checked on the free state of the two); other steps pass."""
    if (old.r_c > 0) == (new.r_c > 0):
        return True
    return _onset_is_stable(cs, old if old.r_c == 0 else new, tol, max_iter)


def _advance(cs, problem, state, d_next, sweep, branch, tol, max_iter, on_jump=None):
    """Step from state to d_next with halving; folds -> land_closure."""
    grid_step = d_next - state.d
    step = grid_step
    min_step = abs(grid_step) * MIN_STEP_FRACTION
    solves = 0
    while state.d != d_next:
        if solves >= MAX_SOLVES_PER_STEP:
            raise ConvergenceError(
                f"closure continuation stalled between d = {state.d * 1e9:.6g} and "
                f"{d_next * 1e9:.6g} nm: {solves} solves (step {abs(step) * 1e9:.3g} nm)",
                d=state.d, residual=state.residual, n_iter=state.n_iter)
        solves += 1
        d_try = state.d + step
        if (d_next - d_try) * math.copysign(1.0, grid_step) < 0 or \
                abs(d_next - d_try) < 0.5 * min_step:
            d_try = d_next
        w_pred, r_pred = _predict(cs, state, d_try)
        new = solve_closure_state(problem, d_try, w_pred, tol=tol, max_iter=max_iter,
                                  r_c0=r_pred, system=cs)
        sweep.n_solves += 1
        if (new.converged and new.stable and _close_to_prediction(cs, new, w_pred, r_pred)
                and _continuous_transition(cs, state, new, tol, max_iter)):
            state = new
            step = math.copysign(min(abs(2 * step), abs(grid_step)), grid_step)
            continue
        if abs(step) > 1.5 * min_step:
            step *= 0.5
            continue
        landed = land_closure(problem, state, d_try, branch=branch, tol=tol, max_iter=max_iter,
                              system=cs)
        sweep.n_solves += 1
        sweep.jumps.append(Jump(branch, state.d, d_try, abs(d_try - state.d), state, landed))
        if on_jump:
            on_jump(sweep.jumps[-1])
        state = landed
    return state
