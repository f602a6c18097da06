"""A contact unzipping or zipping node by node: its lattice snaps, and how the stepping
keeps them cheap.

A *snap* is a fold of the discrete branch: past its last stable separation no stable state
continues the branch close to the prediction, and the surface lands elsewhere
(:mod:`femadh.contact.landing`). A contact's snap - the jump-in or the pull-off of paper 1
(Fig 4; the sigma-gap h >= sigma of eq 8 on the surface of eqs 6 and 10) - releases ~150x the work of the
resolution step it happens in, and is a jump. A *lattice snap* releases no more than that
work (:func:`femadh.contact.stepping.lattice_snap`): one node leaving (or joining) the
contact, because on a grid the contact edge can only move node by node. Near a pull-off the
edge recedes through many nodes in a row, each a micro-fold of its own; the stepping steps
over them (they continue the branch; whether one shows depends on the path of the step
halvings, not on the physics).

Each lattice snap would cost a fold's whole search: the bracketing, the decision solve at
the smallest step with the corrector's whole budget, and the energy descent's landing
(issue 21; validation/results/snap_cost.md: 85 nodes released within one grid step of the
532-node slider, ~10 solves each). Three things here make it cheap, each switchable, and
measured to move no fold off its lattice point and no state's contact set:

- the next snap expected from the rhythm of the last three (:class:`SnapRhythm`,
  SNAP_RHYTHM): the unzipping's folds come at spacings that change slowly, so the first
  trial aims just short of the next one and the branch is then crept to it one resolution
  step at a time;
- a fold's decision cut short where the corrector goes round a cycle of contact sets
  (:func:`decide`, :func:`cycling`, CYCLE_PROBE_ITER): a turned-down micro-fold's corrector
  alternates between the disks of m and m - 1 nodes with repeating residuals, and never
  converges in the whole budget;
- a single node's snap landed by the corrector from the disk a node or two further
  (:func:`femadh.contact.landing.land_next_node`, NEXT_NODE_LANDING), kept only where the
  branch goes on from it (:func:`next_node_holds`): beside a pull-off the corrector can find
  a metastable state one node in where the energy descent leaves the contact.

The rhythm is the stepping's only memory across grid steps besides the state itself; it is
kept on each committed grid state (:meth:`SnapRhythm.snapshot`) so that a run resumed from
its checkpoint mid-unzipping is the uninterrupted run to the bit.

References
----------
Paper 1 (/work/shared/papers/adhesion-aspects-in-mems-nems.txt): eqs 6 and 10 (the
surface's equations off and in contact), eq 8 (the sigma-gap), Fig 4 (the jump-out near
d = 1.18 nm that ends the unzipping; validation/scenes/paper1_fig4.toml).
"""
from .complementarity import solve_complementarity

#: a contact unzipping node by node (issue 21): after three lattice snaps in a rhythm the next
#: one is expected as far past the last as the last was past the one before
#: (:class:`SnapRhythm`);
#: the first trial aims SNAP_MARGIN resolution steps short of it, then the branch is crept
#: one resolution step at a time (each the decision of a fold, whole budget: 1-2 iterations
#: while the branch continues) until SNAP_CREEP steps past it, where the doubling resumes.
#: Measured on the sigma = 0.489 nm, p/psat 0.15 slider's retract (532 nodes, the grid step
#: 1.2 -> 1.4 nm, validation/results/snap_cost.md): 85 nodes released at folds 28, 28, 26, 25,
#: 23, ... 3, 2, 1 resolution steps apart, each found by doubling and bisection in ~10 solves
SNAP_RHYTHM = True
SNAP_MARGIN, SNAP_CREEP = 2, 4
#: ... only while the snaps are at most this many resolution steps apart (a rhythm, not two
#: snaps far apart on the branch)
SNAP_RHYTHM_MAX = 128
#: a single node's snap landed first by the corrector from the disk moved by a node or two
#: (:func:`femadh.contact.landing.land_next_node`), the energy descent only where that fails
#: or is not plainly the descent's landing
NEXT_NODE_LANDING = True


class SnapRhythm:
    """Where the next lattice snap of a contact unzipping node by node is expected.

    Records the last three lattice-snap folds (the last stable separations before them, m);
    where their two distances (in resolution steps) agree within a factor of 2 (a rhythm;
    measured on the Fig 4 disk at 90 nodes: snaps 261, 88, 59 and 31 steps apart, the
    first pair 3x apart is none, the later ones are; at 100 nodes 58 and 36 steps apart,
    a rhythm that aims at a fourth snap which does not come: the pull-off), the last
    distance s predicts the next fold at F + s past
    the last one F. :meth:`aim` bends a trial outside a fold's bracket to that prediction: first to
    SNAP_MARGIN steps short of it, then one resolution step at a time up to SNAP_CREEP steps
    past it (the fold is then located by a decision solve one step past its last stable
    lattice point - the same point the doubling and bisection find on a connected branch
    piece, in fewer and cheaper solves). Cleared by a jump or the halving fallback; its aim
    is dropped when the aimed trial is too far for the predictor (:meth:`forget_aim`).

    Kept across one branch's trace, and on every grid state the trace commits as that state
    leaves it (:meth:`snapshot`, ``State.snap_rhythm``): a trace of the same branch started
    from such a state - a checkpoint's, resumed (:mod:`femadh.runner.checkpoint`) - goes on
    with it (:meth:`restored`), so a resume mid-unzipping takes the uninterrupted run's very
    trials and reaches its states to the bit. The next branch, a regrid or a widening
    (a state carried to another grid) start without it, which moves only where trials go -
    the retract traced again from each grid state without the rhythm reaches the same folds
    and states (tests/test_snap_cost.py), though not always to the last bit (another path of
    trials)."""

    def __init__(self):
        self.clear()

    def clear(self):
        self.folds, self.target, self.creep_to = [], None, None

    def snapshot(self, branch):
        """The rhythm as plain numbers (a checkpoint keeps them): (branch, folds (m, the
        last three at most), target (m or None), creep_to (m or None))."""
        return (branch, tuple(self.folds), self.target, self.creep_to)

    @classmethod
    def restored(cls, snapshot, branch):
        """The rhythm of a :meth:`snapshot` taken on ``branch``; a fresh one for None or a
        snapshot of another branch (an approach's rhythm says nothing of the retract)."""
        out = cls()
        if snapshot is not None and snapshot[0] == branch:
            _, folds, out.target, out.creep_to = snapshot
            out.folds = list(folds)
        return out

    def snapped(self, d_fold, min_step, direction):
        """A lattice snap whose departing branch was last stable at ``d_fold`` (m)."""
        self.folds = (self.folds + [d_fold])[-3:]
        self.target = self.creep_to = None
        if len(self.folds) < 3:
            return
        s0, s = (int(round((b - a) * direction / min_step))
                 for a, b in zip(self.folds, self.folds[1:]))
        if 1 <= s <= SNAP_RHYTHM_MAX and 0.5 * s0 <= s <= 2 * s0:
            self.target = d_fold + direction * (s - SNAP_MARGIN) * min_step
            self.creep_to = d_fold + direction * (s + SNAP_CREEP) * min_step

    def forget_aim(self):
        """The aimed trial was turned down as too far for the predictor: no aim until the
        next snap (the halving takes over; the snaps seen are kept)."""
        self.target = self.creep_to = None

    def aim(self, d, d_try, min_step, direction):
        """The trial separation from the state at ``d`` instead of ``d_try`` (m): the
        expected fold's lattice point short of it, the next resolution step while creeping
        past it, else ``d_try`` (the rhythm is then forgotten)."""
        if self.target is None:
            return d_try
        ahead = int(round((self.target - d) * direction / min_step))
        if ahead >= 1:
            # straight to the lattice point short of the expected fold (the step after a
            # landing would be the smallest, doubled from there)
            return d + direction * ahead * min_step
        if (self.creep_to - d) * direction > 0.5 * min_step:
            return d + direction * min_step
        self.target = self.creep_to = None
        return d_try


#: a fold's decision solve (the smallest step, whole budget) is first run for this many
#: corrector iterations; one that has not converged by then and whose last iterations go
#: round a cycle of contact sets (:func:`cycling`) is decided there as turned down (else the
#: whole budget from the start: the same solve as without the probe). Measured on the
#: sigma = 0.489 nm slider's retract (validation/results/snap_cost.md): every decision that
#: turned a micro-fold down alternated between the disk of m and of m - 1 nodes from its
#: second iteration to its 40th (the edge node tensile on m, below sigma on m - 1), the
#: residual of each set repeating to 6e-6 relative or closer from the third iteration on (to
#: the last bit in some); the whole budget run beside every decision cut short converged at none
#: (snap_cost.md). Only after a lattice snap since the last jump or fallback (a contact
#: unzipping): a turned-down decision elsewhere (a jump-in, a pull-off with no snap before
#: it) runs its whole budget without a cycle and the probe's iterations would be spent
#: again. The pull-off that ends an unzipping is probed too, and pays them again (its
#: decision does not cycle). 0: no probe
CYCLE_PROBE_ITER = 8
#: ... the cycle's length in iterations (a node in and out of the contact)
CYCLE_PERIOD = 2
#: ... and how closely the residual of an iteration must repeat the one CYCLE_PERIOD before
#: it (relative; measured 6e-6 at most on the cycles above, 4e-9 to 1e-7 on most, while a
#: corrector on its way to converge cuts its residual by orders of magnitude per iteration)
CYCLE_RTOL = 1e-3


def decide(problem, d, w_pred, tol, budget, act, factor, work):
    """The decision solve at the smallest step: the corrector with the whole ``budget``,
    cut short after CYCLE_PROBE_ITER iterations where it cycles (:func:`cycling`); the
    work of both attempts is added to ``work``."""
    probe = {"history": []}
    new = solve_complementarity(problem, d, w_pred, tol=tol,
                                max_iter=min(budget, CYCLE_PROBE_ITER), active0=act,
                                factor=factor, stall_iter=None, stats=probe)
    for key in ("solves", "iterations", "factorisations", "stagnated"):
        work[key] = work.get(key, 0) + probe.get(key, 0)
    if new.converged or budget <= CYCLE_PROBE_ITER:
        return new      # the very solve the whole budget runs (nothing else depends on it)
    if cycling(probe["history"]):
        work["decisions_cycling"] = work.get("decisions_cycling", 0) + 1
        return new
    return solve_complementarity(problem, d, w_pred, tol=tol, max_iter=budget, active0=act,
                                 factor=factor, stall_iter=None, stats=work)


def cycling(history):
    """True if the corrector's last 3 CYCLE_PERIOD iterations go round one cycle three
    times: each with the contact set (the same nodes, not only as many) and, to CYCLE_RTOL,
    the residual of the iteration CYCLE_PERIOD before it, the contact set changing at every
    one of them - a node let go and taken back, its residual not falling (the first two
    iterations, from the prediction, are not on the cycle: CYCLE_PROBE_ITER = 8 sees it three
    times). A corrector that moves on through other sets of the same sizes (a node let go
    at one place and another taken at the next) is not on a cycle. ``history``: (residual
    (m), contact nodes, set unchanged, the set as bytes) per iteration
    (:func:`solve_complementarity`'s stats); the sets are compared as those bytes, a
    comparison of n bytes per iteration."""
    n = 2 * CYCLE_PERIOD
    if len(history) < n + CYCLE_PERIOD:
        return False
    last = history[-n - CYCLE_PERIOD:]
    if any(same for _, _, same, _ in last):
        return False
    return all(last[i][3] == last[i + CYCLE_PERIOD][3]
               and abs(last[i][0] - last[i + CYCLE_PERIOD][0]) <= CYCLE_RTOL * last[i][0]
               for i in range(n))


#: a single node's snap landed by the corrector (:func:`~femadh.contact.landing.land_next_node`)
#: is kept only where the
#: branch goes on from it for this many resolution steps (each a stable state accepted as a
#: healthy smallest step); else the energy descent lands it. The descent can leave the
#: contact from the same start (a pull-off) where the corrector found a stable state one
#: node in, downhill of the start and a lattice snap by its energy - a metastable state
#: beside its own fold. Measured on the Fig 4 disk (tests/test_snap_cost.py): at 110, 200
#: and 270 nodes the candidate's branch ended at the very next resolution step (the fold
#: moved by one step, F_ex before it by up to 5.4 %); on 50..400 nodes every candidate
#: that held for 2 steps was the descent's landing
NEXT_NODE_HOLD_STEPS = 2


def next_node_holds(start, d_land, min_step, direction, step):
    """True if the branch continues from a next-node landing at ``d_land`` (m) for
    NEXT_NODE_HOLD_STEPS resolution steps ``min_step`` (m) in ``direction`` (+-1).

    Parameters
    ----------
    start : object
        The landing as ``step`` takes it (the stepping's (state, total force, tangent)).
    step : callable(object, float) -> object or None
        The stepping's healthy smallest step from the first argument to the separation d
        (m): the same kind of object at d, or None where it fails - a converged stable state
        close to its prediction that releases no more than the lattice bound
        (:func:`femadh.contact.stepping._smallest_step`). Its solves count in the sweep's
        work; none of its states is kept (the sweep goes on from the landing as before).
    """
    at = start
    for k in range(1, NEXT_NODE_HOLD_STEPS + 1):
        at = step(at, d_land + direction * k * min_step)
        if at is None:
            return False
    return True
