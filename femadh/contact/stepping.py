"""Continuation in the separation d: approach and retract branches, fold detection and jumps.

Each grid step is taken with a predictor (the tangent dw/dd of the last state, its active set
frozen; computed once per state; on a healthy step of a growing contact the set is the disk
whose edge is extrapolated from the last two states, :func:`edge_set`) and the semismooth
Newton corrector. A step is accepted only if the corrector converges to a *stable* state
close to the prediction - measured from where the corrector starts, the predicted contact on
the floor (:func:`_accept`). A trial step larger than the smallest gets TRIAL_MAX_ITER
corrector iterations. A step turned down
because its stable state lies farther from the prediction than the corrector may go, with no
energy lost beyond one branch's bound (most likely the same branch: the predictor's reach), is
halved. Any other turned-down step
brackets a fold between the last accepted d and itself (:class:`_Bracket`): no trial goes past
it again, and the fold is searched inside by a secant on the indicator 1/G'^2 (zero at a
saddle-node fold), safeguarded by bisection and capped, on the lattice of resolution steps
(MIN_STEP_FRACTION of the grid step) that the plain halving visited - so the fold is the one
the halving found, in fewer solves. When the decision solve (the whole corrector budget) one
resolution step past the last accepted state fails, the branch has folded (the stable
equilibrium ceased to exist: jump-in on approach, jump-out on retract). The fold is reported
at the last stable d, and the surface is then landed on the other branch by descending the
total energy from the last state (Levenberg-Marquardt with the gap bound h >= sigma), which is
where a quasi-static surface would snap to, and polished by Newton. The plain halving (step
halved on any rejection, doubled on acceptance) is kept on lattice-trapped grids, where the
states reached depend on the path, and is the fallback of a grid step whose landing does not
polish.

A corrector can also converge to a stable state of the *other* branch across a fold that lies
inside the step (a small jump-in, whose gap change stays within MAX_CORRECTION_FRACTION). Such a
step is told by its energy: along one branch the total energy E*(d) changes by the work of the
total force, dE*/dd = G(d) = sum_k (S w)_k (envelope theorem, the sigma-gap multipliers
included), so E_b - E_a = integral of G dd; the trapezoid 1/2 (G_a + G_b)(d_b - d_a) misses it by
at most 1/2 |G_b - G_a| |d_b - d_a| wherever G is monotone in the step. A step that *releases*
more energy than that bound crossed a fold (the snap dissipates it) and is halved like any
rejected step; a smooth peak of G inside the step can also exceed the bound, and one halving
puts the peak at an end of the step where the bound holds again (measured on the bundled
scenes: legitimate steps reach 0.7 of the bound away from peaks, Fig 8's smoothed jump-in 1.8).

The same balance sorts the landings at the smallest step: one that releases less than the
step's work is a node snapping across the lattice (:func:`lattice_snap`), stepped over; a
contact's snap (jump-in, pull-off) releases ~150x it and is a jump. A trial step's corrector
gives up when it stagnates (the smallest step's, which decides a fold, has its whole budget).

A contact unzipping node by node near a pull-off (issue 21) makes a micro-fold of every node
it releases; what keeps that cheap - the next snap expected from the rhythm of the last, a
fold's decision cut short where the corrector cycles between contact sets, a single node's
snap landed by the corrector - lives in :mod:`femadh.contact.snap`. Measured on the Fig 4
disk at 50, 60, ..., 400 nodes and on the 532-node slider (validation/results/snap_cost.md)
they move no fold off its lattice point and no state's contact set, and the surfaces agree
with the old path's to 1e-18 m (the polishes stop at different iterates within the
tolerance).
"""
from dataclasses import dataclass, field
import math
import time

import numpy as np

from ..errors import ConvergenceError
from .complementarity import STALL_ITER, solve_complementarity, tangent
from .linalg import disk_size
from .landing import land, land_next_node
from . import snap

#: smallest continuation step, as a fraction of the grid step (fold located to this resolution)
MIN_STEP_FRACTION = 2.0**-10
#: solves allowed between two requested separations before the branch counts as stalled
#: (a fold needs at most ~2 log2(1/MIN_STEP_FRACTION) = 20 bracketed trials, measured 4-8 on
#: a jump-in; healthy steps need a handful)
MAX_SOLVES_PER_STEP = 200
#: ... and each contact node the accepted states released or added on the way brings this
#: many more (a release costs the halvings down to the smallest step,
#: log2(1/MIN_STEP_FRACTION))
SOLVES_PER_EDGE_NODE = 10
#: folds in a row, each within CRAWL_STEPS smallest steps of the last landing, beyond which the
#: branch counts as stalled (folds further apart are a contact unzipping node by node)
MAX_JUMPS_PER_STEP = 3
CRAWL_STEPS = 4
#: a corrector that moves any gap by more than this fraction away from the prediction has
#: left the branch (jumped) even if it converged
MAX_CORRECTION_FRACTION = 0.25
#: energy released beyond the one-branch bound (a multiple of the bound) above which a step
#: counts as crossing a fold; 1 is the bound itself (exact for a force monotone in the step)
FOLD_ENERGY_RATIO = 1.0
#: ... and beyond this share of the work |G| |dd| done in the step: a lattice micro-fold (one
#: node leaving or joining the contact near a fold, measured 0.9-2 % of the step's work on Fig 4
#: and the mu = 2 sphere) is stepped over as before; a snap of the contact releases a
#: finite energy while the work of the step shrinks with it (Fig 8's smoothed jump-in: 90 % of
#: a full step's work)
FOLD_ENERGY_SHARE = 0.1
#: ... and at the smallest step, where a snap's energy dwarfs the step's work (Fig 8: ~1e3 x)
#: while a node snapping on its own in a law steeper than the lattice resolves stays below it
#: (the steep smoothed eq 20 on 100 nodes): those are stepped over as before the check existed
FOLD_ENERGY_SHARE_MIN_STEP = 1.0


@dataclass
class Jump:
    """A fold of the equilibrium branch and where the surface landed.

    Attributes
    ----------
    branch : str
        ``"approach"`` (jump-in) or ``"retract"`` (jump-out).
    d_fold : float
        Last separation (m) at which the departing branch was found stable.
    d_land : float
        Separation (m) at which the landing state was computed (d_fold + smallest step).
    resolution : float
        |d_land - d_fold| (m): the fold lies within this distance of d_fold.
    before, after : State
        The last state of the departing branch and the landing state.
    """

    branch: str
    d_fold: float
    d_land: float
    resolution: float
    before: object
    after: object


@dataclass
class Sweep:
    """The states of one branch at the requested separations, and its folds."""

    branch: str
    states: list = field(default_factory=list)
    jumps: list = field(default_factory=list)
    n_solves: int = 0
    wall_time: float = 0.0
    #: work of the correctors: "solves", "iterations", "factorisations", "stagnated"
    work: dict = field(default_factory=dict)
    d_current: float = math.nan     # separation of the solve under way (for error messages)


def _accept(new, pred_w, d, problem=None, active=None, released=False):
    """True if ``new`` converged to a stable state within MAX_CORRECTION_FRACTION of every
    predicted gap (else it may have left the branch).

    With ``problem`` and the predicted contact set ``active`` (PROJECTED_ACCEPT), the
    prediction is measured where the corrector starts from: ``pred_w`` with the predicted
    contact nodes put on the floor (w = b - sigma there, the corrector's first act). A node
    the predictor put below sigma and that ends in contact has then moved by nothing; measured
    without the projection it moved by its predicted overshoot (Fig 4's 631-node approach:
    0.145 nm against a predicted gap of 0.355 nm at the edge, a ratio of 0.41), and healthy
    steps of a growing contact were turned down and halved (7 of 65 solves of that approach,
    each halving 3-4 solves for one grid step)."""
    if not (new.converged and new.stable):
        return False
    pred_w = _projected(problem, pred_w, d, active)
    # gaps of the prediction; the sphere moves by d but b - w_pred is what was predicted
    h_pred = new.h + (new.w - pred_w)
    change = np.abs(new.w - pred_w)
    ref = np.maximum(h_pred, 0)
    if released and active is not None:
        # a node of the predicted contact that the corrector released: measured against the
        # gap it opened to (it was predicted on the floor, so any opening beyond a quarter
        # of sigma turned a healthy step down: 8 of the 631-node retract's steps, each then
        # halved into 3 solves for the same states); a snap off the contact opens its nodes
        # to several sigma and stays turned down
        out = active & ~new.active
        ref[out] = np.maximum(ref[out], new.h[out])
    return bool(np.all(change <= MAX_CORRECTION_FRACTION * ref + 1e-15))


def _projected(problem, w, d, active):
    """``w`` with the nodes of ``active`` on the floor h = sigma (the corrector's start), or
    ``w`` itself without a gap constraint, a set or PROJECTED_ACCEPT."""
    if not PROJECTED_ACCEPT or problem is None or active is None or problem.sigma is None \
            or not np.any(active):
        return w
    out = np.array(w, dtype=float)
    out[active] = problem.contour(d)[active] - problem.sigma
    return out


def total_force(problem, state):
    """G = sum_k (S w)_k (N): the total elastic force of a state, dE*/dd along its branch."""
    return float(np.sum(problem.S_sym @ state.w))


def crossed_fold(problem, old, new, g_old, g_new, share=None):
    """True if going from ``old`` to ``new`` released more energy than one branch can.

    Parameters
    ----------
    problem : ContactProblem
    old, new : State
        Converged stable states at separations d_a and d_b (m).
    g_old, g_new : float
        Their total forces :func:`total_force` (N).
    share : float, optional
        Share of the step's work 1/2 (|G_a| + |G_b|) |d_b - d_a| the released energy must
        exceed as well (default FOLD_ENERGY_SHARE).

    Returns
    -------
    bool
        ``1/2 (G_a + G_b)(d_b - d_a) - (E_b - E_a)`` (the energy lost, J) exceeds both
        FOLD_ENERGY_RATIO x 1/2 |G_b - G_a| |d_b - d_a| (what the trapezoid rule can miss along
        one branch with a monotone force) and ``share`` of the step's work, beyond round-off:
        a snap (a fold) lies inside the step. False where a node can snap on its own
        (:meth:`ContactProblem.node_softening_ratio` >= 1 at either state).
    """
    share = FOLD_ENERGY_SHARE if share is None else share
    if max(problem.node_softening_ratio(old.h), problem.node_softening_ratio(new.h)) >= 1.0:
        # a law softening faster than a node is stiff: nodes snap on their own (lattice
        # trapping) and the energy lost in a step measures the lattice, not a fold of the
        # contact; such steps are judged by the corrector alone (the adaptive grid's trapping
        # guard refines them away where it runs)
        return False
    released, bound, work, noise = step_energy(problem, old, new, g_old, g_new)
    return bool(released > max(FOLD_ENERGY_RATIO * bound, share * work) + noise)


def step_energy(problem, old, new, g_old, g_new):
    """The energy balance of going from ``old`` to ``new`` (J): (released, bound, work, noise).

    released = 1/2 (G_a + G_b)(d_b - d_a) - (E_b - E_a), the energy the step dissipated;
    bound = 1/2 |G_b - G_a| |d_b - d_a|, what the trapezoid can miss along one branch;
    work = 1/2 (|G_a| + |G_b|) |d_b - d_a|, the work of the step; noise: the round-off of
    these sums (a few ulps of their largest terms)."""
    dd = new.d - old.d
    e_old, e_new = problem.energy(old.w, old.d), problem.energy(new.w, new.d)
    released = 0.5 * (g_old + g_new) * dd - (e_new - e_old)
    bound = 0.5 * abs((g_new - g_old) * dd)
    work = 0.5 * (abs(g_old) + abs(g_new)) * abs(dd)
    noise = 64 * np.finfo(float).eps * (abs(e_old) + abs(e_new) + abs(g_old * dd)
                                        + abs(g_new * dd))
    return released, bound, work, noise


def lattice_snap(problem, old, landed, g_old, g_landed):
    """True if a landing at the smallest step released no more than FOLD_ENERGY_SHARE_MIN_STEP
    of the step's work: a single node snapping across the lattice (measured on the Fig 4
    scene's members: 0.1-0.3 x the work), not a snap of the contact (a jump-in or pull-off
    releases ~150 x it). Such a landing continues the branch - a corrector that converged
    over it would have been accepted at that step - so whether it shows depends on the path
    of step halvings, not on the physics; it is stepped over, never reported as a jump."""
    released, _, work, noise = step_energy(problem, old, landed, g_old, g_landed)
    return bool(released <= FOLD_ENERGY_SHARE_MIN_STEP * work + noise)


#: trials inside a fold's bracket allowed to follow the fold indicator before every further
#: trial bisects (the cap that makes a fold cost at most ~2 log2(1/MIN_STEP_FRACTION) solves)
MAX_INDICATOR_TRIALS = 12
#: an indicator trial must have at least halved the bracket over the last two trials, else the
#: next one bisects (the safeguard of a regula falsi that keeps landing on one side)
MIN_SHRINK_PER_TWO = 0.5
#: corrector iterations a trial step larger than the smallest may take (None: the scene's
#: max_iter); the smallest step, which decides a fold, keeps the whole budget. A trial that
#: has not converged by then lies across a fold or too far for the predictor, and is halved
#: or bracketed as any unconverged trial: on the Fig 4 scene's 631-node retract the trials
#: that converged took at most 14 iterations, while two trial steps across the pull-off ran
#: to the budget of 40 as the contact unzipped node by node in the corrector (the stagnation
#: exit counts a steadily moving edge as progress), 0.2 s each (517 -> 461 iterations over
#: that retract). At 20 the coarse Fig 4 disk of 100 nodes bracketed trials that would have
#: converged in 21-25 iterations (its pull-off's fold solves 24 -> 49); at 25, 23
TRIAL_MAX_ITER = 30
#: a healthy step's released contact nodes are measured against the gap they opened to
#: (:func:`_accept`); never a fold's trial or decision
RELEASED_ACCEPT = True
#: the acceptance measures the prediction with its contact nodes on the floor (:func:`_accept`)
PROJECTED_ACCEPT = True
#: the contact set of a step outside a fold's bracket extrapolated from the last two states
#: (:func:`edge_set`); False: the set of the last state, grown where the prediction is below
#: sigma (the tests' reference)
EDGE_PREDICTOR = True
#: ... only where the edge moved by at least this many nodes between the two states
EDGE_MIN_NODES = 2
#: ... and no further than this many times the distance between the two states (after a
#: landing or a halving the next step can be 2-4 x the last; the edge's m(d) is concave right
#: after a jump-in, where a longer reach overshot)
EDGE_MAX_RATIO = 1.0
#: False: the plain halving everywhere (the path the bracketed search replaced; the tests'
#: reference for where the folds are)
BRACKETED = True


class _Bracket:
    """A fold bracketed between the current state's d and the nearest turned-down separation.

    Once a continuation step is turned down at ``far`` (no stable state of the branch close
    to the prediction, or one across a fold) the fold lies between the last accepted d and
    ``far`` - or ``far`` was only too far for the predictor, which the next trials find out.
    No trial goes beyond ``far`` again while it stands. Each trial inside the bracket aims
    half a resolution step short of the fold's estimate from the indicator (below); once the
    last accepted state lies within a resolution step of the estimate it probes one
    resolution step past it - the decision solve (full corrector budget) that locates the
    fold when it is turned down. Without an estimate, after MAX_INDICATOR_TRIALS, or when
    the bracket has not halved over the last two trials (MIN_SHRINK_PER_TWO), a trial
    bisects. The fold is located when the decision solve from the current state turns down
    ``far`` at most one resolution step away (MIN_STEP_FRACTION of the grid step: the
    resolution of the halving this replaced, never coarser).

    The indicator: near a saddle-node fold at d* the branch's total force G(d) goes as
    G* - c sqrt(|d* - d|), so its tangent G' = sum S dw/dd (N/m) diverges as |d* - d|^-1/2
    and q = 1/G'^2 falls linearly to zero at d*. The two last accepted states give the
    secant estimate d* = d2 + q2 (d2 - d1) / (q1 - q2), used when q falls toward the
    bracket and the estimate lies inside it. (A fold of a contact set - a node released or
    added - has no such divergence: q then does not fall, and the bracket is bisected.)
    """

    def __init__(self, grid_step, min_step):
        self.dir = math.copysign(1.0, grid_step)
        self.min_step = min_step
        self.points = []        # (d, q) of the accepted states since the last landing
        self.clear()

    def clear(self):
        """No bracket (a landing, or a far end that turned out to be no fold)."""
        self.far, self.decided = None, False
        self.widths, self.trials = [], 0

    def restart(self, state, t, problem):
        """A new branch piece from ``state`` (a landing): its indicator starts afresh."""
        self.points = []
        self.clear()
        self.see(state, t, problem)

    def see(self, state, t, problem):
        """An accepted state and its tangent t = dw/dd (or None)."""
        self.decided = False
        gp = float(np.sum(problem.S_sym @ t)) if t is not None else 0.0
        q = 1.0 / (gp * gp) if gp != 0.0 and math.isfinite(gp) else math.inf
        self.points = (self.points + [(state.d, q)])[-2:]

    def reject(self, d, decided):
        """The trial at d was turned down; ``decided``: by a decision solve (whole budget)."""
        self.far, self.decided = d, decided

    def width(self, state):
        return (self.far - state.d) * self.dir

    def located(self, state):
        return self.far is not None and self.decided and self.steps(state) <= 1

    def steps(self, state):
        """The bracket's width in resolution steps (a whole number: its ends are lattice
        points, up to the round-off of d, which can be 1e-8 of a step)."""
        return int(round(self.width(state) / self.min_step))

    def estimate(self):
        """The indicator's estimate of the fold's d (m), or None."""
        if len(self.points) < 2:
            return None
        (d1, q1), (d2, q2) = self.points
        if not (math.isfinite(q1) and math.isfinite(q2)) or (d2 - d1) * self.dir <= 0 \
                or not q2 < q1:
            return None
        return d2 + q2 * (d2 - d1) / (q1 - q2)

    def trial(self, state, work):
        """The next separation to try inside the bracket (m); counts the bisections (the
        fallback) in ``work["fold_bisections"]``.

        Every trial is the current d plus a whole number of resolution steps, so that the
        trials (and the fold) lie on the lattice of the halving this replaced: the fold is
        the last point of that lattice the branch reaches, whichever trials found it."""
        a, h = state.d, self.min_step
        n = self.steps(state)
        if n <= 1:
            return self.far                         # the decision solve
        est = None
        stuck = len(self.widths) >= 2 and n > MIN_SHRINK_PER_TWO * self.widths[-2]
        if self.trials < MAX_INDICATOR_TRIALS and not stuck:
            est = self.estimate()
        self.widths.append(n)
        self.trials += 1
        if est is not None and 0 < (est - a) * self.dir < n * h:
            # half a resolution step short of the estimate; at it: one step past (a decision)
            k = max(1, int(round((est - a) * self.dir / h - 0.5)))
            return a + self.dir * min(k, n - 1) * h
        work["fold_bisections"] = work.get("fold_bisections", 0) + 1
        return a + self.dir * (n // 2) * h


def _smallest_step(problem, tol, max_iter, work):
    """The healthy smallest step that :func:`femadh.contact.snap.next_node_holds` takes from
    a next-node landing: a callable ((state, G (N), tangent), d (m)) -> the same at d, or
    None unless the corrector converged to a stable state close to its prediction that
    releases no more than the lattice bound (:func:`_accept`, :func:`crossed_fold` with
    FOLD_ENERGY_SHARE_MIN_STEP). Its solves are added to ``work``."""
    def step(at, d):
        st, g, t = at
        w_pred, act = _predict(problem, st, d, t)
        new = solve_complementarity(problem, d, w_pred, tol=tol, max_iter=max_iter,
                                    active0=act, factor=st.lu, stall_iter=STALL_ITER,
                                    stats=work)
        if not _accept(new, w_pred, d, problem, act):
            return None
        g_new = total_force(problem, new)
        if crossed_fold(problem, st, new, g, g_new, FOLD_ENERGY_SHARE_MIN_STEP):
            return None
        return new, g_new, _tangent(problem, new)
    return step


def _tangent(problem, state):
    """dw/dd (m/m) of ``state`` with its active set frozen, or None without a factorisation
    (the predictor then takes the state itself); computed once per state, not per trial."""
    if state.lu is None:
        return None
    return tangent(problem, state)


def _predict(problem, state, d, t=None, edge=False):
    """Predicted displacements at d (tangent of the last state) and the active set they imply.

    (A release of the contact ring predicted from the tangent of the contact pressure,
    d lambda_A/dd = -(K t)_A, was measured: 6 % fewer corrector iterations on the Fig 4
    retract, but near the pull-off its decision solve at the smallest step missed a stable
    state the gap-only prediction finds, and moved the fold by one resolution step; the
    fold's decision must not depend on the predictor, so the set only grows here.)

    With ``edge`` (the caller asks for it only on a step outside a fold's bracket, never for
    a decision solve) a growing contact's set is the disk whose edge is extrapolated from the two states
    (:func:`edge_set`), and the prediction's nodes in it are put on the floor: the edge
    advances by 5-23 nodes per grid step on the Fig 4 scene's 631-node member, which a
    tangent with a frozen set cannot see, and the corrector spent 2-4 iterations finding
    the set (measured there: 186 -> 112 iterations over the approach's grid steps, with the
    acceptance of :func:`_accept`)."""
    if t is None and state.lu is not None:
        t = tangent(problem, state)
    if t is not None:
        w = state.w + t * (d - state.d)
    else:
        w = state.w.copy()
    if problem.sigma is None:
        return w, state.active
    b = problem.contour(d)
    grown = state.active | (b - w < problem.sigma)
    act = edge_set(state, d) if edge else None
    if act is None:
        return w, grown
    w[act] = b[act] - problem.sigma
    return w, act


def edge_set(state, d):
    """The contact disk at separation d (m) with its edge extrapolated linearly in d from two
    accepted disk-shaped states of one branch piece - ``state`` and the one before it,
    ``state.edge_from`` = (d_p, m_p), kept on the state (and in a checkpoint: a resumed sweep
    predicts as the uninterrupted one) - as a mask: the
    edge node count m(d) = m_s + (m_s - m_p) min(x, EDGE_MAX_RATIO), x = (d - d_s) /
    (d_s - d_p) > 0, rounded, at most every node.

    None where either state is not a disk or has no contact, their separations coincide,
    the contact did not grow by at least EDGE_MIN_NODES nodes between them, or d does not
    lie beyond ``state`` as seen from ``prev``. A coarse grid's edge moves node by node:
    there the rounded extrapolation put a node into the set that the corrector then opened
    by more than a quarter of sigma, and the step was turned down (the Fig 4 disk at 100
    nodes: 10 of 38 steps). A shrinking contact keeps the last state's set: near the
    pull-off a contact is stable with and without the node at its edge over a range of d (it
    unzips node by node), and the state the sweep follows keeps its nodes until they must
    go - the corrector's own release from the last set. Released in advance by the
    extrapolated edge (with the edge zone's profile shifted inward: 213 -> 173 corrector
    iterations over the 631-node retract's grid steps), the sweep reached the pull-off one
    resolution step earlier on a 60-nm member of the Fig 4 family
    (tests/test_estimate_members.py): another state of the branch."""
    if getattr(state, "edge_from", None) is None:
        return None
    d_p, m_p = state.edge_from
    m_s = disk_size(state.active)
    if state.d == d_p or not m_s or not m_p or m_s - m_p < EDGE_MIN_NODES:
        return None
    x = (d - state.d) / (state.d - d_p)
    if not x > 0:
        return None
    n = state.active.size
    m = int(min(n, round(m_s + (m_s - m_p) * min(x, EDGE_MAX_RATIO))))
    out = np.zeros(n, bool)
    out[:m] = True
    return out


def trace_steps(problem, d_values, *, branch, tol, start=None, max_iter=40, on_state=None,
                on_jump=None, progress=None):
    """Follow the stable equilibrium through the separations ``d_values`` (m).

    Parameters
    ----------
    problem : ContactProblem
    d_values : sequence of float
        Separations in the order they are visited (decreasing for an approach).
    branch : str
        Label of the branch (``"approach"`` or ``"retract"``).
    tol : float
        Residual tolerance (m) every state must meet.
    start : State, optional
        Converged state at d_values[0] to continue from (else solved from w = 0).
    on_state : callable(State), optional
        Called with each converged grid state as soon as it exists (writes it to disk).
    on_jump : callable(Jump), optional
        Called with each fold and its landing as soon as it is found.
    progress : callable(int), optional
        Called with the number of grid steps finished.

    Raises
    ------
    ConvergenceError
        If a grid separation cannot be reached with a converged, stable state even after
        step halving and an energy-descent landing. States already passed to ``on_state``
        are kept by the caller.
    """
    sweep = Sweep(branch)
    try:
        return _trace(sweep, problem, d_values, branch=branch, tol=tol, start=start,
                      max_iter=max_iter, on_state=on_state, on_jump=on_jump,
                      progress=progress)
    except ConvergenceError as exc:
        # every failure carries the states computed so far and the separation it happened at
        if exc.d is None and math.isfinite(sweep.d_current):
            new = ConvergenceError(exc.args[0], d=sweep.d_current)
            new.sweep = sweep
            raise new from None
        if getattr(exc, "sweep", None) is None:
            exc.sweep = sweep
        raise


def _trace(sweep, problem, d_values, *, branch, tol, start, max_iter, on_state, on_jump,
           progress):
    """The body of :func:`trace_steps`, filling ``sweep`` as it goes."""
    t0 = time.perf_counter()
    d_values = [float(x) for x in d_values]
    sweep.d_current = d_values[0]
    if start is None:
        state = solve_complementarity(problem, d_values[0], np.zeros(problem.grid.n), tol=tol,
                            max_iter=max_iter)
        sweep.n_solves += 1
        if not (state.converged and state.stable):
            state = land(problem, d_values[0], np.zeros(problem.grid.n), tol=tol,
                         max_iter=max_iter)
            sweep.n_solves += 1
        _check(state, "first state", tol, sweep)
    else:
        state = start
    sweep.states.append(state)
    if on_state:
        on_state(state)
    g_state = total_force(problem, state)
    # a law that softens beyond a node's stiffness somewhere the surfaces can reach: nodes
    # snap on their own and the states depend on the path (no stagnation exit there)
    trapped = problem.surface_force_stiffness()[0] >= 1.0
    t_state = _tangent(problem, state)
    # the rhythm of the trace this one resumes (a checkpoint's state of this branch), else
    # fresh; the start itself is left as it came
    rhythm = snap.SnapRhythm.restored(state.snap_rhythm, branch)
    for k, d_next in enumerate(d_values[1:], start=1):
        grid_step = d_next - state.d
        step = grid_step
        min_step = abs(grid_step) * MIN_STEP_FRACTION
        solves_here, jumps_here, crawl_run = 0, 0, 0
        beyond = None       # a stable state past a fold that the energy check turned down
        fold = _Bracket(grid_step, min_step)
        fold.see(state, t_state, problem)
        # the plain halving (no bracket): on a lattice-trapped grid, and as the fallback of a
        # grid step whose bracketed fold's landing did not polish (restarted from its start)
        halving = trapped or not BRACKETED
        start_here = (state, g_state, t_state)
        edge_off = False    # an edge-predicted step of this grid step was turned down
        n_start = int(np.count_nonzero(state.active))
        crawling = False    # folds in a row at the smallest step: the step stalls at once
        while state.d != d_next:
            # each fold apart from the last (a contact unzipping node by node past a meniscus
            # edge) brings its own budget; a crawl is cut by crawl_run below; so does each
            # contact node the accepted states released or added (progress: near a pull-off
            # the edge races across ~100 nodes of a fine band within one grid step)
            moved = abs(int(np.count_nonzero(state.active)) - n_start)
            if crawling or solves_here >= MAX_SOLVES_PER_STEP * (1 + jumps_here) \
                    + SOLVES_PER_EDGE_NODE * moved:
                # the folds of the crawl are not physical snaps: keep them out of the result
                crawl = sweep.jumps[len(sweep.jumps) - jumps_here:] if jumps_here else []
                del sweep.jumps[len(sweep.jumps) - jumps_here:]
                # accepted steps keep collapsing to the smallest size without a fold: the
                # branch crawls (e.g. the Hertz closure's inner problem turning non-unique)
                why = (f"{len(crawl)} folds in a row at the smallest step, none of them a "
                       "branch the model continues" if crawl else
                       f"{solves_here} solves, converged states only at the smallest steps")
                exc = ConvergenceError(
                    f"continuation stalled between d = {state.d * 1e9:.6g} and "
                    f"{d_next * 1e9:.6g} nm: {why} ({abs(step) * 1e9:.3g} nm)",
                    d=state.d, residual=state.residual, n_iter=state.n_iter)
                exc.sweep = sweep
                raise exc
            solves_here += 1
            aimed = False       # the trial is the rhythm's (:meth:`snap.SnapRhythm.aim`)
            if fold.far is None or halving:
                d_try = state.d + step
                if snap.SNAP_RHYTHM and not halving:
                    plain = d_try
                    d_try = rhythm.aim(state.d, d_try, min_step, math.copysign(1.0, grid_step))
                    aimed = d_try != plain
                if (d_next - d_try) * math.copysign(1.0, grid_step) < 0 or \
                        abs(d_next - d_try) < 0.5 * min_step:
                    d_try = d_next
            elif fold.located(state):
                # the fold is bracketed to the resolution and the far end was turned down by
                # a decision solve from this very state: no stable state continues the branch
                d_try = fold.far
            else:
                d_try = fold.trial(state, sweep.work)
                if abs(d_try - state.d) > abs(step):
                    # the predictor reaches only this far (a step turned down above for the
                    # corrector's distance from it, not for a fold)
                    d_try = state.d + step
            sweep.d_current = d_try
            # the smallest step decides a fold: its corrector gets the whole budget; a larger
            # step that stagnates is only halved - unless a node softens beyond its own
            # stiffness (it snaps on its own: a slow corrector there is the lattice, and a
            # different path of halvings lands on other lattice states)
            smallest = abs(d_try - state.d) <= min_step * 1.5
            # the extrapolated edge only on a healthy step: a fold's trials and its decision
            # keep the set of the last state (the fold must not hang on the predictor), and
            # a lattice-trapped grid keeps the path it always took
            edge = EDGE_PREDICTOR and not halving and fold.far is None and not smallest \
                and not edge_off and edge_set(state, d_try) is not None
            w_pred, act = _predict(problem, state, d_try, t_state,
                                   edge)
            if fold.far is not None and fold.located(state):
                new = None          # decided already: straight to the landing
            else:
                stall = None if smallest or trapped else STALL_ITER
                budget = max_iter if smallest or trapped or TRIAL_MAX_ITER is None \
                    else min(max_iter, TRIAL_MAX_ITER)
                if smallest and not trapped and snap.CYCLE_PROBE_ITER and rhythm.folds:
                    new = snap.decide(problem, d_try, w_pred, tol, budget, act, state.lu,
                                      sweep.work)
                else:
                    new = solve_complementarity(problem, d_try, w_pred, tol=tol,
                                                max_iter=budget, active0=act,
                                                factor=state.lu, stall_iter=stall,
                                                stats=sweep.work)
                sweep.n_solves += 1
                if edge and not _accept(new, w_pred, d_try, problem, act):
                    # the extrapolated edge did not lead to an acceptable state: the step is
                    # halved (no fold's bracket opens on it) and the rest of this grid step
                    # keeps the last state's own set, as without the edge predictor, so that
                    # whether and where a fold is bracketed never hangs on it (retrying the
                    # same step with the last state's set instead cost a second solve for
                    # steps that set turns down as well: 18 of 91 on the Fig 4 disk at 100
                    # nodes, whose coarse edge moves by a node or two)
                    sweep.work["edge_rejected"] = sweep.work.get("edge_rejected", 0) + 1
                    edge_off = True
                if fold.far is not None:
                    sweep.work["fold_solves"] = sweep.work.get("fold_solves", 0) + 1
            accepted, why = False, None
            healthy = RELEASED_ACCEPT and not halving and fold.far is None and not smallest
            if new is not None and _accept(new, w_pred, d_try, problem, act, healthy):
                g_new = total_force(problem, new)
                share = FOLD_ENERGY_SHARE_MIN_STEP if smallest else FOLD_ENERGY_SHARE
                accepted = not crossed_fold(problem, state, new, g_state, g_new, share)
                if not accepted:
                    beyond, why = new, "rejected_energy"
            elif new is not None:
                why = ("rejected_correction" if new.converged and new.stable
                       else "rejected_unconverged")
                if why == "rejected_correction" and not crossed_fold(
                        problem, state, new, g_state, total_force(problem, new)):
                    # a stable state that released no more energy than one branch can: most
                    # likely the same branch, farther from the prediction than the corrector
                    # may go (the predictor's frozen contact set): halved, no bracket. Only
                    # the search's path hangs on this, never an acceptance: a step across a
                    # fold can pass the energy test too (measured: Fig 4's jump-in, 1.2 ->
                    # 1.1 nm on 632 nodes, converges in contact within the bound), and the
                    # halved trials bracket that fold at their next turned-down step
                    why = "rejected_predictor"
            if why:
                sweep.work[why] = sweep.work.get(why, 0) + 1
            if accepted:
                last = abs(step if halving else d_try - state.d)
                # the edge predictor's second point (None after a landing: a new piece)
                # 0 where the set is not a disk (read as no edge; a checkpoint keeps numbers)
                new.edge_from = (state.d, disk_size(state.active) or 0)
                state, g_state = new, g_new
                t_state = _tangent(problem, state)
                fold.see(state, t_state, problem)
                step = math.copysign(min(2 * last, abs(grid_step)), grid_step)
                if fold.far is not None and state.d == fold.far:
                    # the far end was no fold (a predictor too far from the branch): on with
                    # the whole step
                    fold.clear()
                    step = grid_step
                continue
            if halving:
                # a lattice-trapped grid (nodes snap on their own): the states reached depend
                # on the path of the steps, and the plain halving's path is kept - no bracket
                if abs(step) > min_step * 1.5:
                    step *= 0.5
                    continue
            else:
                k = int(round(abs(d_try - state.d) / min_step))
                if why == "rejected_predictor" and aimed:
                    # the rhythm's trial was too far for the predictor: the halving below
                    # must take over (the aim would repeat the same trial to the stall)
                    rhythm.forget_aim()
                if (why == "rejected_predictor" or edge) and k > 1:
                    # half the distance, in whole resolution steps (the trials' lattice)
                    step = math.copysign(max(1, k // 2) * min_step, grid_step)
                    continue
                if new is not None:
                    fold.reject(d_try, decided=smallest)
                    if not fold.located(state):
                        continue
                d_try = fold.far
            # Fold: no stable state continues the branch beyond state.d.
            landed = None
            if snap.NEXT_NODE_LANDING and not halving:
                # a node snapping across the lattice: the corrector from the disk a node or
                # two further (the way the edge goes: it recedes on a retract), used only if
                # it is plainly the descent's landing, a lattice snap, and the branch goes
                # on from it (:func:`snap.next_node_holds`: else it may be a metastable state
                # one node in where the descent pulls off)
                n0 = sweep.work.get("solves", 0)
                near = land_next_node(problem, d_try, state,
                                      -1 if grid_step > 0 else 1, tol=tol, stats=sweep.work,
                                      stall_iter=STALL_ITER)
                if near is not None and lattice_snap(problem, state, near, g_state,
                                                     total_force(problem, near)):
                    if snap.next_node_holds(
                            (near, total_force(problem, near), _tangent(problem, near)),
                            d_try, min_step, math.copysign(1.0, grid_step),
                            _smallest_step(problem, tol, max_iter, sweep.work)):
                        landed = near
                        sweep.work["next_node_landings"] = \
                            sweep.work.get("next_node_landings", 0) + 1
                    else:
                        sweep.work["next_node_refused_short"] = \
                            sweep.work.get("next_node_refused_short", 0) + 1
                sweep.n_solves += sweep.work.get("solves", 0) - n0
            if landed is None:
                landed = land(problem, d_try, state.w, tol=tol, max_iter=max_iter)
                sweep.n_solves += 1
            if not (landed.converged and landed.stable) and beyond is not None:
                # the descent stalled (a steep law's landing polished onto a saddle); the
                # corrector already found the branch beyond the fold: start Newton there
                landed = solve_complementarity(problem, d_try, beyond.w, tol=tol,
                                               max_iter=max_iter, active0=beyond.active)
                sweep.n_solves += 1
                beyond = None
            if not (landed.converged and landed.stable) and not halving and jumps_here == 0:
                # the fallback: the landing from this fold did not polish (a near-trapped grid
                # where the states reached depend on the path): the grid step once more from
                # its start by plain halving, the path this search replaced (nothing of the
                # step was passed on yet: no jump, no state)
                sweep.work["fold_fallbacks"] = sweep.work.get("fold_fallbacks", 0) + 1
                halving, beyond = True, None
                rhythm.clear()
                state, g_state, t_state = start_here
                fold.restart(state, t_state, problem)
                step = grid_step
                continue
            _check(landed, f"landing after the fold at d = {state.d * 1e9:.6g} nm", tol, sweep)
            g_landed = total_force(problem, landed)
            fold.clear()
            if not halving:
                step = math.copysign(min_step, grid_step)
            if lattice_snap(problem, state, landed, g_state, g_landed):
                sweep.work["lattice_snaps"] = sweep.work.get("lattice_snaps", 0) + 1
                rhythm.snapped(state.d, min_step, math.copysign(1.0, grid_step))
                state, g_state, beyond = landed, g_landed, None
                t_state = _tangent(problem, state)
                fold.restart(state, t_state, problem)
                continue
            rhythm.clear()
            sweep.jumps.append(Jump(branch, state.d, d_try, abs(d_try - state.d), state, landed))
            if on_jump:
                on_jump(sweep.jumps[-1])
            jumps_here += 1
            last = sweep.jumps[-2] if len(sweep.jumps) > 1 and jumps_here > 1 else None
            crawl_run = (crawl_run + 1 if last is not None
                         and abs(state.d - last.d_land) <= CRAWL_STEPS * min_step else 1)
            if crawl_run > MAX_JUMPS_PER_STEP:
                # fold after fold at the smallest step: not a physical snap but a branch the
                # model cannot continue (e.g. the Hertz closure's inner problem non-unique);
                # a flag, not an exhausted count: the budget's per-edge-node part would let a
                # crawl that moves a node per fold go on to the end of the grid step
                crawling = True
            state, g_state = landed, g_landed
            t_state = _tangent(problem, state)
            fold.restart(state, t_state, problem)
        # the rhythm as this grid state leaves it: a trace resumed from it goes on with it
        state.snap_rhythm = rhythm.snapshot(branch)
        sweep.states.append(state)
        if on_state:
            on_state(state)
        if progress:
            progress(k)
    sweep.wall_time = time.perf_counter() - t0
    return sweep


def _check(state, what, tol, sweep):
    """Raise ConvergenceError (carrying the partial ``sweep``) unless state is converged+stable."""
    if state.converged and state.stable:
        return
    if not state.converged:
        msg = f"{what}: Newton did not reach the tolerance {tol:.3g} m"
    else:
        msg = f"{what}: the converged state is unstable (not an energy minimum)"
    exc = ConvergenceError(msg, d=state.d, residual=state.residual, n_iter=state.n_iter)
    exc.sweep = sweep
    raise exc
