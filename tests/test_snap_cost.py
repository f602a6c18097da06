"""A contact unzipping node by node (issue 21): a single node's snap landed by the corrector
from the disk a node or two further, and the next snap expected from the rhythm of the last
ones - the same landings and the same folds as the energy descent and the doubling and
bisection they replace (validation/results/snap_cost.md)."""
import dataclasses

import numpy as np
import pytest

from conftest import FIG4_TOL, fig4_problem, fig4_sweeps
from femadh.contact import landing, snap, stepping
from femadh.contact.stepping import lattice_snap, total_force

TOL = FIG4_TOL
#: how far a next-node landing's surface may lie from the descent's (m): measured at most
#: 6.9e-19 m over the 33 next-node landings taken on the Fig 4 disk at 50, 60, ..., 400 nodes
#: (the corrector's tolerance is 1e-19 m; the two polishes stop at different iterates), up
#: to 5e-19 m on the sigma = 0.489 nm slider's 25 (validation/results/snap_cost.md)
LANDING_TOL = 1e-18
#: the resolution step of the Fig 4 sweeps (0.2-nm grid steps)
H = 0.2e-9 * stepping.MIN_STEP_FRACTION


@pytest.fixture(scope="module")
def unzip():
    """The Fig 4 disk on 100 uniform nodes: its retract sheds three nodes across the lattice
    before the pull-off (tests/test_newton.py), each a next-node landing; the descent's
    landing of each is computed beside it."""
    p = fig4_problem(100)
    seen = []
    orig = stepping.land_next_node

    def compared(problem, d, state, sign, *, tol, **k):
        st = orig(problem, d, state, sign, tol=tol, **k)
        ref = landing.land(problem, d, state.w, tol=tol, max_iter=40)
        seen.append((d, state, st, ref, sign))
        return st
    stepping.land_next_node = compared
    try:
        ap, re = fig4_sweeps(p)
    finally:
        stepping.land_next_node = orig
    return p, ap, re, seen


def test_a_next_node_landing_is_the_descents_landing(unzip):
    """Every landing the corrector found from the disk a node or two further and the sweep
    took (a lattice snap) is the energy descent's own: the same contact set, the surface
    the same to LANDING_TOL (measured here 1.9e-20 to 1.4e-19 m), the energy
    the same to 1.4e-13 relative at most (measured; 1e-12 allowed)."""
    p, ap, re, seen = unzip
    taken = [(d, s, st, ref) for d, s, st, ref, _ in seen if st is not None and lattice_snap(
        p, s, st, total_force(p, s), total_force(p, st))]
    assert len(taken) == ap.work.get("next_node_landings", 0) + \
        re.work.get("next_node_landings", 0) >= 3
    for d, s, st, ref in taken:
        assert ref.converged and ref.stable
        assert np.array_equal(st.active, ref.active)
        assert np.max(np.abs(st.w - ref.w)) <= LANDING_TOL
        e, e_ref = p.energy(st.w, d), p.energy(ref.w, d)
        assert abs(e - e_ref) <= 1e-12 * abs(e_ref)
        # a single node released across the lattice
        assert s.active.sum() - st.active.sum() in (1, 2)


def test_a_contact_snap_is_landed_by_the_descent(unzip):
    """The pull-off (the contact's snap, ~140x its step's work) is never a next-node
    landing: whatever the corrector reaches from the disk a node or two smaller fails the
    lattice-snap test, and the jump's landing is the descent's (no contact left)."""
    p, ap, re, seen = unzip
    j = re.jumps[-1]
    fold = [x for x in seen if x[1] is j.before]
    assert len(fold) == 1
    d, s, st, ref, sign = fold[0]
    assert sign == -1
    assert st is None or not lattice_snap(p, s, st, total_force(p, s), total_force(p, st))
    assert not j.after.active.any()
    assert np.max(np.abs(j.after.w - ref.w)) <= 3 * TOL


def test_a_landing_above_the_descents_start_is_refused(unzip):
    """The descent never climbs: the straight path from the descent's start (the last state
    projected onto the floor) to a state of higher energy fails the downhill test, the path
    to the descent's own landing of a lattice snap passes it."""
    p, ap, re, seen = unzip
    d, s, st, ref, _ = next(x for x in seen if x[2] is not None)
    start = np.minimum(s.w, p.contour(d) - p.sigma)
    e0 = p.energy(start, d)
    assert landing._downhill(p, d, start, e0, ref.w)
    # back up from the landing to where the descent started: uphill at the end
    assert p.energy(ref.w, d) < e0
    assert not landing._downhill(p, d, ref.w, p.energy(ref.w, d), start)


def test_a_barrier_midway_along_the_path_is_refused(unzip, monkeypatch):
    """The downhill test samples the path, not only its end: the first snap's real start and
    descent landing (downhill, checked above) with a narrow energy barrier put midway
    between them (a bump of 10x the energy the snap releases, a sixteenth of the path wide,
    standing in for a ridge the descent's surface could not cross) is refused, though
    both ends are as before."""
    p, ap, re, seen = unzip
    d, s, st, ref, _ = next(x for x in seen if x[2] is not None)
    start = np.minimum(s.w, p.contour(d) - p.sigma)
    e0, e1 = p.energy(start, d), p.energy(ref.w, d)
    assert landing._downhill(p, d, start, e0, ref.w) and e1 < e0
    energy, span = p.energy, ref.w - start

    def ridged(w, d_):
        t = float((w - start) @ span / (span @ span))
        return energy(w, d_) + 10 * (e0 - e1) * np.exp(-((t - 0.5) * 32) ** 2)
    monkeypatch.setattr(p, "energy", ridged)
    assert ridged(ref.w, d) - e1 < 1e-6 * (e0 - e1)     # the ends as before
    assert not landing._downhill(p, d, start, ridged(start, d), ref.w)


def test_the_snap_rhythm_aims_at_the_next_fold():
    """The rhythm: folds 28 and 26 resolution steps apart (the sigma = 0.489 nm slider's
    unzipping, snap_cost.md) put the first trial SNAP_MARGIN steps short of the fold 26
    steps past the last, then creep one step at a time to SNAP_CREEP past it; snaps 3x apart
    in spacing are no rhythm; a jump forgets it."""
    r = snap.SnapRhythm()
    for k in (0, 28, 54):
        r.snapped(k * H, H, 1.0)
    land = 55 * H
    assert round(r.aim(land, land + H, H, 1.0) / H) == 54 + 26 - snap.SNAP_MARGIN
    d = (54 + 26 - snap.SNAP_MARGIN) * H
    assert round((r.aim(d, d + 64 * H, H, 1.0) - d) / H) == 1
    d = (54 + 26 + snap.SNAP_CREEP) * H
    assert r.aim(d, d + 64 * H, H, 1.0) == d + 64 * H
    assert r.target is None
    q = snap.SnapRhythm()
    for k in (0, 10, 40):
        q.snapped(k * H, H, 1.0)
    assert q.target is None
    # on a decreasing d (an approach) the same, mirrored
    m = snap.SnapRhythm()
    for k in (0, -28, -54):
        m.snapped(k * H, H, -1.0)
    assert round(m.aim(-55 * H, -56 * H, H, -1.0) / H) == -(54 + 26 - snap.SNAP_MARGIN)
    m.clear()
    assert m.aim(-55 * H, -56 * H, H, -1.0) == -56 * H


def test_the_unzipping_folds_and_states_are_those_of_the_old_path(unzip, monkeypatch):
    """With the rhythm, the next-node landing and the decision's cycle probe off (the path
    before them): the same folds
    at the same lattice points (to the round-off of d, 1e-6 of a resolution step), the same
    grid states to the tolerance."""
    p, ap, re, _ = unzip
    monkeypatch.setattr(snap, "SNAP_RHYTHM", False)
    monkeypatch.setattr(snap, "NEXT_NODE_LANDING", False)
    monkeypatch.setattr(snap, "CYCLE_PROBE_ITER", 0)
    ap0, re0 = fig4_sweeps(p)
    for new, old in ((ap, ap0), (re, re0)):
        assert [round(j.d_fold / H, 6) for j in new.jumps] == \
            [round(j.d_fold / H, 6) for j in old.jumps]
        assert [s.d for s in new.states] == [s.d for s in old.states]
        for a, b in zip(new.states, old.states):
            assert np.array_equal(a.active, b.active)
            assert np.max(np.abs(a.w - b.w)) <= LANDING_TOL
    assert re.work["lattice_snaps"] == re0.work["lattice_snaps"]


def _same_path(p, new_sweeps, old_sweeps):
    """Assert two (approach, retract) pairs have the same folds (lattice points), grid
    states and landings: contact sets equal, surfaces within LANDING_TOL."""
    for new, old in zip(new_sweeps, old_sweeps):
        assert [round(j.d_fold / H, 6) for j in new.jumps] == \
            [round(j.d_fold / H, 6) for j in old.jumps]
        assert [s.d for s in new.states] == [s.d for s in old.states]
        pairs = list(zip(new.states, old.states)) + [
            (x, y) for a, b in zip(new.jumps, old.jumps)
            for x, y in ((a.before, b.before), (a.after, b.after))]
        for a, b in pairs:
            assert np.array_equal(a.active, b.active)
            assert np.max(np.abs(a.w - b.w)) <= LANDING_TOL


@pytest.mark.parametrize("n", [110, 200])
def test_a_next_node_landing_beside_a_pull_off_is_left_to_the_descent(n, monkeypatch):
    """At 110 and 200 nodes the last node's snap before the pull-off has a candidate one
    node in (8 -> 7, 13 -> 12 nodes) that is stable, downhill of the descent's start and a
    lattice snap - while the descent from the same start leaves the contact (the pull-off,
    one resolution step earlier; F_ex before it 5.4 % apart at 110 nodes). The candidate's
    branch ends at the next resolution step (:func:`snap.next_node_holds`), so the
    descent lands it: the folds, grid states and landings are the old path's (all three
    switches off), and so with each switch on alone (measured on 50, 60, ..., 400 nodes: all
    36 the same)."""
    p = fig4_problem(n)
    refused = []
    orig = snap.next_node_holds

    def holds(start, *a):
        ok = orig(start, *a)
        if not ok:
            refused.append(start[0])
        return ok
    monkeypatch.setattr(snap, "next_node_holds", holds)
    on = fig4_sweeps(p)
    assert len(refused) == 1 and on[1].jumps[-1].after.active.sum() == 0
    assert refused[0].active.sum() == on[1].jumps[-1].before.active.sum() - 1
    switches = {"SNAP_RHYTHM": False, "NEXT_NODE_LANDING": False, "CYCLE_PROBE_ITER": 0}
    for name, value in switches.items():
        monkeypatch.setattr(snap, name, value)
    _same_path(p, on, fig4_sweeps(p))
    for name in switches:
        with monkeypatch.context() as m:
            m.setattr(snap, name, {"SNAP_RHYTHM": True, "NEXT_NODE_LANDING": True,
                                       "CYCLE_PROBE_ITER": 8}[name])
            _same_path(p, on, fig4_sweeps(p))


def test_an_aimed_trial_too_far_for_the_predictor_gives_way_to_the_halving(monkeypatch):
    """A trial of the rhythm that the stepping turns down as too far for the predictor (a
    stand-in: every aimed trial converges to a stable state farther from its prediction than
    the corrector may go, within the one-branch energy bound) is halved like any such step:
    the sweep goes on to the same folds and grid states, instead of aiming at the same
    point until the grid step's budget runs out ("continuation stalled")."""
    p = fig4_problem(100)
    ref = fig4_sweeps(p)
    aimed, turned = set(), []
    aim, accept, crossed, solve = (snap.SnapRhythm.aim, stepping._accept,
                                   stepping.crossed_fold, stepping.solve_complementarity)

    def aim_seen(self, d, d_try, min_step, direction):
        out = aim(self, d, d_try, min_step, direction)
        if out != d_try:
            aimed.add(out)
        return out

    def accept_not_aimed(new, pred_w, d, *a, **k):
        return d not in aimed and accept(new, pred_w, d, *a, **k)

    def crossed_not_aimed(problem, old, new, *a, **k):
        return new.d not in aimed and crossed(problem, old, new, *a, **k)

    def solve_aimed_stable(problem, d, *a, **k):
        # the aimed trial (here past the last snap, where the corrector would not converge
        # and a bracket would open) reads as a stable state: "rejected_predictor"
        st = solve(problem, d, *a, **k)
        if d in aimed:
            turned.append(d)
            st = dataclasses.replace(st, converged=True, stable=True)
        return st
    monkeypatch.setattr(stepping, "solve_complementarity", solve_aimed_stable)
    monkeypatch.setattr(snap, "solve_complementarity", solve_aimed_stable)
    monkeypatch.setattr(snap.SnapRhythm, "aim", aim_seen)
    monkeypatch.setattr(stepping, "_accept", accept_not_aimed)
    monkeypatch.setattr(stepping, "crossed_fold", crossed_not_aimed)
    got = fig4_sweeps(p)
    assert aimed and turned
    _same_path(p, got, ref)


def test_a_resume_with_no_rhythm_reaches_the_same_states():
    """A trace without the rhythm (a regrid, a widening, a resume re-solved without its
    checkpoint start without it; tests/test_snaphome_resume.py: a checkpoint keeps it):
    the retract resumed from each of its grid states, its rhythm dropped (its edge
    predictor's point kept) reaches the same folds and grid states as the uninterrupted one
    - the rhythm moves only where trials go, never a fold (the 36 sizes above: rhythm on and
    off the same)."""
    p = fig4_problem(100)
    aimed = []
    aim = snap.SnapRhythm.aim

    def aim_seen(self, d, d_try, min_step, direction):
        out = aim(self, d, d_try, min_step, direction)
        aimed.extend([out] if out != d_try else [])
        return out
    snap.SnapRhythm.aim = aim_seen
    try:
        ap, re = fig4_sweeps(p)
    finally:
        snap.SnapRhythm.aim = aim
    assert re.work["lattice_snaps"] == 3 and aimed     # the rhythm aimed on this retract
    from conftest import FIG4_D_VALUES
    from femadh.contact import trace
    d_values = list(FIG4_D_VALUES[::-1])
    for k in range(1, len(re.states) - 1):
        part = trace(p, d_values[k:], branch="retract", tol=TOL,
                     start=dataclasses.replace(re.states[k], snap_rhythm=None))
        tail = dataclasses.replace(re, states=re.states[k:],
                                   jumps=[j for j in re.jumps if j.d_fold >= re.states[k].d])
        _same_path(p, (part,), (tail,))


def _taken(unzip):
    """(d, last state, next-node landing) of the first lattice snap the sweep took."""
    p, ap, re, seen = unzip
    return p, next((d, s, st) for d, s, st, _, _ in seen if st is not None)


@pytest.mark.parametrize("what", ["unstable", "edge_kept", "edge_grown", "uphill"])
def test_a_next_node_candidate_that_is_not_plainly_the_landing_is_refused(unzip, what,
                                                                          monkeypatch):
    """The corrector's candidate is refused (None: the descent decides) when it is not a
    stable state (the Hessian's inertia), when its edge did not move by 1-2 nodes the way
    the edge goes (kept, or grown on a retract), or when its energy lies above the descent's
    start. Each guard is tried on the real candidate of the first snap with that one
    property changed (the corrector itself replaced by a stand-in returning it); unchanged,
    the candidate is taken."""
    p, (d, s, st) = _taken(unzip)
    bad = dataclasses.replace(st, active=st.active.copy(), w=st.w.copy())
    m = int(s.active.sum())
    if what == "unstable":
        bad.stable = False
    elif what == "edge_kept":
        bad.active[:m] = True
    elif what == "edge_grown":
        bad.active[:m + 1] = True
    else:
        # the whole surface 1 nm further from the sphere: gaps >= sigma kept, the elastic
        # energy far above the start's (checked)
        bad.w = st.w - 1e-9
        start = np.minimum(s.w, p.contour(d) - p.sigma)
        assert p.energy(bad.w, d) > p.energy(start, d)
    monkeypatch.setattr(landing, "solve_complementarity", lambda *a, **k: bad)
    assert landing.land_next_node(p, d, s, -1, tol=TOL) is None
    good = dataclasses.replace(st)
    monkeypatch.setattr(landing, "solve_complementarity", lambda *a, **k: good)
    assert landing.land_next_node(p, d, s, -1, tol=TOL) is good


def test_every_next_node_landing_taken_is_a_lattice_snap(monkeypatch):
    """A candidate that is the contact's snap (here the descent's own landing of the
    pull-off, handed to the stepping as the corrector's candidate) is not taken as a
    next-node landing: the lattice-snap test sends it to the descent, and the count of
    next-node landings is the count of lattice snaps they were (3 on this retract)."""
    p = fig4_problem(100)
    orig = stepping.land_next_node

    def pull_off_too(problem, d, state, sign, *, tol, **k):
        st = orig(problem, d, state, sign, tol=tol, **k)
        if st is None and state.active.any():
            st = landing.land(problem, d, state.w, tol=tol, max_iter=40)
        return st
    monkeypatch.setattr(stepping, "land_next_node", pull_off_too)
    ap, re = fig4_sweeps(p)
    assert len(re.jumps) == 1 and not re.jumps[0].after.active.any()
    assert re.work["next_node_landings"] == re.work["lattice_snaps"] == 3


#: a decision's corrector history on the sigma = 0.489 nm slider's retract (532 nodes, the
#: micro-fold at 1.2884 nm; validation/results/snap_cost.md): (residual (m), contact nodes,
#: set unchanged, the set) per iteration - the disk of 73 and 72 nodes in turn from the
#: second iteration on, each residual repeating to 6e-6 relative from the third
def _disk(m, n=532):
    """The contact disk of m nodes as the corrector's history holds it (bytes)."""
    return (np.arange(n) < m).tobytes()


CYCLE = [(r, m, False, _disk(m)) for r, m in (
    (2.6511e-21, 73), (1.3992e-15, 72), (1.5452737311835257e-15, 73),
    (1.3988823954798885e-15, 72), (1.5452641917231115e-15, 73),
    (1.3988824008565625e-15, 72), (1.5452641915163163e-15, 73),
    (1.3988823985818158e-15, 72))]


def test_a_corrector_going_round_a_cycle_of_contact_sets_is_told():
    """The measured cycle is one; a corrector whose residual falls by orders of magnitude
    while its set still changes is not (a Newton converging as the edge settles), nor one
    whose set stood still at an iteration, nor one alternating between other node counts
    at the same residuals, nor fewer than three rounds."""
    assert snap.cycling(CYCLE)
    falling = [(10.0 ** -(10 + 2 * k), 72 + k % 2, False, _disk(72 + k % 2))
               for k in range(8)]
    assert not snap.cycling(falling)
    assert not snap.cycling(CYCLE[:-1] + [(CYCLE[-1][0], 72, True, _disk(72))])
    assert not snap.cycling(CYCLE[:-1] + [(CYCLE[-1][0], 71, False, _disk(71))])
    assert not snap.cycling(CYCLE[3:])


def test_a_decision_not_cut_short_is_the_whole_budgets_solve():
    """Where the probe neither converges nor cycles (the Fig 4 jump-in's decision one
    resolution step past its fold: 40 iterations without converging, tests/test_newton.py)
    and where it converges (a step on the branch), the decision returns the very state the
    whole budget gives - to the last bit - and counts the work of both attempts."""
    p = fig4_problem(100)
    ap, _ = fig4_sweeps(p)
    j = ap.jumps[0]
    seen = []
    for before, d in ((j.before, j.d_land), (ap.states[-1], ap.states[-1].d - 0.05e-9)):
        w, act = stepping._predict(p, before, d)
        full = stepping.solve_complementarity(p, d, w, tol=TOL, max_iter=40, active0=act,
                                              factor=before.lu)
        work = {}
        got = snap.decide(p, d, w, TOL, 40, act, before.lu, work)
        assert got.converged == full.converged and got.n_iter == full.n_iter
        assert np.array_equal(got.w, full.w) and np.array_equal(got.active, full.active)
        probe = min(snap.CYCLE_PROBE_ITER, full.n_iter)
        assert work["iterations"] == full.n_iter + (0 if full.converged else probe)
        assert "decisions_cycling" not in work
        seen.append((full.converged, full.n_iter))
    assert seen[0] == (False, 40)
    assert seen[1][0] and seen[1][1] <= snap.CYCLE_PROBE_ITER
