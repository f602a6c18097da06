"""The corrector's Krylov products in single precision (complementarity.KRYLOV_SINGLE).

GMRES's operator diag(area)(K + diag P')_II takes K_II v from a float32 copy of K; the
residual of eq (6)/(10) that convergence is declared on stays in double. Judged against the
double product on a state of the Fig 4 disk (240 uniform nodes, d = -1 nm, 90 contact
nodes): the product's error, one Newton step, and the converged state with its residual
recomputed here from C.
"""
import numpy as np
import pytest

from femadh.contact import complementarity as cm
from femadh.contact.linalg import disk_size

from conftest import FIG4_TOL as TOL, fig4_problem


@pytest.fixture(scope="module")
def state():
    p = fig4_problem(240)
    st = cm.solve_complementarity(p, -1e-9, np.zeros(p.grid.n), tol=TOL, max_iter=40)
    assert st.converged and st.stable
    return p, st


def _residual(p, st):
    """max |w - C (P - p_c)| (m) recomputed from the state's gaps and contact set."""
    P = p.pressure(st.h)
    pc = np.zeros(st.w.size)
    pc[st.active] = P[st.active] - (p.K @ st.w)[st.active]
    return float(np.abs(st.w - p.C @ (P - pc)).max())


def test_single_products_keep_the_newton_step_and_the_state(state, monkeypatch):
    """The single product against K_II's own: relative error measured 1.6e-6 on the
    state's smooth w (K's rows nearly cancel on it), 1.1e-7 on a random vector (allowed 3x
    each); a Newton step from the state moved to d = -0.95 nm differs from the double one by
    4.4e-7 of itself (allowed 2e-6: GMRES_RTOL on each side); the state solved from there
    has the same contact set, w within 1.5e-22 m of the double one's (allowed TOL) and its
    residual recomputed from C within TOL."""
    p, st = state
    m = disk_size(st.active)
    K_II = p.K[m:, m:]
    monkeypatch.setattr(cm, "KRYLOV_SINGLE", True)
    single = cm._krylov_product(p, m)
    rng = np.random.default_rng(21)
    for v, allowed in ((st.w[m:], 5e-6), (rng.standard_normal(p.grid.n - m), 3.5e-7)):
        exact = K_II @ v
        assert np.linalg.norm(single(v) - exact) <= allowed * np.linalg.norm(exact)
    d = -0.95e-9
    w = st.w.copy()
    w[st.active] = p.contour(d)[st.active] - p.sigma
    h = p.contour(d) - w
    F_I = (p.K @ w - p.pressure(h))[m:]
    steps, states = {}, {}
    for flag in (False, True):
        monkeypatch.setattr(cm, "KRYLOV_SINGLE", flag)
        steps[flag] = cm._krylov_step(p, h, st.active, m, F_I, None, cm.GMRES_RTOL)[0]
        states[flag] = cm.solve_complementarity(p, d, st.w, tol=TOL, max_iter=40,
                                                active0=st.active)
    assert np.linalg.norm(steps[True] - steps[False]) <= 2e-6 * np.linalg.norm(steps[False])
    a, b = states[True], states[False]
    assert a.converged and a.stable and np.array_equal(a.active, b.active)
    assert np.abs(a.w - b.w).max() <= TOL
    assert _residual(p, a) <= TOL


def test_the_single_copy_follows_the_problems_stiffness(state, monkeypatch):
    """A problem whose K is replaced (here by 2 K) gets a new single copy: the product is
    2 K_II v to single precision (relative 1e-6 allowed, as above), not the old K's."""
    p, st = state
    monkeypatch.setattr(cm, "KRYLOV_SINGLE", True)
    m = disk_size(st.active)
    v = np.random.default_rng(3).standard_normal(p.grid.n - m)
    cm._krylov_product(p, m)(v)                 # the copy of K made
    monkeypatch.setattr(p, "K", 2.0 * p.K)
    exact = p.K[m:, m:] @ v
    assert np.linalg.norm(cm._krylov_product(p, m)(v) - exact) <= 1e-6 * np.linalg.norm(exact)
