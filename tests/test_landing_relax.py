"""The landing after a fold where the collocation equations have lost the descent's
equilibrium (femadh.contact.landing._relax): the 2-mm slider with LJ, the sigma = 0.3 nm gap
and an ethanol meniscus at p/psat = 0.05 (the stiction map's sigma = 0.3 nm corner) on the
banded member of 26 nm band spacing (253 nodes; the edge nodes soften 1.05x their own
stiffness, at the lattice-trapping limit).

Its approach folds twice: the jump-in at d = 1.1098 nm lands as always; at the second fold
(d = 1.1018 nm, the contact growing by a node) the energy descent settles in a genuine
minimum (energy Hessian positive definite on 70 contact nodes), but the collocation form
K w = P - p_c has no equilibrium on that contact set near it: the Newton polish cycled for
200 iterations at a residual of ~7e-14 m and the run failed. The pseudo-time relaxation of
the collocation equations passes the vanished root and lands on the set whose equilibrium
exists."""
import math
from pathlib import Path

import numpy as np
import pytest

import femadh
from femadh.contact import landing, trace
from femadh.contact.stability import is_stable
from femadh.discretisation import plan_grid
from femadh.elastic import GreenOperator
from femadh.errors import ConvergenceError
from femadh.scene import build_problem

SCENE = Path(__file__).resolve().parents[1] / "validation" / "scenes" / \
    "paper1_slider_meniscus.toml"
#: the band spacing of the member (m) whose second landing failed before the relaxation
SPACING = 26e-9
#: the approach through both folds
D_VALUES = np.array([1.2, 1.0]) * 1e-9


@pytest.fixture(scope="module")
def slider():
    scene = femadh.load_scene(SCENE).replace({"effects.asperity_gap.sigma": "0.3 nm",
                                              "effects.capillary.relative_pressure": 0.05,
                                              "sweep.start": "4 nm"})
    plan = plan_grid(scene.effects, scene.gap.sigma, scene.sphere, scene.analysis_radius,
                     scene.d_values, scene.target_accuracy)
    op = GreenOperator(plan.family.member(SPACING), scene.e_star)
    return scene, build_problem(scene, operator=op)


@pytest.fixture(scope="module")
def relaxed(slider):
    """The approach with the relaxation, and every call of it: (d, contact set given,
    (w, contact set, steps))."""
    scene, p = slider
    seen = []
    real = landing._relax

    def spy(problem, d, w, active, **kw):
        out = real(problem, d, w, active, **kw)
        seen.append((d, np.array(active), out))
        return out
    try:
        landing._relax = spy
        sweep = _approach(scene, p)
    finally:
        landing._relax = real
    return sweep, seen


def _approach(scene, p):
    return trace(p, D_VALUES, branch="approach", tol=scene.tolerance,
                 max_iter=scene.max_iter)


def test_the_landing_fails_without_the_relaxation(slider, monkeypatch):
    """The case is a real failure of the Newton polish from the descent (so the test below
    exercises the relaxation): without it the second landing does not converge."""
    scene, p = slider
    monkeypatch.setattr(landing, "RELAX_STEPS", 0)
    with pytest.raises(ConvergenceError, match="landing after the fold"):
        _approach(scene, p)


def test_the_relaxed_landing_is_a_stable_equilibrium(slider, relaxed):
    """With the relaxation the approach passes both folds. Every landing is checked
    independently of the solver: the collocation residual max |w - C (P - p_c)| within the
    tolerance (1e-19 m), the gap bound h >= sigma with p_c >= 0 on the contact set and
    p_c = 0 off it, an energy minimum (Hessian positive definite on the free nodes), and
    downhill from where the surface left the branch (energy below the departing state's
    surface at the landing's separation: a quasi-static snap releases energy)."""
    scene, p = slider
    sweep, _ = relaxed
    assert len(sweep.jumps) >= 2
    sigma, tol = p.sigma, scene.tolerance
    for j in sweep.jumps:
        st = j.after
        b = p.contour(st.d)
        assert np.all(st.h >= sigma * (1 - 1e-12))
        assert np.allclose(st.h, b - st.w, rtol=0, atol=1e-22)
        pc = np.zeros_like(st.w)
        A = st.active
        pc[A] = p.pressure(st.h)[A] - (p.K @ st.w)[A]
        assert np.all(pc[A] >= 0)
        assert np.all(np.abs(st.h[A] - sigma) <= 1e-9 * sigma)
        res = float(np.max(np.abs(st.w - p.C @ (p.pressure(st.h) - pc))))
        assert res <= tol, res
        assert is_stable(p, st.h, ~A)
        assert p.energy(st.w, st.d) < p.energy(j.before.w, st.d)
    # the states continue on the landed branch: the last one is in contact and stable
    assert sweep.states[-1].active.any() and sweep.states[-1].stable


def test_relax_reaches_a_collocation_equilibrium_from_the_descent(slider, relaxed):
    """_relax on its own, from the descent's minimum at the failing fold: it returns within
    its step cap a state whose collocation residual on the free nodes is below the
    tolerance, with an unchanged contact set - one node more in contact than the descent's
    (measured: 70 -> 71 nodes, 115 steps)."""
    scene, p = slider
    _, seen = relaxed
    assert seen, "the relaxation was not needed"
    d, active, (w, A, steps) = seen[0]
    assert w is not None and steps <= landing.RELAX_STEPS
    assert A.sum() > active.sum()
    b = p.contour(d)
    h = b - w
    assert np.all(np.abs(h[A] - p.sigma) <= 1e-9 * p.sigma)
    F = p.K @ w - p.pressure(h)
    free = ~A
    r = np.max(np.abs(p.areas[free] * F[free]) / np.diag(p.S_sym)[free])
    assert r <= scene.tolerance
    assert math.isfinite(float(p.energy(w, d)))
