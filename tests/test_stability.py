"""Stability of reported states: the inertia of the symmetric energy Hessian decides.

The regression case of the old decision (signs of LU pivots over the matrix diagonal): a free
node whose own diagonal turns negative (LJ softening above the node's stiffness, the lattice-
trapping regime) makes pivot and diagonal both negative, so a saddle read as stable.
"""

import numpy as np
import pytest

from femadh.contact import ContactProblem
from femadh.contact.arclength import trace_curve
from femadh.contact import solve_state
from femadh.contact.stability import is_stable
from femadh.elastic import GreenOperator, RadialGrid
from femadh.indenter import Sphere
from femadh.studies.smooth_sphere import lj_sphere_problem

from conftest import HAMAKER, Z0

TOL = 1e-19


class _Softening:
    """A law whose softening -P' is `soft` (Pa/m) below the gap `h_c` and 0 above (only the
    derivative matters to the Hessian)."""

    def __init__(self, soft, h_c):
        self.soft, self.h_c = soft, h_c

    def pressure(self, h):
        return np.zeros_like(h)

    def dpressure(self, h):
        return np.where(np.asarray(h) < self.h_c, -self.soft, 0.0)

    def energy(self, h):
        return np.zeros_like(h)


def _node_problem(n=40):
    op = GreenOperator(RadialGrid.uniform(1e-6, n), 50e9)
    return op, np.diag(op.stiffness)


@pytest.mark.parametrize("factor,expected", [(1.5, False), (0.3, True)])
def test_softening_of_one_free_node_against_its_own_stiffness(factor, expected):
    """Node k softens by `factor` x its own stiffness K_kk (per area: -P' vs K_kk). Above 1 the
    energy has a descent direction along that node alone (the Rayleigh quotient of e_k is
    area_k (K_kk - 1.5 K_kk) < 0): a saddle. Well below 1 the state is a minimum."""
    op, kdiag = _node_problem()
    k = 17
    law = _Softening(factor * kdiag[k], 2e-9)
    pb = ContactProblem(op, Sphere(1e-3), {"x": law}, check_laws=False)
    h = np.full(op.grid.n, 10e-9)
    h[k] = 1e-9
    free = np.ones(op.grid.n, bool)
    lam = np.linalg.eigvalsh(pb.energy_hessian(h, free))[0]
    assert (lam > 0) == expected        # the independent judge agrees with the construction
    assert is_stable(pb, h, free) == expected
    # a contact set (nodes 0..9 held) changes nothing about node 17's own instability
    free[:10] = False
    assert is_stable(pb, h, free) == expected


def test_stability_flag_equals_hessian_eigenvalue_sign_on_random_states():
    """Across states straddling marginal stability the decision is the sign of the smallest
    eigenvalue (it cannot be a constant: both outcomes occur)."""
    op, kdiag = _node_problem(30)
    rng = np.random.default_rng(1)
    outcomes = []
    for _ in range(40):
        soft = rng.uniform(0.0, 2.0) * np.median(kdiag)
        pb = ContactProblem(op, Sphere(1e-3), {"x": _Softening(soft, 2e-9)}, check_laws=False)
        h = np.where(rng.random(op.grid.n) < 0.3, 1e-9, 10e-9)
        free = rng.random(op.grid.n) < 0.8
        lam = np.linalg.eigvalsh(pb.energy_hessian(h, free))[0]
        outcomes.append(lam > 0)
        assert is_stable(pb, h, free) == (lam > 0)
    assert any(outcomes) and not all(outcomes)


@pytest.fixture(scope="module")
def mu2_curve():
    problem, lj, e_star, a, d_min = lj_sphere_problem(2.0, 1e-6, HAMAKER, Z0, 0.4, 120)
    curve = trace_curve(problem, 12 * Z0, d_min, tol=TOL, scale=Z0, ds=0.2, ds_max=2.0)
    return problem, curve


def test_s_curve_is_unstable_between_its_folds_and_stable_elsewhere(mu2_curve):
    """Tabor mu = 2: the traced S has two folds; the points between them are saddles, the
    others minima - by the flag the trace carries and by the Hessian's smallest eigenvalue
    (away from the folds: next to one, the symmetric Hessian and the collocation Jacobian
    turn singular O(h) apart)."""
    problem, curve = mu2_curve
    assert len(curve.folds) == 2
    i1, i2 = (f.index for f in curve.folds)
    near = {i1, i1 + 1, i2, i2 + 1}
    for i, p in enumerate(curve.points):
        between = i1 < i <= i2
        assert p.stable == (not between)
        if i not in near:
            lam = np.linalg.eigvalsh(problem.energy_hessian(problem.contour(p.d) - p.w))[0]
            assert (lam > 0) == (not between)


def test_newton_corrector_reports_a_converged_saddle_as_unstable(mu2_curve):
    """Newton converges to unstable equilibria as readily as to stable ones; the state it
    returns must say which it is (the continuation rejects unstable states)."""
    problem, curve = mu2_curve
    i1, i2 = (f.index for f in curve.folds)
    inner = [p for p in curve.points[i1 + 2: i2 - 1]]
    assert len(inner) >= 3
    for p in inner[:: max(1, len(inner) // 5)] + [curve.points[0], curve.points[-1]]:
        st = solve_state(problem, p.d, p.w, tol=TOL, max_iter=40)
        assert st.converged
        assert st.stable == p.stable


def test_lattice_trapping_saddles_with_negative_node_diagonals_are_unstable():
    """The regression case of the old pivot-ratio decision: on a grid 2.5x too coarse for the
    LJ law (each node softer than the law's peak softening), equilibria exist in which a free
    node's own diagonal K_kk + P'(h_k) is negative. Newton converges to them; the ones the
    Hessian's eigenvalues call saddles must be reported unstable (the old decision called
    most of them stable: 137 of 306 curve points disagreed)."""
    problem, *_ , d_min = lj_sphere_problem(2.0, 1e-6, HAMAKER, Z0, 2.5, 17)
    curve = trace_curve(problem, 12 * Z0, d_min, tol=TOL, scale=Z0, ds=0.2, ds_max=0.5)
    K = np.diag(problem.K)
    checked = 0
    for p in curve.points[::3]:
        h = problem.contour(p.d) - p.w
        if not np.any(K + problem.dpressure(h) < 0):
            continue
        lam = np.linalg.eigvalsh(problem.energy_hessian(h))[0]
        st = solve_state(problem, p.d, p.w, tol=TOL, max_iter=40)
        assert st.converged and st.stable == (lam > 0)
        checked += not st.stable
    assert checked >= 5
