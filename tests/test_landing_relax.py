"""The landing after a fold where the collocation equations have lost the descent's
equilibrium (femadh.contact.landing: :func:`_next_edges`, :func:`_relax`): the 2-mm slider
with LJ, the sigma = 0.3 nm gap and an ethanol meniscus at p/psat = 0.05 (the stiction map's
sigma = 0.3 nm corner) on the banded member of 26 nm band spacing (253 nodes; its edge nodes
soften 1.05x their own stiffness, at the lattice-trapping limit).

Its approach folds twice: the jump-in at d = 1.1098 nm lands as always; at the second fold
(d = 1.1018 nm, the contact growing by a node) the energy descent settles in a genuine
minimum (energy Hessian positive definite, 70 contact nodes), but the collocation form
K w = P - p_c has no equilibrium on that contact set near it: the Newton polish cycled for
200 iterations at a residual of ~7e-14 m and the run failed. The corrector from the
neighbouring contact edges, or the pseudo-time relaxation of the collocation equations past
the vanished root, lands on the set whose equilibrium exists (71 nodes)."""
import numpy as np
import pytest

from conftest import CORNER_D_VALUES, CORNER_SPACING
from femadh.contact import complementarity as cm
from femadh.contact import landing
from femadh.contact.complementarity import solve_complementarity
from femadh.contact.stability import is_stable

#: the band spacing of the member (m) whose second landing failed before the fallbacks, and
#: the approach through both folds (the case is traced once, by conftest.corner_approach)
SPACING, D_VALUES = CORNER_SPACING, CORNER_D_VALUES


@pytest.fixture(scope="module")
def slider(corner_approach):
    scene, p, _, _ = corner_approach
    return scene, p


@pytest.fixture(scope="module")
def landed(corner_approach):
    """The approach through both folds, and every landing that needed a fallback:
    (d, w_start, descent (w, contact set)) - what :func:`landing.land` and its fallbacks
    were called with.

    Which fold's landing loses its equilibrium depends on the path to it at round-off: with
    the Krylov preconditioner's factor kept in single precision (linalg.PRECONDITIONER_DTYPE,
    the solver's default) the approach on this member passes both folds without needing a
    fallback (measured: 2 jumps, 0 fallbacks), with it in double it reaches the landing
    described above (2 jumps, 1 fallback). The landing itself is what is tested here: the
    double-precision path is taken to reach it (conftest.corner_approach)."""
    _, _, sweep, fallbacks = corner_approach
    return sweep, fallbacks


def _check_landing(p, st, tol):
    """A landing checked independently of the solver: the collocation residual
    max |w - C (P - p_c)| within ``tol``, the gap bound h >= sigma with p_c >= 0 on the
    contact set, and an energy minimum (Hessian positive definite on the free nodes)."""
    sigma = p.sigma
    assert st.converged and st.stable
    assert np.all(st.h >= sigma * (1 - 1e-12))
    assert np.allclose(st.h, p.contour(st.d) - st.w, rtol=0, atol=1e-22)
    A = st.active
    pc = np.zeros_like(st.w)
    pc[A] = p.pressure(st.h)[A] - (p.K @ st.w)[A]
    assert np.all(pc[A] >= 0)
    assert np.all(np.abs(st.h[A] - sigma) <= 1e-9 * sigma)
    res = float(np.max(np.abs(st.w - p.C @ (p.pressure(st.h) - pc))))
    assert res <= tol, res
    assert is_stable(p, st.h, ~A)


def test_the_approach_lands_on_stable_equilibria(slider, landed):
    """With the fallbacks the approach passes both folds (one of its landings needed them);
    every landing is a stable equilibrium of the collocation equations and lies downhill of
    where the surface left the branch (a quasi-static snap releases energy: the landing's
    energy below the departing surface's at the landing's separation)."""
    scene, p = slider
    sweep, fallbacks = landed
    assert len(sweep.jumps) >= 2 and fallbacks
    for j in sweep.jumps:
        _check_landing(p, j.after, scene.tolerance)
        assert p.energy(j.after.w, j.d_land) < p.energy(j.before.w, j.d_land)
    assert sweep.states[-1].active.any() and sweep.states[-1].stable


def test_the_landing_fails_without_the_fallbacks(slider, landed, monkeypatch):
    """The case is a real failure of the Newton polish from the descent: without the
    neighbouring edges and the relaxation the landing does not end on a stable state."""
    scene, p = slider
    d, w_start, _ = landed[1][0]
    monkeypatch.setattr(landing, "RELAX_STEPS", 0)
    monkeypatch.setattr(landing, "EDGE_SHIFTS", ())
    # the corrector of the path that found the case (conftest.corner_approach): with the
    # first Newton step at a set solved to GMRES_RTOL_NEW_SET this polish converges
    monkeypatch.setattr(cm, "GMRES_RTOL_NEW_SET", cm.GMRES_RTOL)
    st = landing.land(p, d, w_start, tol=scene.tolerance, max_iter=scene.max_iter)
    assert not (st.converged and st.stable)


def test_a_neighbouring_edge_polishes(slider, landed):
    """From the descent's minimum, the corrector on the neighbouring contact edges reaches
    a stable collocation equilibrium with the contact grown (the collocation form's edge
    node has lost its root on the descent's set: measured 70 -> 72 nodes here, 150 -> 151
    on the 13 nm member's fourth fold), the one of least energy among the shifts."""
    scene, p = slider
    d, _, (w, active) = landed[1][0]
    st = landing._next_edges(p, d, w, active, tol=scene.tolerance, max_iter=scene.max_iter)
    assert st is not None
    _check_landing(p, st, scene.tolerance)
    assert 0 < int(st.active.sum()) - int(active.sum()) <= 2
    b = p.contour(d)
    for k in landing.EDGE_SHIFTS:
        A = np.zeros(w.size, bool)
        A[:int(active.sum()) + k] = True
        w0 = np.where(A, b - p.sigma, w)
        other = solve_complementarity(p, d, w0, tol=scene.tolerance,
                                      max_iter=scene.max_iter, active0=A)
        if other.converged and other.stable:
            assert p.energy(st.w, d) <= p.energy(other.w, d)


def test_relax_reaches_a_collocation_equilibrium_from_the_descent(slider, landed):
    """_relax on its own from the descent's minimum: within its step cap it ends on a state
    whose collocation residual on the free nodes is below the tolerance with an unchanged
    contact set, one node more in contact than the descent's (measured: 70 -> 71 nodes, 115
    steps), and the corrector confirms it as a stable equilibrium in a few iterations."""
    scene, p = slider
    d, _, (w, active) = landed[1][0]
    wr, A, steps = landing._relax(p, d, w, active, tol=scene.tolerance)
    assert wr is not None and steps <= landing.RELAX_STEPS
    assert A.sum() > active.sum()
    h = p.contour(d) - wr
    assert np.all(np.abs(h[A] - p.sigma) <= 1e-9 * p.sigma)
    F = p.K @ wr - p.pressure(h)
    free = ~A
    r = np.max(np.abs(p.areas[free] * F[free]) / np.diag(p.S_sym)[free])
    assert r <= scene.tolerance
    st = solve_complementarity(p, d, wr, tol=scene.tolerance, max_iter=5, active0=A)
    _check_landing(p, st, scene.tolerance)
