"""Pseudo-arclength continuation through folds (femadh.contact.arclength) on a smooth LJ sphere."""

import numpy as np
import pytest

from femadh.contact import trace
from femadh.contact.arclength import trace_curve
from femadh.contact.landing import land
from femadh.studies.smooth_sphere import lj_sphere_problem

from conftest import check_curve_against_fields

Z0, R, A = 0.165e-9, 1e-6, 1e-19
TOL = 1e-19


@pytest.fixture(scope="module")
def mu2():
    """Tabor mu = 2: one S-shaped curve (jump-in and jump-out)."""
    problem, lj, e_star, a, d_min = lj_sphere_problem(2.0, R, A, Z0, 0.4, 120)
    curve = trace_curve(problem, 12 * Z0, d_min, tol=TOL, scale=Z0, ds=0.2, ds_max=2.0)
    return problem, curve, d_min


def test_curve_points_are_equilibria(mu2):
    """Every traced point, stable or not, solves eq (6) to the tolerance."""
    problem, curve, _ = mu2
    for p in curve.points:
        h = problem.contour(p.d) - p.w
        assert np.max(np.abs(p.w - problem.C @ problem.pressure(h))) <= TOL
    assert len(curve.folds) == 2
    assert any(not p.stable for p in curve.points)      # the unstable branch is traced too


def test_folds_are_turning_points_with_a_zero_eigenvalue(mu2):
    """At a located fold dd/ds = 0, and the Jacobian K + diag(P') is singular there: its
    smallest singular value is tiny next to the typical one; one step away it is not."""
    problem, curve, _ = mu2
    for f in curve.folds:
        h = problem.contour(f.d) - f.w
        J = problem.K + np.diag(problem.dpressure(h))
        sv = np.linalg.svd(J, compute_uv=False)
        p = curve.points[f.index]
        hp = problem.contour(p.d) - p.w
        svp = np.linalg.svd(problem.K + np.diag(problem.dpressure(hp)), compute_uv=False)
        # fold located to 1e-12 of the step: the smallest relative singular value is 7e-12
        # and 4e-14 there, 3e-4 and 7e-5 at the last traced point before it
        assert sv[-1] / sv[0] < 7e-11
        assert svp[-1] / svp[0] > 1e6 * sv[-1] / sv[0]


def test_folds_match_the_separation_stepping_solver(mu2):
    """The fold separations agree with femadh.contact.trace, which finds them by step halving
    to 2^-10 of its grid step (its resolution is the bound)."""
    problem, curve, d_min = mu2
    d = np.linspace(12 * Z0, d_min, 41)
    ap = trace(problem, d, branch="approach", tol=TOL)
    rt = trace(problem, d[::-1], branch="retract", tol=TOL, start=ap.states[-1])
    res = abs(d[1] - d[0]) * 2.0**-10 * 1.01
    j_in = curve.branch("approach")
    folds_in = [x for k, x, _ in j_in if k == "fold"]
    folds_out = [x for k, x, _ in curve.branch("retract") if k == "fold"]
    assert folds_in[0] == pytest.approx(ap.jumps[0].d_fold, abs=res)
    assert folds_out[-1] == pytest.approx(rt.jumps[-1].d_fold, abs=res)


def test_landing_is_where_energy_descent_goes(mu2):
    """The walk's landing after the jump-in (the next stable branch at the fold's d) is the
    state a quasi-static surface reaches by descending the energy from the fold."""
    problem, curve, _ = mu2
    path = curve.branch("approach")
    k = next(i for i, e in enumerate(path) if e[0] == "land")
    (_, d_f, w_f), (_, _, w_land) = path[k - 1], path[k]
    st = land(problem, d_f - 1e-6 * Z0, w_f, tol=TOL, max_iter=40)
    # same state up to the 1e-6 z0 offset of the descent's start beyond the fold: measured
    # 1.9e-6 z0
    assert np.max(np.abs(st.w - w_land)) < 1e-5 * Z0


def test_hysteresis_energy_identity(monkeypatch):
    """Work of the closed approach-retract cycle = energy released at the jumps (from the fold
    and landing states, which do not depend on the continuation's steps) = loop integral of
    F dd (trapezoid along the paths), which converges to it as the steps shrink."""
    import femadh.studies.smooth_sphere as smooth_sphere
    from femadh.studies.regime import lj_sphere

    runs = []
    for target, ds_max in ((0.05, 0.5), (0.0125, 0.125)):   # steps ~4x shorter everywhere
        # (the map's own step control, passed to trace_curve)
        monkeypatch.setattr(smooth_sphere, "TRACE_CORRECTION", target)
        # the legacy fixed grid: one grid for the whole curve (a moving band's grids would
        # change with the steps, and with them the discretisation of the two states)
        runs.append(lj_sphere(2.0, ds_max=ds_max, stiffness_target=0.4, min_nodes=120))
    coarse, fine = runs
    assert fine.n_points > 1.5 * coarse.n_points
    assert coarse.hysteresis > 0.5
    # folds located to 1e-12 of a step, landings solved to tol: measured 2.1e-10 apart
    assert fine.hysteresis == pytest.approx(coarse.hysteresis, rel=2e-9)
    err = [abs(r.hysteresis_trapezoid - r.hysteresis) for r in runs]
    assert err[1] < err[0] / 4   # 2.4x more points: error falls 5.7x, faster than 1/points
    assert err[1] < 1e-3 * fine.hysteresis   # measured 3.8e-4


def test_gap_constrained_problem_is_refused():
    from femadh.contact import ContactProblem
    from femadh.contact import AsperityGap
    from femadh.laws import LennardJones
    from femadh.elastic import GreenOperator, RadialGrid
    from femadh.indenter import Sphere

    pb = ContactProblem(GreenOperator(RadialGrid.uniform(1e-7, 20), 1e10), Sphere(1e-6),
                        {"lj": LennardJones(A, Z0)}, AsperityGap(1e-9))
    with pytest.raises(ValueError, match="sigma-gap"):
        trace_curve(pb, 5e-9, 0.0, tol=TOL, scale=Z0, ds=0.2)


def test_scene_with_arclength_continuation_matches_stepping(tmp_path):
    """`[solver] continuation = "arclength"` in a scene: the folds of the traced curve are the
    jumps the stepping solver finds (to its 2^-10-step resolution); equilibrium_curve.csv holds
    the unstable branch too; curve.csv holds the forces of the states in fields.csv."""
    import copy
    import csv
    from pathlib import Path

    import femadh
    from femadh.scene import scene_from_dict

    path = Path(__file__).resolve().parents[1] / "validation/scenes/lj_sphere_mu2_arclength.toml"
    arc = femadh.load_scene(path)
    raw = copy.deepcopy(arc.raw)
    raw["solver"]["continuation"] = "steps"
    steps = scene_from_dict(raw, str(path))
    ra = femadh.run(arc, str(tmp_path / "arc"), figures=False, progress=False, estimate=False)
    rs = femadh.run(steps, str(tmp_path / "steps"), figures=False, progress=False,
                    estimate=False)
    assert ra.status == rs.status == "converged"
    res = 0.1e-9 * 2.0**-10 * 1.01
    for b in ("approach", "retract"):
        ja = [j for j in ra.jumps if j["branch"] == b]
        js = [j for j in rs.jumps if j["branch"] == b]
        assert len(ja) == len(js) == 1
        assert ja[0]["d_fold_m"] == pytest.approx(js[0]["d_fold_m"], abs=res)
    rows = list(csv.DictReader(open(tmp_path / "arc" / "equilibrium_curve.csv")))
    assert any(r["stable"] == "False" for r in rows)
    signs = np.sign([float(r["dd_ds"]) for r in rows])
    assert np.count_nonzero(np.diff(signs)) == 2           # two folds: one S
    assert check_curve_against_fields(tmp_path / "arc") == sum(
        len(c["d_m"]) for c in ra.branches.values())


def test_arclength_with_the_hertz_closure_is_a_scene_error(tmp_path):
    """The complementarity sigma-gap is traced (tests/test_sigma_continuation.py); the
    paper's Hertz closure is not."""
    from pathlib import Path

    import femadh
    from femadh.errors import SceneError

    fig3 = (Path(__file__).resolve().parents[1] / "validation/scenes/paper1_fig3.toml")
    text = fig3.read_text().replace('[solver]\n', '[solver]\ncontinuation = "arclength"\n', 1)
    text = text.replace('contact_model = "complementarity"', 'contact_model = "hertz-closure"')
    p = tmp_path / "s.toml"
    p.write_text(text)
    with pytest.raises(SceneError) as e:
        femadh.load_scene(p)
    msg = str(e.value)
    assert "solver.continuation" in msg and "arclength" in msg and "sigma-gap" in msg
