"""The coarser members of the error estimate, solved only where the headline numbers are read.

A member of the grid family (:func:`femadh.runner.estimates.coarser_members`) used to trace the
whole sweep again - every state, every fold halved down from the full grid step - to give
the handful of numbers the estimate compares: the largest adhesion, the forces at the deepest
separation, the folds, the energy they release, the contact radius where F_ex vanishes. Each
of them is read off at most a few states of the fine run, so the member solves those states
only, each by Newton from the fine run's committed state there carried to the member's grid
(:func:`femadh.discretisation.moving.interpolate_state`):

- the deepest separation: one state (F_LJ and F_ex there);
- the largest adhesion: the grid states around the fine run's peak (walked on while the
  member's own grid maximum lies further out), then the same bounded search between them as
  the fine run's (:func:`femadh.runner.estimates.peak_adhesion`);
- each fold: the one grid step that holds the fine run's fold, traced from the member's
  state at its start with the stepping continuation (the same halvings, the same resolution:
  the fold located and landed on exactly as a whole trace would in that step);
- the contact radius at zero force: the grid states around the fine run's sign change.

A member state is the member's equilibrium on the fine run's branch at that separation; a
whole trace reaches the same state where its branch is the same (measured on the Fig 3 scene's
family, spacings 15-240 nm: F_LJ at the deepest separation identical to the last digit).
Anything the reduced member cannot reproduce - a state that does not converge, is unstable or
refused by a guard, a fold that is not in the fine run's step, a sign change that moved - is
not guessed: :func:`reduced_member` returns None and the member is traced whole, as before.
"""
import math

import numpy as np

#: grid states the member may walk past the fine run's peak looking for its own grid maximum
PEAK_WALK = 3


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
    if (getattr(scene, "grid", None) or {}).get("follow"):
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
        st = solve_state(self.problem, c.d, w0, tol=self.scene.tolerance,
                         max_iter=self.scene.max_iter, **kw)
        self.solves += 1
        if not (st.converged and st.stable):
            raise _NotReduced(f"the state at d = {c.d * 1e9:.6g} nm ({branch}) did not "
                              "converge to a stable state from the fine run's")
        check_state(self.problem, st, self.member)     # GuardError: traced whole (refused)
        self.cache[key] = st
        return st

    def f_ex(self, st):
        from ..contact.forces import state_forces

        return state_forces(self.problem, st)[2]


def _peak(m, sink, snaps):
    """(F, d) of the member's largest adhesion: its grid maximum near the fine run's, then
    the bounded search between the grid states around it."""
    from .estimates import peak_adhesion

    branch, _, prev, best, nxt = sink.peak
    states = snaps[branch]
    i = next(j for j, s in enumerate(states) if s is best)
    n = len(states)
    k = i
    for _ in range(PEAK_WALK + 1):
        f = {j: m.f_ex(m.state(branch, states, j)) for j in (k - 1, k, k + 1) if 0 <= j < n}
        top = max(f, key=lambda j: (f[j], -abs(j - k)))
        if top == k:
            break
        k = top
    else:
        raise _NotReduced("the member's largest adhesion is not near the fine run's")
    if abs(k - i) > PEAK_WALK:
        raise _NotReduced("the member's largest adhesion is not near the fine run's")
    st = m.state(branch, states, k)
    if prev is None or nxt is None or k == 0 or k == n - 1:
        # the fine run's peak is at a branch end (no bracket): the grid value, as there
        return float(m.f_ex(st)), float(st.d)
    F, d, _ = peak_adhesion(m.problem, m.state(branch, states, k - 1), st,
                            m.state(branch, states, k + 1), m.scene)
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


def _folds(m, res, snaps):
    """The member's folds in the grid steps of the fine run's, in the same order: a list of
    (branch, d_fold, energy released)."""
    from ..contact import trace
    from ..errors import ConvergenceError

    out = []
    for (branch, k), fine_jumps in sorted(_fold_steps(res, snaps).items(),
                                          key=lambda kv: (kv[0][0] != "approach", kv[0][1])):
        states = snaps[branch]
        start = m.state(branch, states, k)
        try:
            sw = trace(m.problem, [states[k].d, states[k + 1].d], branch=branch,
                       tol=m.scene.tolerance, start=start, max_iter=m.scene.max_iter)
        except ConvergenceError as exc:
            raise _NotReduced(f"the fold's step did not trace ({exc})") from None
        m.solves += sw.n_solves
        if len(sw.jumps) != len(fine_jumps):
            raise _NotReduced(f"{len(sw.jumps)} folds in the member's step at d = "
                              f"{states[k].d * 1e9:.6g} nm, {len(fine_jumps)} in the fine run's")
        for jump in sw.jumps:
            released = float(m.problem.energy(jump.before.w, jump.d_land)
                             - m.problem.energy(jump.after.w, jump.d_land))
            out.append((branch, jump.d_fold, released))
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
    window = [j for j in range(ks[0] - 1, ks[0] + 3) if 0 <= j < len(f)]
    sts = [m.state(branch, snaps[branch], j) for j in window]
    rc = _zero_crossing([s.d for s in sts], [m.f_ex(s) for s in sts], [s.r_c for s in sts])
    if not math.isfinite(rc):
        raise _NotReduced(f"the member's F_ex does not change sign where the fine run's does "
                          f"({branch})")
    return rc


def reduced_member(scene, member, problem, sink, res):
    """The member's headline numbers from the states they are read at (see the module
    docstring), or (None, why) where the member must be traced whole.

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

    Returns
    -------
    (dict or None, str or int)
        The member's headline {quantity: value} (the quantities the fine run has) and the
        number of corrector solves it took; or None and the reason it cannot stand in.
    """
    from ..errors import FemadhError
    from ..scene import build_problem

    why = eligible(scene, problem, sink)
    if why:
        return None, why
    snaps = sink.committed
    try:
        m = _Member(member, problem, member, build_problem(member))
        hl = {}
        fine = res.headline
        if "F_LJ_deepest_N" in fine or "F_ex_deepest_N" in fine:
            from ..contact.forces import state_forces

            st = m.state("approach", snaps["approach"], len(snaps["approach"]) - 1)
            f_lj, _, f_ex = state_forces(m.problem, st)
            hl.update(d_deepest_m=float(st.d), F_LJ_deepest_N=float(f_lj),
                      F_ex_deepest_N=float(f_ex))
        if "max_adhesion_N" in fine and sink.peak is not None:
            hl["max_adhesion_N"], hl["d_at_max_adhesion_m"] = _peak(m, sink, snaps)
        if res.jumps:
            folds = _folds(m, res, snaps)
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
