"""The landing's energy descent counts a trial that rises within the energy's round-off as a
flat step (femadh.contact.landing.ROUNDOFF_REJECTS): it settles with fewer Cholesky
factorisations, on the minimum the descent without the shortcut settles on (to the energy's
round-off), and the polished landing is the same state to a small fraction of the tolerance;
the whole descent (``roundoff`` off: trapped grids, the retry after a failed polish) is
untouched, bit for bit."""
import numpy as np
import pytest

from femadh.contact import landing
from femadh.contact.forces import state_forces

from conftest import FIG4_TOL as TOL


@pytest.fixture(scope="module")
def jump(fig4_jump150):
    """The Fig 4 disk (sigma = 0.5 nm) on 150 uniform nodes: its jump-in lands after a fold."""
    return fig4_jump150


def _descend(p, j, monkeypatch, rejects, count, **kw):
    monkeypatch.setattr(landing, "ROUNDOFF_REJECTS", rejects)
    count[0] = 0
    w, settled = landing._lm_descent(p, j.d_land, j.before.w, p.sigma, **kw)
    return w, settled, count[0]


def test_rises_within_round_off_settle_the_descent_sooner_on_the_same_minimum(
        jump, cholesky_count, monkeypatch):
    """Measured on 150 nodes: 50 -> 43 factorisations (300 nodes: 38 -> 30), the two minima's
    energies 4e-16 apart relative (the energy's round-off is 64 ulps of its parts' magnitudes:
    the criterion itself, checked here)."""
    p, j = jump
    count = cholesky_count
    w0, s0, c0 = _descend(p, j, monkeypatch, False, count)
    w1, s1, c1 = _descend(p, j, monkeypatch, True, count)
    assert s0 and s1
    assert c1 < c0, (c0, c1)
    e0, e1 = p.energy(w0, j.d_land), p.energy(w1, j.d_land)
    assert abs(e1 - e0) <= landing._roundoff(p, w0, e0), (e0, e1)


def test_the_polished_landing_is_the_same_state(jump, monkeypatch):
    """The Newton polish from either descent lands on one state: the same contact set, the
    surfaces within 1e-3 of the tolerance (measured 1.0e-5 of it), F_LJ within 1e-14 relative
    (measured 1.4e-16)."""
    p, j = jump
    out = []
    for rejects in (False, True):
        monkeypatch.setattr(landing, "ROUNDOFF_REJECTS", rejects)
        st = landing.land(p, j.d_land, j.before.w, tol=TOL, max_iter=40)
        assert st.converged and st.stable
        out.append(st)
    a, b = out
    assert np.array_equal(a.active, b.active)
    assert np.max(np.abs(a.w - b.w)) <= 1e-3 * TOL
    assert state_forces(p, b)[2] == pytest.approx(state_forces(p, a)[2], rel=1e-14, abs=0)


def test_the_whole_descent_is_untouched(jump, monkeypatch, cholesky_count):
    """With the round-off stop off (a trapped grid; the retry after a polish that failed) the
    descent runs as before: the same iterate, bit for bit, the same factorisations."""
    p, j = jump
    count = cholesky_count
    w0, s0, c0 = _descend(p, j, monkeypatch, False, count, roundoff=False, max_iter=60)
    w1, s1, c1 = _descend(p, j, monkeypatch, True, count, roundoff=False, max_iter=60)
    assert c0 > 0                     # the spy counts the descent's factorisations
    assert c0 == c1 and s0 == s1
    assert np.array_equal(w0, w1)


def test_the_descent_settles_on_its_lowest_point(jump, monkeypatch):
    """The descent never climbs: the point it returns has the lowest energy of every point it
    evaluated (the rejected trials, those that rose within the round-off included, rose above
    the point it stood on)."""
    p, j = jump
    seen = []
    real = p.energy

    def energy(w, d):
        e = real(w, d)
        seen.append(e)
        return e
    monkeypatch.setattr(p, "energy", energy)
    w, settled = landing._lm_descent(p, j.d_land, j.before.w, p.sigma)
    monkeypatch.undo()
    assert settled
    assert p.energy(w, j.d_land) == min(e for e in seen if np.isfinite(e))


class _Huber:
    """A separable pseudo-Huber energy C + sum sqrt(1 + (w - w*)^2) (J, w in m) on a constant
    C: its round-off, 64 ulps of C, is what the descent must tell apart; no gap bound within
    reach, S = I."""

    def __init__(self, C, n=3):
        self.C, self.n = C, n
        self.S_sym = np.eye(n)
        self.star = np.linspace(1.0, 2.0, n)

    def contour(self, d):
        return np.full(self.n, 1e6)

    def energy(self, w, d):
        return self.C + float(np.sum(np.sqrt(1 + (w - self.star) ** 2)))

    def energy_gradient(self, w, d):
        u = w - self.star
        return u / np.sqrt(1 + u**2)

    def energy_hessian(self, h, free):
        u = 1e6 - h - self.star
        return np.diag(((1 + u**2) ** -1.5)[free])


def test_a_rise_beyond_the_round_off_does_not_settle_the_descent():
    """On the pseudo-Huber energy riding on C = 1e11 J (round-off 64 ulps: 1.4e-3 J) from 40
    widths off, the descent's trials overshoot and rise before the damping holds them; it
    settles on the minimum all the same (measured 6e-14 off; with the round-off taken 1000x
    larger, in its flat steps and its rejections alike, it settled 0.15 off, 1.2e-2 J above
    the minimum)."""
    p = _Huber(1e11)
    w, settled = landing._lm_descent(p, 0.0, np.full(3, 40.0), 0.0)
    assert settled
    assert np.max(np.abs(w - p.star)) <= 1e-6
    assert p.energy(w, 0.0) - p.energy(p.star, 0.0) <= landing._roundoff(p, p.star, p.C)
