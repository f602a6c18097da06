"""Every solve has a budget and every fault a clear error: an inconsistent law fails in seconds,
a non-finite value stops the solve where it arises, no message reports a nan residual."""
import math

import numpy as np
import pytest

from femadh.contact import ContactProblem, trace
from femadh.contact.arclength import trace_curve
from femadh.contact import AsperityGap
from femadh.laws import LennardJones
from femadh.elastic import GreenOperator, RadialGrid
from femadh.errors import ConvergenceError, LawError
from femadh.indenter import Sphere
from femadh.studies.smooth_sphere import lj_sphere_problem

from conftest import E_STAR, HAMAKER, Z0

TOL = 1e-19


class SteepDerivative(LennardJones):
    """LJ with a derivative 10 % too steep: Newton's Jacobian and the law disagree."""

    def dpressure(self, h):
        return 1.1 * super().dpressure(h)


class NanBelow(LennardJones):
    """LJ that returns nan below a gap (a law evaluated outside its domain)."""

    floor = 0.6e-9

    def pressure(self, h):
        return np.where(np.asarray(h) < self.floor, np.nan, super().pressure(h))


def _fig4(law, check=True):
    a = math.sqrt(2 * 2e-3 * 10e-9)
    return ContactProblem(GreenOperator(RadialGrid.uniform(a, 200), E_STAR), Sphere(2e-3),
                          {"lj": law}, AsperityGap(0.5e-9), check_laws=check)


def test_inconsistent_law_is_refused_before_solving():
    with pytest.raises(LawError, match=r"'lj': dpressure is not the derivative of pressure"):
        _fig4(SteepDerivative(HAMAKER, Z0))


def test_wrong_derivative_fails_cleanly_in_stepping_continuation(monkeypatch):
    """Unchecked, the wrong Jacobian still ends in a ConvergenceError naming where, within a
    bounded number of Newton iterations, not in a crawl. Measured: 92 complementarity solves,
    3077 Newton iterations in all (2 s quiet) before the landing after the jump-in fails; the
    bound is 3x that. It counts work, not seconds: a wall-clock bound failed at load 15."""
    from femadh.contact import landing, snap, stepping

    work = {"solves": 0, "iterations": 0}

    def counted(solve):
        def spy(*a, **k):
            st = solve(*a, **k)
            work["solves"] += 1
            work["iterations"] += st.n_iter
            return st
        return spy
    monkeypatch.setattr(stepping, "solve_complementarity",
                        counted(stepping.solve_complementarity))
    monkeypatch.setattr(landing, "solve_complementarity", counted(landing.solve_complementarity))
    monkeypatch.setattr(snap, "solve_complementarity", counted(snap.solve_complementarity))
    p = _fig4(SteepDerivative(HAMAKER, Z0), check=False)
    ds = np.round(np.arange(2.0, -2.0001, -0.2), 10) * 1e-9
    with pytest.raises(ConvergenceError, match=r"d = .* nm") as e:
        a = trace(p, ds, branch="approach", tol=TOL)
        trace(p, ds[::-1], branch="retract", tol=TOL, start=a.states[-1])
    assert 0 < work["iterations"] <= 3 * 3077, work
    assert "iterations" in str(e.value) and "nan" not in str(e.value)


def test_wrong_derivative_fails_cleanly_in_arclength_continuation():
    """Unchecked, the tangent and the corrector disagree; the step budget per point stops
    the trace within a bounded amount of work (before the budget it ran for over 15
    minutes). Measured: 99 corrector solves and 1052 residual evaluations (one per Newton
    iteration, tangent and fold location included: 0.4 s quiet) before it stalls at
    d = 0.723 nm; the bounds are 3x that. It counts work, not seconds: a wall-clock bound
    fails under load."""
    problem, lj, *_, d_min = lj_sphere_problem(2.0, 1e-6, HAMAKER, Z0, 0.4, 120)
    problem = ContactProblem(problem.operator, problem.sphere,
                             {"lj": SteepDerivative(HAMAKER, Z0)}, check_laws=False)
    calls = {"pressure": 0}
    pressure = problem.pressure

    def counted(h):
        calls["pressure"] += 1
        return pressure(h)
    problem.pressure = counted          # this instance only: every residual the trace takes
    with pytest.raises(ConvergenceError, match="arclength continuation stalled") as e:
        trace_curve(problem, 12 * Z0, d_min, tol=TOL, scale=Z0, ds=0.2, ds_max=0.5)
    assert 0 < e.value.curve.n_solves <= 3 * 99, e.value.curve.n_solves
    assert 0 < calls["pressure"] <= 3 * 1052, calls
    assert e.value.curve.points            # the part traced so far is kept
    assert "nan" not in str(e.value)


def test_non_finite_law_value_stops_the_solve_where_it_arises():
    """A law that returns nan below 0.6 nm: the sweep stops with the law, the node and the
    gap named, instead of carrying nan into a residual."""
    with pytest.raises(LawError, match="not finite"):
        _fig4(NanBelow(HAMAKER, Z0))            # the check sees it before any solve
    p = _fig4(NanBelow(HAMAKER, Z0), check=False)
    ds = np.round(np.arange(2.0, -2.0001, -0.2), 10) * 1e-9
    with pytest.raises(ConvergenceError) as e:
        trace(p, ds, branch="approach", tol=TOL)
    msg = str(e.value)
    assert "'lj'" in msg and "not finite" in msg and "gap h =" in msg and "d = " in msg
    assert e.value.sweep.states                 # the states before it are kept
    assert "nan m" not in msg and "residual = nan" not in msg


def test_convergence_error_never_prints_a_nan_residual():
    msg = str(ConvergenceError("x", d=1e-9, residual=math.nan, n_iter=3))
    assert "nan" not in msg and "no finite residual" in msg
