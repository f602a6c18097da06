"""The continuation's predictor and acceptance (femadh.contact.stepping: the contact edge
extrapolated from the last two states, the acceptance measured from the corrector's projected
start, a healthy step's released nodes against the gap they opened to) and the peak search's
warm starts (femadh.runner.peak): the same states, folds and peaks as without them, in fewer
corrector solves and iterations."""
from types import SimpleNamespace

import numpy as np
import pytest

from femadh.contact import forces, stepping, trace
from femadh.runner import peak

from conftest import FIG4_TOL as TOL
from conftest import fig4_problem

#: 240 uniform nodes on the Fig 4 disk (26 nm apart): the contact edge advances 4-10 nodes
#: per 0.2-nm step after the jump-in
N = 240
#: the approach from 1.6 nm through the jump-in (1.11 nm) to -1 nm
D_VALUES = np.round(np.arange(1.6, -1.01, -0.2), 10) * 1e-9
#: the resolution step (m) of the 0.2-nm grid step
H = 0.2e-9 * stepping.MIN_STEP_FRACTION


@pytest.fixture(scope="module")
def problem():
    return fig4_problem(N)


def _approach(problem, monkeypatch, projected, edge):
    monkeypatch.setattr(stepping, "PROJECTED_ACCEPT", projected)
    monkeypatch.setattr(stepping, "EDGE_PREDICTOR", edge)
    return trace(problem, D_VALUES, branch="approach", tol=TOL)


def test_the_predictor_keeps_the_states_and_folds_in_fewer_solves(problem, monkeypatch):
    """With the projected acceptance and the edge predictor the approach reaches the same
    states (measured 3.4e-20 m apart, a third of the tolerance) and the same jump-in (the
    same lattice point), and turns down fewer healthy steps: measured 44 -> 32 solves, 8 -> 2
    steps turned down as 'too far from the prediction' - the nodes the predictor put below
    sigma were counted as corrected by their overshoot."""
    new = _approach(problem, monkeypatch, True, True)
    old = _approach(problem, monkeypatch, False, False)
    assert [s.d for s in new.states] == [s.d for s in old.states]
    for a, b in zip(new.states, old.states):
        assert np.array_equal(a.active, b.active)
        assert np.max(np.abs(a.w - b.w)) <= 3 * TOL
    assert len(new.jumps) == len(old.jumps) == 1
    assert abs(new.jumps[0].d_fold - old.jumps[0].d_fold) <= 1e-6 * H
    assert new.work["solves"] <= old.work["solves"] - 8          # measured 32 against 44
    assert new.work.get("rejected_predictor", 0) <= 2 < old.work["rejected_predictor"]


def _disk(n, m):
    out = np.zeros(n, bool)
    out[:m] = True
    return out


def test_the_edge_is_extrapolated_from_two_growing_disks():
    """m(d) = m_s + (m_s - m_p) min(x, EDGE_MAX_RATIO), x = (d - d_s)/(d_s - d_p): exact for
    an edge advancing by whole nodes at a steady rate; nothing where the contact shrinks,
    moves by less than EDGE_MIN_NODES, is not a disk, d is not beyond the last state, or the
    state has no second point (the first of a branch piece)."""
    n = 50

    def st(d, m, prev=(1.0e-9, 10)):
        return SimpleNamespace(d=d, active=_disk(n, m), edge_from=prev)
    state = st(0.8e-9, 14)
    assert stepping.edge_set(state, 0.6e-9).sum() == 18
    assert stepping.edge_set(state, 0.7e-9).sum() == 16
    assert np.array_equal(stepping.edge_set(state, 0.6e-9), _disk(n, 18))
    # a longer reach is capped at the distance between the two states
    assert stepping.edge_set(state, 0.2e-9).sum() == 14 + 4 * stepping.EDGE_MAX_RATIO
    assert stepping.edge_set(st(0.8e-9, 10, (1.0e-9, 14)), 0.6e-9) is None   # shrinking
    assert stepping.edge_set(st(0.8e-9, 11), 0.6e-9) is None                 # one node
    assert stepping.edge_set(state, 0.9e-9) is None                          # not beyond
    assert stepping.edge_set(st(0.8e-9, 14, None), 0.6e-9) is None          # no second
    ring = st(0.8e-9, 14)
    ring.active[0] = False
    assert stepping.edge_set(ring, 0.6e-9) is None                           # no disk
    assert stepping.edge_set(st(0.8e-9, 48), 0.6e-9).sum() == n              # all nodes


def test_the_acceptance_measures_from_the_projected_start():
    """A node predicted below sigma that ends on the floor moved by nothing from where the
    corrector started; a node of the predicted contact released by a healthy step is held to
    a quarter of the gap it opened to (a quarter of sigma otherwise); a snap off the contact
    (its nodes opening to several sigma) is turned down either way."""
    sigma, n = 0.5e-9, 4
    b = np.full(n, 2e-9)
    prob = SimpleNamespace(sigma=sigma, contour=lambda d: b)
    predicted = np.array([True, True, True, False])
    w_pred = b - np.array([0.3e-9, 0.35e-9, sigma, 1.0e-9])     # nodes 0, 1 below the floor

    def state(h):
        h = np.asarray(h)
        return SimpleNamespace(converged=True, stable=True, h=h, w=b - h,
                               active=np.isclose(h, sigma, rtol=1e-12, atol=0))
    on_floor = state([sigma, sigma, sigma, 1.0e-9])
    assert stepping._accept(on_floor, w_pred, 0.0, prob, predicted)
    assert not stepping._accept(on_floor, w_pred, 0.0)        # measured from w_pred itself
    opened = state([sigma, sigma, 0.65e-9, 1.0e-9])           # node 2 released: 0.3 sigma
    assert stepping._accept(opened, w_pred, 0.0, prob, predicted, released=True)
    assert not stepping._accept(opened, w_pred, 0.0, prob, predicted, released=False)
    snapped = state([1.4e-9, 1.4e-9, 1.5e-9, 1.6e-9])
    assert not stepping._accept(snapped, w_pred, 0.0, prob, predicted, released=True)
    # a free node of the prediction (not a released one) is held to its predicted gap: 1.0
    # -> 1.3 nm is 0.3 of it, turned down, though within a quarter of the gap it reached
    drifted = state([sigma, sigma, sigma, 1.3e-9])
    assert not stepping._accept(drifted, w_pred, 0.0, prob, predicted, released=True)


def test_the_peak_search_starts_from_its_own_fresh_states(problem, monkeypatch):
    """Each fresh state after the first starts Newton from the search's nearest one: the
    same peak (measured 1.9e-11 of the force, 6e-20 m in d) in fewer corrector iterations
    (measured 44 against 70 over the search's 16 fresh states)."""
    import femadh.contact.complementarity as cm

    ap = trace(problem, D_VALUES, branch="approach", tol=TOL)
    f = [forces.state_forces(problem, s)[2] for s in ap.states]
    k = int(np.argmax(f))
    assert 0 < k < len(f) - 1
    sc = SimpleNamespace(tolerance=TOL, max_iter=40)
    real, its = cm.solve_complementarity, [0]

    def counted(*a, **kw):
        st = real(*a, **kw)
        its[0] += st.n_iter
        return st
    monkeypatch.setattr(cm, "solve_complementarity", counted)
    out = {}
    for warm in (True, False):
        monkeypatch.setattr(peak, "WARM_PEAK", warm)
        its[0] = 0
        out[warm] = peak.peak_adhesion(problem, *ap.states[k - 1:k + 2], sc) + (its[0],)
    (F1, d1, tol1, n1), (F0, d0, tol0, n0) = out[True], out[False]
    assert F1 > f[k]                                   # between the grid states, higher
    assert F1 == pytest.approx(F0, rel=1e-9, abs=0)
    assert abs(d1 - d0) <= 1e-3 * tol1
    assert n1 <= 0.75 * n0                             # measured 44 against 70


def test_the_warm_start_is_a_fresh_state_between_the_same_grid_states():
    """The search's fresh state nearest to d among those between the bracketing grid states
    (the same piece of the branch), with the secant slope through the next nearest there."""
    def st(d, w):
        return SimpleNamespace(d=d, w=np.array([w]))
    a, b = st(0.8e-9, 0.0), st(1.0e-9, 2.0)
    outside, inside, other = st(0.79e-9, 5.0), st(0.95e-9, 1.0), st(0.9e-9, 0.5)
    near, slope = peak._warm([outside, inside], a, b, 0.81e-9)
    assert near is inside                               # not the nearer one outside
    assert slope == pytest.approx((b.w - a.w) / (b.d - a.d), rel=1e-12, abs=0)
    near, slope = peak._warm([outside, inside, other], a, b, 0.93e-9)
    assert near is inside
    assert slope == pytest.approx((other.w - inside.w) / (other.d - inside.d), rel=1e-12,
                                  abs=0)
    assert peak._warm([outside], a, b, 0.81e-9) is None


def test_the_warm_start_extrapolates_toward_the_new_state(problem, monkeypatch):
    """A fresh state started from a nearby one moved along the secant slope starts closer
    to its solution than the nearby state itself (the slope's sign and size): median over
    the nodes 2.7e-13 m against 5.9e-13 m, 0.02 grid steps apart near the Fig 4 peak on 240
    nodes."""
    import femadh.contact as contact

    ap = trace(problem, D_VALUES, branch="approach", tol=TOL)
    f = [forces.state_forces(problem, s)[2] for s in ap.states]
    k = int(np.argmax(f))
    a, b = ap.states[k - 1], ap.states[k]
    sc = SimpleNamespace(tolerance=TOL, max_iter=40)
    d1 = a.d + 0.3 * (b.d - a.d)
    s1 = peak.state_between(problem, a, b, d1, sc)
    d2 = d1 + 0.02 * (b.d - a.d)
    real, starts = contact.solve_state, []

    def spy(p, d, w0, **kw):
        starts.append(np.array(w0))
        return real(p, d, w0, **kw)
    monkeypatch.setattr(contact, "solve_state", spy)
    s2 = peak.state_between(problem, a, b, d2, sc, start=(s1, (b.w - a.w) / (b.d - a.d)))
    assert s1 is not None and s2 is not None
    # the median over the nodes: the grid secant is a poor slope at the contact edge, which
    # moved between the grid states (there both starts are off by ~ the step), and good
    # elsewhere
    gap_start = np.median(np.abs(starts[-1] - s2.w))
    gap_near = np.median(np.abs(s1.w - s2.w))
    assert gap_start <= 0.6 * gap_near, (gap_start, gap_near)       # measured 0.46
