"""An estimate member's states on a small grid factorise their own Jacobian instead of
inheriting a factorisation from a state a fraction of a grid step away
(femadh.runner.peak.MEMBER_FACTOR_MIN_NODES, reuse_factor; femadh.runner.members._Member.state).

The inherited factorisation turns the corrector's steps into chord steps, each a full
evaluation of the laws, where a member's few dozen nodes factorise for less than one of them.
The case: the Fig 3 scene at accuracy 1e-2 (58 nodes; members of 41 and 29 nodes, the
estimate's peak search 40 fresh states, one member's window missed). The fine run's own
states keep their chord steps, so its headline numbers do not move; the members' states
converge to the same equilibria within the solver's tolerance, so the estimates move only by
what that tolerance allows."""
import warnings

import pytest

import femadh
from conftest import adaptive_scene
from femadh.errors import MeshResolutionWarning
from femadh.runner import estimates, members, peak


def _run(min_nodes):
    """(result, {part: Newton iterations}) of the Fig 3 scene at 1e-2 with members reusing
    factorisations on grids of at least ``min_nodes`` nodes; the members' iterations of the
    last trial's estimate, split into their fresh states between grid states ("fresh") and
    their states at the fine run's grid separations ("grid")."""
    import femadh.contact as contact

    count = {"fresh": 0, "grid": 0}
    where = []
    solve, between, state = contact.solve_state, peak.state_between, members._Member.state
    reduced = estimates.reduced_member

    def counted_solve(*a, **kw):
        st = solve(*a, **kw)
        if where and where[0] == "member":
            count[where[-1]] += st.n_iter
        return st

    def tagged(tag, f):
        def g(*a, **kw):
            where.append(tag)
            try:
                return f(*a, **kw)
            finally:
                where.pop()
        return g

    estimate = estimates.estimate_errors

    def estimate_last(*a, **kw):
        # a new estimate (the adaptive loop's next trial): count the last one only
        count.update(fresh=0, grid=0)
        return estimate(*a, **kw)

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(peak, "MEMBER_FACTOR_MIN_NODES", min_nodes)
        mp.setattr(contact, "solve_state", counted_solve)
        mp.setattr(peak, "state_between", tagged("fresh", between))
        mp.setattr(members._Member, "state", tagged("grid", state))
        mp.setattr(estimates, "reduced_member", tagged("member", reduced))
        mp.setattr(estimates, "estimate_errors", estimate_last)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", MeshResolutionWarning)
            res = femadh.run(adaptive_scene(accuracy=1e-2), progress=False, figures=False)
    assert res.status == "converged"
    return res, count


@pytest.fixture(scope="module")
def runs():
    """The run with every member state inheriting a nearby factorisation (as before) and
    with the default (own factorisations below MEMBER_FACTOR_MIN_NODES)."""
    return {"inherit": _run(0), "own": _run(peak.MEMBER_FACTOR_MIN_NODES)}


def test_members_below_the_threshold_factorise_their_own_states(runs):
    (_, before), (res, after) = runs["inherit"], runs["own"]
    assert res.grid["nodes"] < peak.MEMBER_FACTOR_MIN_NODES      # the case is a small grid
    # a count, not a time. Measured: the fresh states 155 -> 102 Newton iterations (0.66), the
    # states at grid separations 57 -> 43 (0.75); allowed: each at most 0.85 of before, so
    # that neither part may go back to inherited factorisations
    for part in ("fresh", "grid"):
        assert before[part] > 0, part
        assert after[part] <= 0.85 * before[part], (part, before, after)


def test_the_fine_run_and_the_estimates_do_not_move(runs):
    (old, _), (new, _) = runs["inherit"], runs["own"]
    # the fine run's own states keep their chord steps: its numbers bit for bit
    for k, v in old.headline.items():
        if not k.endswith("_error"):
            assert new.headline[k] == v, k
    assert new.grid["nodes"] == old.grid["nodes"]
    # the members' states are the same equilibria to the solver's tolerance (1e-10 nm on
    # displacements of ~1 nm): each estimate within 1e-6 of itself (measured: at most
    # 4.2e-9, the largest adhesion's 1.8137236482e-7 -> 1.8137236559e-7 N)
    for k, v in old.headline.items():
        if k.endswith("_error") and v:
            assert new.headline[k] == pytest.approx(v, rel=1e-6, abs=0), k

