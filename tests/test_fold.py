"""Where a branch folds, located by a bracket instead of blind halving (femadh.contact.stepping):
the fold is where a brute-force march in fine steps finds it, within one resolution step; it
is the fold the plain halving finds; a fold costs a bounded number of solves; the bisection
fallback and the halving fallback of a landing that does not polish both run and locate the
same fold; the energy descent of a landing stops once it has settled at round-off."""
import math

import numpy as np
import pytest

from femadh.contact import trace
from femadh.contact import landing, stepping
from femadh.contact.forces import state_forces

from conftest import FIG4_D_VALUES as D_VALUES, FIG4_TOL as TOL
from conftest import fig4_problem, fig4_sweeps

#: 100 uniform nodes on the Fig 4 disk (sigma = 0.5 nm): small, and both folds on it
N = 100
#: the resolution step (m): MIN_STEP_FRACTION of the 0.2 nm grid step
H = 0.2e-9 * stepping.MIN_STEP_FRACTION


@pytest.fixture(scope="module")
def fig4():
    p = fig4_problem(N)
    return p, fig4_sweeps(p)


def _halving(monkeypatch, p):
    monkeypatch.setattr(stepping, "BRACKETED", False)
    out = fig4_sweeps(p)
    monkeypatch.setattr(stepping, "BRACKETED", True)
    return out


def test_the_jump_in_is_where_a_brute_force_march_finds_it(fig4):
    """The approach's jump-in (a smooth saddle-node: no contact before it) against a march
    in steps of H/8 from the last grid state before it, each step with its own search (the
    fold then resolved to H/8/1024). The located fold claims: the branch exists at d_fold and
    ends within one resolution step H beyond it. Measured: the march's fold lies 0.50 H
    beyond d_fold (0.73 H on 180 nodes, 0.78 H on 240); the force there is 1.3 % below the
    march's last state (the square-root approach to the fold over 0.5 H), not a tolerance
    of this test but the resolution's share of the jump's 'before' force."""
    p, (ap, _) = fig4
    (j,) = ap.jumps
    assert j.resolution <= H * (1 + 1e-9)
    prev = [s for s in ap.states if s.d > j.d_fold][-1]
    d0 = j.d_fold + 4 * H
    fine = [d0 - k * H / 8 for k in range(64)]
    ref = trace(p, [prev.d] + fine, branch="approach", tol=TOL, start=prev)
    (jr,) = ref.jumps
    assert jr.resolution < H / 1000
    beyond = (j.d_fold - jr.d_fold) / H          # the march's fold past the located one
    assert 0 < beyond <= 1, beyond
    # the march's last state and the located one: the same branch (the march passes d_fold)
    at = [s for s in ref.states if abs(s.d - j.d_fold) < H / 16]
    assert at and np.max(np.abs(at[0].w - j.before.w)) <= 1e-6 * np.max(np.abs(j.before.w))


def test_the_folds_are_the_plain_halvings(fig4, monkeypatch):
    """The bracket's trials lie on the halving's lattice (the grid step's start plus whole
    resolution steps), so the fold is the last lattice point the branch reaches whichever
    trials found it: measured, both folds at the plain halving's separations (to 1e-11 H, the
    round-off of the sums of steps) on 100, 180 and 240 nodes, their states the same to the tolerance - while the bracket
    needs fewer corrector iterations in all (measured 992 against 1074 on this grid; 1021
    against 1558 on the Fig 4 scene's 632-node member)."""
    p, (ap, re) = fig4
    ap0, re0 = _halving(monkeypatch, p)
    for new, old in ((ap, ap0), (re, re0)):
        assert len(new.jumps) == len(old.jumps)
        # the same lattice point, to the round-off of d (sums of steps: 1e-11 H measured)
        assert all(abs(a.d_fold - b.d_fold) <= 1e-6 * H for a, b in zip(new.jumps, old.jumps))
        assert [s.d for s in new.states] == [s.d for s in old.states]
        for a, b in zip(new.states, old.states):
            assert np.max(np.abs(a.w - b.w)) <= 3 * TOL
        for a, b in zip(new.jumps, old.jumps):
            assert np.max(np.abs(a.after.w - b.after.w)) <= 3 * TOL
    assert ap.work["iterations"] + re.work["iterations"] < \
        ap0.work["iterations"] + re0.work["iterations"]


def test_a_fold_costs_a_bounded_number_of_solves(fig4):
    """The jump-in is located in 4 solves inside its bracket (measured; the halving took 22
    from the first turned-down step to the decision), the pull-off with its contact
    unzipping node by node (mostly bisection: no square-root law there) in 24 over
    its four pieces (the pull-off and three nodes shed across the lattice). The cap: at most
    MAX_INDICATOR_TRIALS trials follow the indicator, each pair of trials at least halves
    the bracket, then bisection: a fold from a whole grid step costs at most
    2 log2(1/MIN_STEP_FRACTION) + 2 = 22 solves, each landing's piece its own."""
    p, (ap, re) = fig4
    cap = 2 * round(-math.log2(stepping.MIN_STEP_FRACTION)) + 2
    assert ap.work["fold_solves"] <= 6                          # measured 4
    pieces = len(re.jumps) + re.work.get("lattice_snaps", 0)
    assert re.work["fold_solves"] <= cap * pieces               # measured 24 over 4 pieces
    # the indicator placed the jump-in's trials: no bisection there
    assert ap.work.get("fold_bisections", 0) == 0


def test_the_bisection_fallback_locates_the_same_folds(fig4, monkeypatch):
    """Without the indicator's estimate every trial bisects (the fallback): the same folds,
    at the cost of more solves on the jump-in (measured 4 -> 8)."""
    p, (ap, re) = fig4
    monkeypatch.setattr(stepping._Bracket, "estimate", lambda self: None)
    ap1, re1 = fig4_sweeps(p)
    old, new = ap.jumps + re.jumps, ap1.jumps + re1.jumps
    assert len(new) == len(old)
    assert all(abs(a.d_fold - b.d_fold) <= 1e-6 * H for a, b in zip(new, old))
    assert ap1.work["fold_bisections"] > 0
    assert ap1.work["fold_solves"] > ap.work["fold_solves"]


def test_a_landing_that_does_not_polish_falls_back_to_halving(fig4, monkeypatch):
    """The first landing after a bracketed fold is made to fail (as on a near-trapped grid
    where the states reached depend on the path): the grid step is taken once more from
    its start by the plain halving, which lands, and the sweep ends with the same folds; a
    failing landing on the halving path itself is still the error it was, naming where."""
    p, (ap, re) = fig4
    real = stepping.land
    calls = [0]

    def flaky(problem, d, w, **kw):
        calls[0] += 1
        st = real(problem, d, w, **kw)
        if calls[0] == 1:
            st.converged = False
        return st
    monkeypatch.setattr(stepping, "land", flaky)
    ap1 = trace(p, D_VALUES, branch="approach", tol=TOL)
    assert ap1.work["fold_fallbacks"] == 1
    assert [j.d_fold for j in ap1.jumps] == [j.d_fold for j in ap.jumps]

    def broken(problem, d, w, **kw):
        st = real(problem, d, w, **kw)
        st.converged = False
        return st
    monkeypatch.setattr(stepping, "land", broken)
    with pytest.raises(stepping.ConvergenceError, match="landing after the fold at d = 1.1"):
        trace(p, D_VALUES, branch="approach", tol=TOL)


def test_the_energy_descent_stops_once_settled_at_round_off(monkeypatch, fig4_jump150,
                                                           cholesky_count):
    """The jump-in's landing on 150 nodes: the descent reaches its basin's minimum within a
    few dozen steps and then can no longer lower the energy beyond its round-off; it stops
    there (measured 50 Cholesky factorisations, where it used to spin to its 400-step cap:
    721; 39 against 723 on the Fig 4 scene's 632 nodes) and the Newton polish lands on the
    state the full descent lands on, to the tolerance."""
    p, j = fig4_jump150
    count = cholesky_count
    w, settled = landing._lm_descent(p, j.d_land, j.before.w, p.sigma)
    assert settled and count[0] < 100, count[0]
    short = count[0]
    count[0] = 0
    monkeypatch.setattr(landing, "ROUNDOFF_STEPS", 10**9)    # the descent to its cap
    w_full, _ = landing._lm_descent(p, j.d_land, j.before.w, p.sigma)
    assert count[0] > 3 * short
    e, e_full = p.energy(w, j.d_land), p.energy(w_full, j.d_land)
    assert e - e_full <= 1e-12 * abs(e_full)
    monkeypatch.setattr(landing, "ROUNDOFF_STEPS", 3)
    landed = landing.land(p, j.d_land, j.before.w, tol=TOL, max_iter=40)
    assert landed.converged and landed.stable
    assert np.max(np.abs(landed.w - j.after.w)) <= 3 * TOL
    assert state_forces(p, landed)[2] == pytest.approx(state_forces(p, j.after)[2],
                                                       rel=1e-9, abs=0)


def test_a_landing_whose_polish_fails_after_the_settled_descent_runs_the_whole_descent(
        monkeypatch):
    """The round-off stop is a shortcut, never a new failure: when the Newton polish from the
    settled descent does not reach a stable state (forced here on the first polish), the
    landing runs the whole descent to its cap as before and lands on the same state."""
    p = fig4_problem(150)
    j = trace(p, D_VALUES, branch="approach", tol=TOL).jumps[0]
    real = landing.solve_complementarity
    calls = []

    def first_fails(*a, **k):
        st = real(*a, **k)
        calls.append(st.n_iter)
        if len(calls) <= 2:             # the polish and its larger-budget retry
            st.converged = False
        return st
    monkeypatch.setattr(landing, "solve_complementarity", first_fails)
    # the last-resort fallbacks (relaxation, neighbouring edges) off: the whole descent alone
    monkeypatch.setattr(landing, "RELAX_STEPS", 0)
    monkeypatch.setattr(landing, "EDGE_SHIFTS", ())
    landed = landing.land(p, j.d_land, j.before.w, tol=TOL, max_iter=40)
    assert len(calls) == 3 and landed.converged and landed.stable
    assert np.max(np.abs(landed.w - j.after.w)) <= 3 * TOL


@pytest.mark.parametrize("n, trapped", [(40, True), (150, False)])
def test_the_round_off_stop_is_off_on_a_lattice_trapped_grid(n, trapped, monkeypatch):
    """On a lattice-trapped grid (the law softening beyond a node's stiffness: measured 1.20x
    on 40 nodes of the Fig 4 disk, 0.32x on 150) the landing's first descent runs to its cap
    (the polish there is fragile and the states reached follow the iterates); elsewhere it
    stops once settled at round-off. Landing from the flat surface at d = 0.6 nm."""
    p = fig4_problem(n)
    assert (p.surface_force_stiffness()[0] >= 1.0) is trapped
    real = landing._lm_descent
    seen = []

    def spy(*a, **k):
        seen.append(k.get("roundoff", True))
        return real(*a, **k)
    monkeypatch.setattr(landing, "_lm_descent", spy)
    landing.land(p, 0.6e-9, np.zeros(p.grid.n), tol=TOL, max_iter=40)
    assert seen and seen[0] is (not trapped)

