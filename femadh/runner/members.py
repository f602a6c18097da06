"""The coarser members of the error estimate, solved only where the headline numbers are read.

A member of the grid family (:func:`femadh.runner.estimates.coarser_members`) used to trace the
whole sweep again - every state, every fold halved down from the full grid step - to give
the handful of numbers the estimate compares: the largest adhesion, the forces at the deepest
separation, the folds, the energy they release, the contact radius where F_ex vanishes. Each
of them is read off at most a few states of the fine run, so the member solves those states
only, each by Newton from the fine run's committed state there carried to the member's grid
(:func:`femadh.discretisation.moving.interpolate_state`):

- the deepest separation: one state (F_LJ and F_ex there) - none where the members placed by
  its contact edge (:func:`deepest_locked`) give those numbers' grid part;
- the largest adhesion: the grid states around the fine run's peak (walked on while the
  member's own grid maximum lies further out), then the same bounded search between them as
  the fine run's (:func:`femadh.runner.peak.peak_adhesion`), first in a window around the
  fine run's peak; where the window misses, the kink model searches the rest of the bracket
  (:func:`femadh.runner.peak.kink_peak`);
- each fold: continued on the fine run's lattice of smallest steps (the stepping's own in
  that grid step) from a few lattice steps before the fine run's fold, with the stepping's
  acceptance rules, landing and lattice-snap test (:func:`_lattice_fold`): the same fold
  point and landing as a whole trace, in ~10-20 solves where halving the grid step down to
  the fold and landing takes ~40; the grid step traced whole where that finds none;
- the contact radius at zero force: the two grid states of the fine run's sign change, where
  the member's F_ex changes sign between them too; else the four around it.

A member state is the member's equilibrium on the fine run's branch at that separation; a
whole trace reaches the same state where its branch is the same (measured on the Fig 3 scene's
family, spacings 15-240 nm: F_LJ at the deepest separation identical to the last digit; Fig 3
and Fig 4 at their defaults: every grid part within 1.4e-6 of its number of the whole
trace's, folds and hysteresis identical). A state where Newton from the carried state ends
on a saddle (a node at the contact edge between its two minima) is landed from the carried
state onto the minimum of its basin (:meth:`_Member._off_saddle`). Anything the reduced
member cannot reproduce - a state that does not converge, is unstable or refused by a
guard, a fold that is not near the fine run's, a landing elsewhere than the fine run's, a
sign change that moved - is not guessed: :func:`reduced_member` says why and the member is traced whole, as before. So are a
uniform grid's members (N/2, N/4 may resolve the contact so coarsely that their branches
differ from the fine one's: folds the fine run does not have, which no state of it shows).

The forces at the deepest separation also get members placed by the contact edge
(:func:`deepest_locked`): one state each.
"""
import math

import numpy as np

from ..contact.stepping import MIN_STEP_FRACTION
from ..estimate.guards import TRAPPING_LIMIT
from .peak import off_branch, reuse_factor

#: grid states the member may walk past the fine run's peak looking for its own grid maximum
PEAK_WALK = 3
#: half-width of a member's peak search around the fine run's peak, in grid steps (the Fig 4
#: members' peaks lie 0.02 grid steps from the fine run's, Fig 3's 0.06); an optimum at the
#: window's edge is searched again over the whole bracket
PEAK_WINDOW = 0.125
#: a member state that Newton from the fine run's carried state ends on a saddle is landed
#: by energy descent (:meth:`_Member._off_saddle`) and kept where it stays on the fine run's
#: branch (False: the member is traced whole, as before)
LAND_SADDLE = True
#: where a member's windowed peak search misses, the rest of the bracket is searched by the
#: kink model (femadh.runner.peak.kink_peak: F_ex(d) as smooth pieces joined at the kinks
#: where a node joins or leaves the contact) from every state the window's search solved,
#: which stops at the window's edge (WINDOW_EDGE_STOP). False: the windowed search runs to
#: its end and the whole bracket is searched again by the bounded search (as before)
KINK_PEAK = True
#: a member's windowed peak search stops as soon as its best fresh state lies within this
#: fraction of the window's width of its edge (femadh.runner.peak.WindowMiss), and the whole
#: bracket is searched by the kink model from the states it solved
#: (femadh.runner.peak.kink_peak; with KINK_PEAK): the slider meniscus scene's members
#: peak 0.25-0.35 of a grid step from the fine run's, beyond the window, whose search
#: walked 16 fresh states to its edge and the whole bracket's Brent search 19 more
WINDOW_EDGE_STOP = 0.1
#: a member's fold is continued on the fine run's lattice from near the fine run's fold
#: (False: the fine run's grid step that holds it is traced, halvings and all)
LATTICE_FOLDS = True
#: False: a member's lattice walk steps one lattice point at a time up to the fine run's fold
#: and doubles only beyond it; True: doubles from its start (the walk as it was)
DOUBLE_TO_FOLD = False
#: corrector solves a member's fold search may take (a healthy one: 10-20)
MAX_FOLD_SOLVES = 80
#: a member's contact radius at zero force from the fine run's sign-change interval alone
#: where the member's F_ex changes sign there too (2 states per branch); its neighbours
#: (4 states) only where it does not. False: the four states always (as before)
ZERO_FORCE_PAIR_FIRST = True
#: a member's fold decision (the one-lattice-step trial beyond its last state) gives up when
#: its corrector stops making progress (STALL_ITER), as the stepping's larger trials do,
#: instead of running to max_iter: beyond a fold no equilibrium is near and the failing
#: corrector took the whole budget (Fig 4 at 1e-3: 296 of the members' 409 Newton
#: iterations; with it 118, every fold, landing and estimate bit for bit the same at 1e-2,
#: 3e-3 and 1e-3). A decision cut short by a slow corrector that would have converged is no
#: fold here: the landing from the last state then ends on the same branch, releasing no
#: more than the step's work (:func:`~femadh.contact.stepping.lattice_snap`), and the walk
#: goes on from it. False: the whole budget (as the fine run's stepping gives its own)
FOLD_DECISION_STALL = True


class _NotReduced(Exception):
    """The reduced member cannot stand in for the whole trace (the reason in its message)."""


def eligible(scene, problem, sink):
    """Why the member must be traced whole (a string), or None where the reduced member may
    stand in: stepping continuation, the complementarity sigma-gap or smooth laws, no
    instrument (its readout needs every state), a grid that stays put (a band following the
    edge exchanges grids mid-sweep), every committed state of the fine run in memory (a
    resumed run holds only a few)."""
    if scene.continuation == "arclength":
        return "arclength continuation"
    if problem.contact_model == "hertz-closure":
        return "the Hertz closure"
    if getattr(scene, "instrument", None) is not None:
        return "an instrument"
    if getattr(scene, "grid", None) is None:
        # an explicit uniform grid's members (N/2, N/4) may resolve the contact so coarsely
        # that their branches differ from the fine one's - the Fig 8 scene's N = 100 and 50
        # members unzip in 3 and 4 folds where N = 200 has one, and a member state solved
        # from the fine run's misses the folds the fine run does not have; the banded
        # families femadh plans keep their members below the trapping limit
        return "a uniform grid (its members are traced whole)"
    if scene.grid.get("follow"):
        return "a band following the edge"
    committed = getattr(sink, "committed", None) or {}
    for branch, rows in sink.rows.items():
        snaps = committed.get(branch, [])
        if len(snaps) != len(rows) or any(
                s.w is None or np.ndim(s.w) != 1 or s.w.size != problem.grid.n for s in snaps):
            return f"the {branch} branch's states are not all in memory"
    return None


class _Member:
    """A member's problem and the states it solved, by the fine run's state index."""

    def __init__(self, scene, fine, member, problem):
        self.scene, self.fine, self.member, self.problem = scene, fine, member, problem
        self.cache = {}
        self.solves = 0

    def state(self, branch, snaps, k):
        """The member's equilibrium at the separation of the fine run's k-th committed state
        of ``branch``, by Newton from that state carried to the member's grid."""
        from ..contact import solve_state
        from ..discretisation.moving import interpolate_state
        from ..estimate.guards import check_state

        key = (branch, k)
        if key in self.cache:
            return self.cache[key]
        c = snaps[k]
        w0, active0 = interpolate_state(self.fine, self.problem, c.d, c.w)
        kw = {} if active0 is None else {"active0": active0}
        # the factorisation of the member's nearest state on the branch serves the chord
        # steps (as a sweep's previous step does) on a grid where that is cheaper than the
        # chord steps it makes (femadh.runner.peak.reuse_factor: a grid step away, a small
        # member's own factorisation converges in fewer evaluations of the laws)
        near = [j for b, j in self.cache if b == branch]
        if near and reuse_factor(self.problem):
            kw["factor"] = self.cache[(branch, min(near, key=lambda j: abs(j - k)))].lu
        st = solve_state(self.problem, c.d, w0, tol=self.scene.tolerance,
                         max_iter=self.scene.max_iter, **kw)
        self.solves += 1
        if st.converged and not st.stable and LAND_SADDLE:
            st = self._off_saddle(st, w0)
        if not (st.converged and st.stable):
            raise _NotReduced(f"the state at d = {c.d * 1e9:.6g} nm ({branch}) did not "
                              "converge to a stable state from the fine run's")
        check_state(self.problem, st, self.member)     # GuardError: traced whole (refused)
        self.cache[key] = st
        return st

    def _off_saddle(self, st, w0):
        """The stable state an energy descent reaches from the fine run's state carried to
        the member's grid (``w0``), where Newton from it converged to the saddle ``st``:
        the minimum in whose basin the carried state lies, kept where it stays on that
        branch (within a quarter of every gap of w0) on the saddle's contact set; else
        ``st``.

        Near the contact edge a free node whose gap sits just above sigma (the member's
        nodes 1.41x further apart than the fine run's, the LJ softening steeper over a
        node's share) has two minima, the node nearer sigma and further out, and Newton's
        full steps from the carried state can overshoot onto the saddle between them: the
        stiction map's sigma = 0.489 nm, p/psat 0.15 at d = -5 nm on its 19.06-nm member
        (one negative Hessian eigenvalue, its mode on the first free nodes; the first's gap
        0.5435 nm at the saddle, 0.5628 carried, 0.5768 at the minimum). The descent
        (:func:`~femadh.contact.landing.land`, the stepping's own landing) from the carried
        state reaches the member's whole trace's deepest state there to 8e-15 nm
        (tests/test_member_saddle.py)."""
        from ..contact.landing import land

        landed = land(self.problem, st.d, w0, tol=self.scene.tolerance,
                      max_iter=self.scene.max_iter)
        self.solves += 1
        if not (landed.converged and landed.stable) or \
                off_branch(self.problem, st.d, landed.w, w0) or \
                not np.array_equal(landed.active, st.active):
            # and the saddle's contact set: a node of two minima moved to sigma changes its
            # gap 13 % (0.5628 nm carried -> 0.489), within off_branch's quarter, so a state
            # with it (and a neighbour) in contact - another branch: 209 contact nodes on the
            # case of tests/test_member_saddle.py, F_ex 2.2e-3 off - passes that test; the
            # basin's minimum keeps the saddle's set (208 nodes there)
            return st
        return landed

    def near(self, snap, d, branch=True):
        """The member's stable equilibrium at separation d by Newton from the fine run's state
        ``snap`` (at a nearby separation) carried to the member's grid, or None where Newton
        does not end on a stable state (or, with ``branch``, ends further than a quarter of a
        gap from the start: another branch)."""
        from ..contact import solve_state
        from ..discretisation.moving import interpolate_state

        w0, active0 = interpolate_state(self.fine, self.problem, d, snap.w)
        kw = {} if active0 is None else {"active0": active0}
        st = solve_state(self.problem, d, w0, tol=self.scene.tolerance,
                         max_iter=self.scene.max_iter, **kw)
        self.solves += 1
        if not (st.converged and st.stable):
            return None
        if branch and off_branch(self.problem, d, st.w, w0):
            return None
        return st

    def carried(self, snap, d):
        """The fine run's displacements of ``snap`` on the member's grid at separation d."""
        from ..discretisation.moving import interpolate_state

        return interpolate_state(self.fine, self.problem, d, snap.w)[0]

    def released(self, before, after, d_land):
        """Energy (J) a snap from ``before`` to ``after`` releases at the landing's d."""
        return float(self.problem.energy(before.w, d_land)
                     - self.problem.energy(after.w, d_land))

    def f_ex(self, st):
        from ..contact.forces import state_forces

        return state_forces(self.problem, st)[2]


def _peak(m, sink, snaps, d_fine=None):
    """(F, d) of the member's largest adhesion: its grid maximum near the fine run's on the
    same piece of the branch (between the folds: :func:`femadh.runner.peak.pieces`), then
    the bounded search between the states around it - a fold's landing or last state where
    the piece ends there, as the fine run's bracket."""
    from .peak import peak_adhesion, pieces

    branch, _, prev, best, nxt = sink.peak
    states = snaps[branch]
    at = {id(s): j for j, s in enumerate(states)}
    where = [(p, lands, folds) for p, lands, folds in pieces(sink, branch)
             if any(s is best for s in p)]
    if not where:
        raise _NotReduced("the fine run's peak state is not among its committed states")
    piece, lands, folds = where[0]
    i = next(j for j, s in enumerate(piece) if s is best)
    fold_states = {}

    def member(j):
        """The member's state at the piece's j-th state: a committed state's as
        :meth:`_Member.state`; a fold's last state or landing by Newton from it carried."""
        s = piece[j]
        if id(s) in at:
            return m.state(branch, states, at[id(s)])
        if id(s) not in fold_states:
            st = m.near(s, s.d)
            if st is None:
                raise _NotReduced(f"the member has no state on the fine run's piece at the "
                                  f"fold's d = {s.d * 1e9:.6g} nm ({branch})")
            fold_states[id(s)] = st
        return fold_states[id(s)]
    n = len(piece)
    k = i
    for _ in range(PEAK_WALK + 1):
        f = {j: m.f_ex(member(j)) for j in (k - 1, k, k + 1) if 0 <= j < n}
        top = max(f, key=lambda j: (f[j], -abs(j - k)))
        if top == k:
            break
        k = top
    else:
        raise _NotReduced("the member's largest adhesion is not near the fine run's")
    if abs(k - i) > PEAK_WALK:
        raise _NotReduced("the member's largest adhesion is not near the fine run's")
    st = member(k)
    # the piece's ends: a landing brackets its own side, a fold's last state its own
    j_lo = k - 1 if k > 0 else (0 if lands else None)
    j_hi = k + 1 if k < n - 1 else (k if folds else None)
    if prev is None or nxt is None or j_lo is None or j_hi is None:
        # the fine run's peak is at a branch end (no bracket): the grid value, as there
        return float(m.f_ex(st)), float(st.d)
    around = (member(j_lo), st, member(j_hi))
    if k == i and d_fine is not None:
        # the member's peak lies within its grid difference of the fine run's: the search
        # on PEAK_WINDOW of the grid step around it (the same tolerance in d), the whole
        # bracket where the member's optimum ends at the window's edge
        half = PEAK_WINDOW * (abs(piece[j_hi].d - piece[i].d)
                              or abs(piece[i].d - piece[j_lo].d))
        return _window_peak(m.problem, around, m.scene, (d_fine - half, d_fine + half),
                            f_of=m.f_ex)
    F, d, _ = peak_adhesion(m.problem, *around, m.scene, reuse=True)
    return F, d


def _window_peak(problem, around, scene, window, f_of=None):
    """(F, d) of a member's largest adhesion searched first on ``window`` = (lo, hi) around
    the fine run's peak (:func:`~femadh.runner.peak.peak_adhesion` ``within``), kept where
    its optimum lies inside; where it ends at the window's edge (or stops there, with
    KINK_PEAK: WINDOW_EDGE_STOP) the whole bracket of ``around`` = (prev, best, nxt) is
    searched by the kink model from every state the window's search solved (KINK_PEAK), else
    by the bounded search. Fresh states reuse the nearer grid state's factorisation."""
    from .peak import WindowMiss, kink_peak, peak_adhesion

    known = []
    try:
        F, d, tol = peak_adhesion(problem, *around, scene, within=window, reuse=True,
                                  record=known,
                                  edge_stop=WINDOW_EDGE_STOP if KINK_PEAK else None)
        if abs(d - window[0]) > 2 * tol and abs(d - window[1]) > 2 * tol:
            return F, d
    except WindowMiss:
        pass
    if KINK_PEAK:
        # a miss: the whole bracket by the kink model, from every state the window's
        # search solved (femadh.runner.peak.kink_peak)
        F, d, _ = kink_peak(problem, *around, scene, known=known, window=window, reuse=True,
                            f_of=f_of)
        return F, d
    F, d, _ = peak_adhesion(problem, *around, scene, reuse=True)
    return F, d


def _fold_steps(res, snaps):
    """{(branch, k): fine jumps} of the grid steps k -> k+1 that hold the fine run's folds."""
    out = {}
    for j in res.jumps:
        states = snaps.get(j["branch"], [])
        ds = [s.d for s in states]
        sign = math.copysign(1.0, ds[-1] - ds[0]) if len(ds) > 1 else 1.0
        # the step from the last committed separation at or before the fold (along the sweep)
        ks = [k for k in range(len(ds) - 1) if (j["d_fold_m"] - ds[k]) * sign >= 0
              and (ds[k + 1] - j["d_fold_m"]) * sign > 0]
        if not ks:
            raise _NotReduced(f"the fold at d = {j['d_fold_m'] * 1e9:.6g} nm is not between "
                              "two committed states")
        out.setdefault((j["branch"], ks[0]), []).append(j)
    return out


def _step_folds(m, branch, states, k, count):
    """The member's folds in the fine run's grid step k -> k+1 of ``branch``, traced from
    the member's state at its start (the halvings of a whole trace): [(d_fold, released)]."""
    from ..contact import trace
    from ..errors import ConvergenceError

    start = m.state(branch, states, k)
    try:
        sw = trace(m.problem, [states[k].d, states[k + 1].d], branch=branch,
                   tol=m.scene.tolerance, start=start, max_iter=m.scene.max_iter)
    except ConvergenceError as exc:
        raise _NotReduced(f"the fold's step did not trace ({exc})") from None
    m.solves += sw.n_solves
    if len(sw.jumps) != count:
        raise _NotReduced(f"{len(sw.jumps)} folds in the member's step at d = "
                          f"{states[k].d * 1e9:.6g} nm, {count} in the fine run's")
    return [(j.d_fold, m.released(j.before, j.after, j.d_land)) for j in sw.jumps]


def _lattice_fold(m, d_fold, d_land, before, after):
    """(d_fold, released) of the member's fold on the fine run's lattice d_fold + j r
    (r = d_land - d_fold, the fine run's smallest step: the stepping's own lattice in that
    grid step), continued from near the fine run's fold instead of halving the grid step
    down to it.

    The start: Newton from the fine run's last state before its fold (``before``), carried
    to the member's grid, at j = -1, -2, -4, ... until it ends on a stable state within a
    quarter of every gap of the start (near a fold Newton's basin is narrow: the Fig 4
    scene's members reach it 18-31 lattice steps back). From there the stepping's rules on
    the lattice: a tangent predictor, the corrector, a step accepted if it converged to a
    stable state within MAX_CORRECTION_FRACTION of the predicted gaps and released no more
    energy than one branch can (:func:`~femadh.contact.stepping.crossed_fold`), doubled after
    an acceptance and halved after a rejection; the fold is where a one-step move fails. The
    landing one step beyond: the energy descent from the last state
    (:func:`~femadh.contact.landing.land`; where it does not converge the member is traced
    whole, whose trace fails there too); a landing that releases no more than the step's
    work is a node snapping across the lattice and is stepped over (:func:`~femadh.contact.stepping.lattice_snap`), as in a
    whole trace."""
    from ..contact.complementarity import STALL_ITER, solve_complementarity, tangent
    from ..contact.landing import land
    from ..contact.stepping import (FOLD_ENERGY_SHARE, FOLD_ENERGY_SHARE_MIN_STEP,
                                    MAX_CORRECTION_FRACTION, crossed_fold, lattice_snap,
                                    total_force)

    p, sc = m.problem, m.scene
    r = d_land - d_fold
    cap = int(round(1.0 / MIN_STEP_FRACTION))
    j, state = -1, None
    while state is None:
        if -j > cap:
            raise _NotReduced("no member state near the fine run's fold")
        state = m.near(before, d_fold + j * r)
        j = j if state is not None else 2 * j
    g, step, solves = total_force(p, state), 1, 0
    while True:
        if solves > MAX_FOLD_SOLVES or j > cap:
            raise _NotReduced("the member's fold is not within a grid step of the fine run's")
        d = d_fold + (j + step) * r
        w = state.w + tangent(p, state) * (d - state.d) if state.lu is not None else state.w
        act = None if p.sigma is None else state.active | (p.contour(d) - w < p.sigma)
        kw = {} if act is None else {"active0": act}
        new = solve_complementarity(p, d, w, tol=sc.tolerance, max_iter=sc.max_iter,
                                    factor=state.lu,
                                    stall_iter=None if step == 1 and not FOLD_DECISION_STALL
                                    else STALL_ITER,
                                    **kw)
        solves, m.solves = solves + 1, m.solves + 1     # counted as made (a fallback's too)
        ok = new.converged and new.stable and bool(np.all(
            np.abs(new.w - w) <= MAX_CORRECTION_FRACTION * np.maximum(new.h + (new.w - w), 0)
            + 1e-15))
        if ok:
            g_new = total_force(p, new)
            ok = not crossed_fold(p, state, new, g, g_new, FOLD_ENERGY_SHARE_MIN_STEP
                                  if step == 1 else FOLD_ENERGY_SHARE)
        if ok:
            # doubling, but landing on the fine run's fold (j = 0) and trying the next
            # lattice point from there first: the member's fold is most often the fine run's
            # own lattice point, where a doubled trial past it only fails (a stalled solve
            # before the decision at j = 1)
            state, g, j = new, g_new, j + step
            if DOUBLE_TO_FOLD:
                step *= 2
            else:
                step = min(2 * step, -j) if j < 0 else 1 if j == 0 else 2 * step
            continue
        if step > 1:
            step //= 2
            continue
        landed = land(p, d, state.w, tol=sc.tolerance, max_iter=sc.max_iter)
        solves, m.solves = solves + 1, m.solves + 1
        if not (landed.converged and landed.stable):
            # as in a whole trace, whose failure there is the member's (a lattice-trapped
            # member's landing that does not polish: the adaptive run refines): traced whole
            raise _NotReduced(f"the landing after the member's fold at d = "
                              f"{state.d * 1e9:.6g} nm did not converge")
        g_landed = total_force(p, landed)
        if lattice_snap(p, state, landed, g, g_landed):
            # a node snapping across the lattice: the branch goes on (as in a whole trace)
            state, g, j, step = landed, g_landed, j + 1, 1
            continue
        # the member must land where the fine run did (on the branch of its landing, within
        # a quarter of every gap): a member that lands elsewhere - a contact unzipping in
        # several folds on a coarse grid - is not the fine run's picture and is traced whole
        w0 = m.carried(after, d)
        if off_branch(p, d, landed.w, w0):
            raise _NotReduced(f"the member lands elsewhere than the fine run after its fold at "
                              f"d = {state.d * 1e9:.6g} nm")
        return state.d, m.released(state, landed, d)


def _folds(m, res, sink, snaps):
    """The member's folds where the fine run's are, in the same order: a list of
    (branch, d_fold, energy released). Each by :func:`_lattice_fold` from the fine run's
    fold states, or - where that finds none - by tracing the fine run's grid step that holds
    it (:func:`_step_folds`)."""
    out = []
    fine = {(b, d): (before, after) for b, d, _, before, after in getattr(sink, "folds", [])}
    for (branch, k), fine_jumps in sorted(_fold_steps(res, snaps).items(),
                                          key=lambda kv: (kv[0][0] != "approach", kv[0][1])):
        states = snaps[branch]
        try:
            if LATTICE_FOLDS and all((branch, j["d_fold_m"]) in fine for j in fine_jumps):
                got = [_lattice_fold(m, j["d_fold_m"], j["d_land_m"],
                                       *fine[(branch, j["d_fold_m"])]) for j in fine_jumps]
            else:
                got = None
        except _NotReduced:
            got = None
        if got is None:
            got = _step_folds(m, branch, states, k, len(fine_jumps))
        out += [(branch, d, e) for d, e in got]
    return out


def _zero_force_radius(m, res, snaps, branch):
    """The member's contact radius where F_ex changes sign on ``branch`` (the fine run's
    interval and its neighbours), or None where the fine run has none."""
    from .headline import _zero_crossing

    c = res.branches[branch]
    f, r = c["F_ex_N"], c["r_c_m"]
    ks = [k for k in range(len(f) - 1) if r[k] > 0 and r[k + 1] > 0 and f[k] * f[k + 1] <= 0
          and f[k] != f[k + 1]]
    if not ks:
        return None
    k = ks[0]
    if ZERO_FORCE_PAIR_FIRST:
        # the fine run's interval first: where the member's F_ex changes sign there too, its
        # crossing is read off those two states alone (the window's first crossing is the
        # same unless the member's F_ex changes sign twice within three grid steps)
        sts = [m.state(branch, snaps[branch], j) for j in (k, k + 1)]
        rc = _zero_crossing([s.d for s in sts], [m.f_ex(s) for s in sts],
                            [s.r_c for s in sts])
        if math.isfinite(rc):
            return rc
    window = [j for j in range(k - 1, k + 3) if 0 <= j < len(f)]
    sts = [m.state(branch, snaps[branch], j) for j in window]
    rc = _zero_crossing([s.d for s in sts], [m.f_ex(s) for s in sts], [s.r_c for s in sts])
    if not math.isfinite(rc):
        raise _NotReduced(f"the member's F_ex does not change sign where the fine run's does "
                          f"({branch})")
    return rc


def reduced_member(scene, member, problem, sink, res, deepest=True, *, rest=True,
                   resume=None):
    """The member's headline numbers from the states they are read at (see the module
    docstring), or (None, why) where the member must be traced whole.

    In two parts (:class:`ReducedMember`; an adaptive trial's deferred estimate,
    :func:`femadh.runner.estimates.estimate_errors`' ``defer``): ``rest=False`` returns the
    judged numbers and the member's :class:`ReducedMember` in place of the solve count
    (or None and why); ``resume=`` that member then returns what the call in one part
    would have, bit for bit.

    Parameters
    ----------
    scene, member : Scene
        The fine run's scene and the member's (a coarser grid of the same family).
    problem : ContactProblem
        The fine run's problem (its committed states are on its grid).
    sink : Sink
        The fine run's sink: its committed states and its peak.
    res : ContactResult
        The fine run's result: its curves and jumps.
    deepest : bool
        Solve the deepest separation's state (F_LJ and F_ex there); False where the members
        placed by its contact edge (:func:`deepest_locked`) give those numbers' grid part.

    Returns
    -------
    (dict or None, str or int)
        The member's headline {quantity: value} (the quantities the fine run has) and the
        number of corrector solves it took; or None and the reason it cannot stand in.
    """
    if resume is not None:
        return resume.rest()
    rm = ReducedMember(scene, member, problem, sink, res, deepest)
    hl, why = rm.judged()
    if hl is None:
        return hl, why
    return rm.rest() if rest else (hl, rm)


class ReducedMember:
    """:func:`reduced_member` in two parts, on one member problem and one cache of its
    states: :meth:`judged`, the numbers an accuracy loop judges a trial by (the forces at
    the deepest separation, the largest adhesion and where it is:
    :func:`femadh.runner.estimates.judged_errors`), then :meth:`rest`, the folds, the hysteresis
    and the contact radii at zero force. :meth:`rest` continues on the same member problem
    and state cache whenever it is called, so the two parts give the numbers of
    :func:`reduced_member` bit for bit (each member state's Newton start - the carried state,
    the factorisation of its nearest cached neighbour - is the same); an accuracy loop calls
    it only for the trial it keeps (:data:`femadh.runner.estimates.DEFER_UNJUDGED`). Where
    :meth:`judged` reduces but :meth:`rest` does not, the member is traced whole when the
    estimate is completed, while a loop without deferral would have judged the trial on that
    whole trace: then (only) the loop's judgement of the trial can differ (counted 0 of 16
    reducing judged parts on the bundled scenes, validation/results/pace.md).

    Parameters are :func:`reduced_member`'s.
    """

    def __init__(self, scene, member, problem, sink, res, deepest=True):
        self.scene, self.member, self.problem = scene, member, problem
        self.sink, self.res, self.deepest = sink, res, deepest
        self.m = self.hl = None

    def judged(self):
        """(the member's deepest-state forces and largest adhesion as a headline dict, None)
        or (None, why it must be traced whole)."""
        from ..errors import FemadhError
        from ..scene import build_problem

        why = eligible(self.scene, self.problem, self.sink)
        if why:
            return None, why
        snaps, sink, fine = self.sink.committed, self.sink, self.res.headline
        try:
            m = self.m = _Member(self.member, self.problem, self.member,
                                 build_problem(self.member))
            if m.problem.surface_force_stiffness()[0] >= TRAPPING_LIMIT:
                # a law softening beyond a node's own stiffness: nodes snap on their own and
                # the member's states depend on its path, which no state of the fine run shows
                return None, "a lattice-trapped member (traced whole)"
            hl = {}
            if self.deepest and ("F_LJ_deepest_N" in fine or "F_ex_deepest_N" in fine):
                from ..contact.forces import state_forces

                st = m.state("approach", snaps["approach"], len(snaps["approach"]) - 1)
                f_lj, _, f_ex = state_forces(m.problem, st)
                hl.update(d_deepest_m=float(st.d), F_LJ_deepest_N=float(f_lj),
                          F_ex_deepest_N=float(f_ex))
            if "max_adhesion_N" in fine and sink.peak is not None:
                hl["max_adhesion_N"], hl["d_at_max_adhesion_m"] = _peak(
                    m, sink, snaps, fine.get("d_at_max_adhesion_m"))
        except (_NotReduced, FemadhError) as exc:
            return None, str(exc)
        self.hl = hl
        return hl, None

    def rest(self):
        """(the member's whole headline dict, its corrector solves) after :meth:`judged`
        succeeded: its folds, hysteresis and contact radii at zero force added; or (None,
        why) where it must be traced whole."""
        from ..errors import FemadhError

        m, res, sink, hl = self.m, self.res, self.sink, dict(self.hl)
        snaps, fine = sink.committed, res.headline
        try:
            if res.jumps:
                folds = _folds(m, res, sink, snaps)
                ins = [d for b, d, _ in folds if b == "approach"]
                outs = [d for b, d, _ in folds if b == "retract"]
                if ins:
                    hl["jump_in_d_m"] = float(ins[0])
                if outs:
                    hl["jump_out_d_m"] = float(outs[-1])
                if "hysteresis_J" in fine:
                    hl["hysteresis_J"] = float(sum(e for _, _, e in folds))
            for branch in res.branches:
                key = f"r_c_at_zero_force_{branch}_m"
                if math.isfinite(fine.get(key, math.nan)):
                    hl[key] = _zero_force_radius(m, res, snaps, branch)
        except (_NotReduced, FemadhError) as exc:
            return None, str(exc)
        return hl, m.solves


#: fewest band spacings between the centre and the contact edge of a member placed by the
#: edge (coarser members are pre-asymptotic: the Fig 3 scene's F_LJ at the deepest state is
#: 7e-3 off at 15 spacings, 1.3e-3 at 21)
MIN_EDGE_SPACINGS = 12


def contact_edge(problem, snap):
    """Radius (m) of the contact edge of a sigma-gap state between its grid nodes: the gap
    opens beyond the edge like (r - r_e)^(3/2) (an adhesive edge without a stress
    singularity), so the gaps above sigma at the first two free nodes place it; None
    without a contact or where they do not bracket it (the outermost contact node and the
    next)."""
    if problem.sigma is None or snap.active is None or not np.any(snap.active):
        return None
    r = problem.grid.nodes
    a = int(np.flatnonzero(snap.active)[-1])
    if a + 2 >= r.size:
        return None
    gap = problem.contour(snap.d) - snap.w - problem.sigma
    g1, g2 = float(gap[a + 1]), float(gap[a + 2])
    if not (0 < g1 < g2):
        return None
    q = (g2 / g1) ** (2.0 / 3.0)
    r_e = (r[a + 2] - q * r[a + 1]) / (1.0 - q)
    return float(min(max(r_e, r[a]), r[a + 1]))


def locked_spacings(problem, r_e, band, ratio, count=2):
    """Band spacings h_k ~ ratio^k h (k = 1..count) of members whose lattice puts the edge
    at radius ``r_e`` at the same fraction of a spacing as the fine grid's (h_k = r_e /
    (n_k + f), r_e / h = n + f): the discretisation error of a number read at that edge
    changes sign as the edge crosses a node (the Fig 3 scene's F_LJ at the deepest state:
    +1.3e-3, -2.1e-4, +6.7e-4 on members at 170, 120, 85 nm), and is smooth, of order ~2,
    among members at one fraction (-1.6e-3, -8.9e-4, -4.7e-4 at 153, 110, 78.5 nm): the
    members' differences then measure the fine grid's own error. None where the edge is not
    inside the band's uniform part, or a member would have fewer than MIN_EDGE_SPACINGS
    spacings to it."""
    h = float(problem.grid.nodes[1])
    if r_e is None or band is None or r_e + 2 * ratio**count * h > band:
        return None
    x = r_e / h
    f = x - math.floor(x)
    out = []
    for k in range(1, count + 1):
        n_k = round(x / ratio**k - f)
        if n_k < MIN_EDGE_SPACINGS:
            return None
        out.append(r_e / (n_k + f))
    return out


def deepest_locked(scene, problem, sink, ratio, variant):
    """(spacings, [member headlines]) of the members placed by the contact edge of the
    deepest state (:func:`locked_spacings`), each solved at the deepest separation only, by
    Newton from the fine run's state there; None where they cannot be placed or solved
    (the family's own members stand)."""
    from ..contact.forces import state_forces
    from ..errors import FemadhError
    from ..scene import build_problem

    g = getattr(scene, "grid", None)
    if g is None:
        # a uniform grid: members uniform to the analysis radius at the locked spacings (a
        # band over the whole disk). The deepest state is the one contact state at that
        # separation, so a member solved there from the fine run's stands in for its whole
        # trace (the folds a coarse uniform member may add are elsewhere on the sweep): the
        # slider meniscus scene's N = 100, 200, 400 err +1.6e-3, -4e-4, -2.6e-5 in F_LJ
        # there - the edge hopping between nodes - and its N/2 member made N = 400's
        # estimate 15x the error
        a = float(problem.grid.radius)
        g = {"spacing": float(problem.grid.nodes[1]), "band": a, "grading": a}
        why = eligible(scene, problem, sink)
        if why and not why.startswith("a uniform grid"):
            return None
    elif g.get("follow") or eligible(scene, problem, sink):
        return None
    # the deepest state: the approach branch's last (a resumed run reads it back from its
    # fields, the same bits, where the other committed states are not in memory)
    snap = (getattr(sink, "last", None) or {}).get("approach")
    if scene.method != "green" or snap is None or snap.w is None or \
            np.shape(snap.w) != (problem.grid.n,):
        return None
    snaps = [snap]
    spacings = locked_spacings(problem, contact_edge(problem, snap), g.get("band"), ratio)
    if spacings is None:
        return None
    levels = []
    for h in spacings:
        member = variant(scene, grid={**g, "spacing": h})
        try:
            m = _Member(member, problem, member, build_problem(member))
            st = m.state("approach", snaps, 0)
        except (_NotReduced, FemadhError, ValueError):
            return None
        f_lj, _, f_ex = state_forces(m.problem, st)
        levels.append({"F_LJ_deepest_N": float(f_lj), "F_ex_deepest_N": float(f_ex)})
    return spacings, levels
