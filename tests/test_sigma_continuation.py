"""Arclength continuation of the sigma-gap complementarity model through its folds
(femadh.contact.sigma_arclength) against the stepping solver on the same discrete problem."""
import tomllib

import numpy as np
import pytest

from femadh.contact import trace
from femadh.contact.forces import state_forces
from femadh.contact.sigma_arclength import curve_state, path_w_at, trace_sigma_curve
from femadh.contact.stability import is_stable
from femadh.scene import build_problem, scene_from_dict

from conftest import fig3_uniform_text


def small_text(nodes=120, stop="-1 nm"):
    """The Fig 3 scene at sigma = 0.5 nm (the Fig 4 gap: a jump-in and a jump-out) on a
    uniform grid of ``nodes`` nodes, swept from 2 nm to ``stop``."""
    return (fig3_uniform_text().replace('sigma = "1.0 nm"', 'sigma = "0.5 nm"')
            .replace("nodes = 200", f"nodes = {nodes}")
            .replace('stop = "-5 nm"', f'stop = "{stop}"'))


@pytest.fixture(scope="module")
def traced():
    """(problem, curve, approach sweep, retract sweep) of the small sigma = 0.5 nm scene."""
    return stepped_and_traced(scene_from_dict(tomllib.loads(small_text())))


def stepped_and_traced(sc):
    """(problem, curve, approach sweep, retract sweep) of a scene: its stepped branches and
    its sigma-gap curve traced by arclength over the same separations."""
    problem = build_problem(sc)
    d, tol = sc.d_values, sc.tolerance
    ap = trace(problem, d, branch="approach", tol=tol)
    rt = trace(problem, d[::-1], branch="retract", tol=tol, start=ap.states[-1])
    curve = trace_sigma_curve(problem, d[0], d[-1], tol=tol, scale=abs(d[1] - d[0]), ds=1.0,
                              ds_max=1.0)
    return problem, curve, ap, rt


def force(problem):
    return lambda d, w: state_forces(problem, curve_state(problem, d, w, True))[2]


def test_stable_states_match_the_stepped_branches(traced):
    """Every state of the stepped approach and retract lies on the traced curve's
    displacement-controlled path: F_ex at the same d agrees (both solved to 1e-19 m;
    measured worst 1.6e-10 relative, from the residuals' force equivalents)."""
    problem, curve, ap, rt = traced
    F = force(problem)
    n = 0
    for sweep, branch in ((ap, "approach"), (rt, "retract")):
        for st in sweep.states:
            w = path_w_at(curve, branch, st.d)
            assert w is not None, f"{branch}: d = {st.d:.6g} m not on the traced path"
            f_step = state_forces(problem, st)[2]
            assert F(st.d, w) == pytest.approx(f_step, rel=2e-9, abs=0)
            n += 1
    assert n == len(ap.states) + len(rt.states) == 32


def test_folds_are_the_stepped_jumps(traced):
    """Each jump of the stepping solver (the last stable d, the fold within one halved step
    of it in the travel direction) has a fold of the traced curve in that bracket; the
    approach's first fold (the jump-in) is the curve's first fold."""
    _, curve, ap, rt = traced
    assert len(ap.jumps) == 1 and len(rt.jumps) >= 1
    for j in ap.jumps + rt.jumps:
        sign = -1.0 if j.branch == "approach" else 1.0
        lo, hi = sorted((j.d_fold, j.d_fold + sign * j.resolution))
        assert any(lo <= f.d <= hi for f in curve.folds), (j.branch, j.d_fold)
    assert ap.jumps[0].d_fold - ap.jumps[0].resolution <= curve.folds[0].d \
        <= ap.jumps[0].d_fold


def _dF_dd(problem, p):
    """dF_ex/dd (N/m) along the curve at point p: F_ex = sum area (K w) at equilibrium."""
    return float(problem.areas @ (problem.K @ p.t[:-1])) / p.t_d


def test_unstable_branch_between_the_folds(traced):
    """Between the jump-in fold and the next fold every point is unstable (the Hessian on
    its free nodes is indefinite, recomputed here); the force keeps rising through the
    fold, so dF/dd < 0 before it (stable: F grows as the sphere approaches) and > 0 after
    it (d turns back); the largest tension on the curve is at least the largest the
    displacement-controlled retract reaches (measured 1.1 % above it: the unstable JKR
    side is pulled beyond the displacement-controlled pull-off)."""
    problem, curve, ap, rt = traced
    f0, f1 = curve.folds[0], curve.folds[1]
    pts = curve.points
    between = pts[f0.index + 1:f1.index + 1]
    assert len(between) >= 5
    for p in between:
        # free nodes: those of the point's piece (an event state at a corner fold is the
        # last state of the unstable piece and the first of the stable one)
        assert not p.stable
        assert not is_stable(problem, problem.contour(p.d) - p.w,
                             ~curve.tracers[p.seg].active)
    before = pts[f0.index]
    assert before.stable and is_stable(problem, problem.contour(before.d) - before.w, None)
    assert _dF_dd(problem, before) < 0 < _dF_dd(problem, pts[f0.index + 1])
    F = force(problem)
    f_curve = max(F(p.d, p.w) for p in pts)
    f_retract = max([state_forces(problem, s)[2] for s in rt.states]
                    + [state_forces(problem, j.before)[2] for j in rt.jumps])
    assert f_curve >= f_retract * (1 + 5e-3)


def test_tangent_against_finite_differences(traced):
    """(dw/ds, dd/ds) of a point on the unstable contact branch against the central
    difference of two corrected neighbours at +-delta along it: O(delta^2) (measured
    1.9e-5 at delta = 1e-3, 1.9e-7 at 1e-4 step units, in the arclength norm of the unit
    tangent; a first-order error, e.g. a tangent of the wrong piece, falls only 10x)."""
    problem, curve, _, _ = traced
    pts = curve.points
    f0 = curve.folds[0]
    # an interior point of a contact piece on the unstable branch, neighbours on its piece
    k = next(i for i in range(f0.index + 2, len(pts) - 1)
             if pts[i].seg == pts[i - 1].seg == pts[i + 1].seg
             and curve.tracers[pts[i].seg].A.size > 0 and not pts[i].stable)
    p = pts[k]
    pc = curve.tracers[p.seg]
    x = np.r_[p.w, p.d] / pc.scale
    errs = []
    for delta in (1e-3, 1e-4):
        xp, _, _, okp = pc.correct(x + delta * p.t, p.t)
        xm, _, _, okm = pc.correct(x - delta * p.t, p.t)
        assert okp and okm
        fd = (xp - xm) / (2 * delta)
        diff = fd - p.t
        errs.append(np.sqrt(pc.omega * diff[:-1] @ diff[:-1] + diff[-1] ** 2))
    assert errs[0] < 4e-5 and errs[1] < 4e-7    # 2x the measured errors
    assert errs[1] < errs[0] / 50          # second order: 100x for 10x smaller delta


def test_cycle_work_is_the_hysteresis(traced):
    """The loop integral of F dd around the traced cycle (the area it encloses) equals the
    energy the stepped jumps release, within the stepping resolution's error bound
    sum |F_after - F_before| * resolution (measured: 3.8e-18 J apart, bound 1.8e-17 J)."""
    problem, curve, ap, rt = traced
    jumps = ap.jumps + rt.jumps
    released = sum(problem.energy(j.before.w, j.d_land) - problem.energy(j.after.w, j.d_land)
                   for j in jumps)
    bound = sum(abs(state_forces(problem, j.after)[2] - state_forces(problem, j.before)[2])
                * j.resolution for j in jumps)
    work = curve.cycle_work(force(problem))
    assert released > 0
    assert work == pytest.approx(released, abs=bound)


def test_scene_with_sigma_gap_runs_arclength(tmp_path):
    """`continuation = "arclength"` with the complementarity sigma-gap: the run converges,
    its equilibrium_curve holds unstable states and its jumps are the curve's folds; the
    Hertz closure is refused in one line naming the key."""
    import femadh
    from femadh.errors import SceneError

    text = small_text(nodes=100, stop="0 nm").replace(
        "[solver]\n", '[solver]\ncontinuation = "arclength"\n', 1)
    p = tmp_path / "arc.toml"
    p.write_text(text)
    res = femadh.run(femadh.load_scene(p), None, figures=False, progress=False,
                     estimate=False)
    assert res.status == "converged", res.error
    ec = res.equilibrium_curve
    assert np.any(~ec["stable"]) and np.any(ec["stable"])
    assert np.count_nonzero(np.diff(np.sign(ec["dd_ds"]))) >= 2
    assert {j["branch"] for j in res.jumps} == {"approach", "retract"}
    assert res.headline["hysteresis_J"] > 0
    closure = text.replace('contact_model = "complementarity"', 'contact_model = "hertz-closure"')
    p.write_text(closure)
    with pytest.raises(SceneError) as e:
        femadh.load_scene(p)
    assert "solver.continuation" in str(e.value) and "hertz-closure" in str(e.value)
    assert len(str(e.value).splitlines()) == 1
    # eq 20 on the contact set: a node joins with lambda = P_LJa and leaves at lambda = 0,
    # so approach and retract part at every node (no single curve): refused
    adhesive = text + ('\n[effects.asperity_adhesion]\nasperity_radius = "0.94 um"\n'
                       'surface_energy = "0.06 J/m^2"\ndensity = "179 um^-2"\n'
                       'contact_probability = 0.5\n')
    p.write_text(adhesive)
    with pytest.raises(SceneError) as e:
        femadh.load_scene(p)
    assert "asperity_adhesion" in str(e.value) and len(str(e.value).splitlines()) == 1
    p.write_text(adhesive + 'model = "smoothed"\n')
    assert femadh.load_scene(p).continuation == "arclength"


def test_a_stalled_trace_names_where_it_stopped(monkeypatch):
    """A corrector that cannot converge (one Newton iteration allowed) stops the trace with
    a ConvergenceError naming the separation, residual and iterations, the partial curve
    attached (from the converged start state to where it stopped)."""
    import femadh.contact.sigma_arclength as sa
    from femadh.errors import ConvergenceError

    sc = scene_from_dict(tomllib.loads(small_text(nodes=40, stop="1 nm")))
    problem = build_problem(sc)
    monkeypatch.setattr(sa, "MAX_ITER", 1)
    with pytest.raises(ConvergenceError) as e:
        trace_sigma_curve(problem, 2e-9, 1e-9, tol=sc.tolerance, scale=0.2e-9, ds=1.0)
    exc = e.value
    # (tiny steps whose prediction already meets the tolerance still pass: a few points)
    assert "stalled after d = " in str(exc) and "residual" in str(exc)
    assert 1e-9 < exc.d <= 2e-9 and np.isfinite(exc.residual) and exc.n_iter == 1
    assert exc.curve.points[0].d == 2e-9 and exc.curve.points[0].residual <= sc.tolerance
    assert abs(exc.curve.points[-1].d - exc.d) < 0.01e-9


def test_a_small_jump_in_inside_one_grid_step_is_found():
    """Fig 8 with eq 20 as the smoothed law: the jump-in lies inside one 0.2-nm grid step and
    moves no gap by more than a quarter of it, so the corrector alone lands on the contact
    branch in one step; the step's energy gives it away (it releases ~1.8x what one branch
    can miss). The stepped approach reports the jump-in at the traced curve's first fold
    (within its resolution), and the stepped jumps release the curve's cycle work within the
    stepping bound (before the energy check: no jump-in, 9.7e-16 J of a 4.6e-15 J loop)."""
    import copy
    from pathlib import Path

    from femadh.scene import load_scene

    path = Path(__file__).resolve().parents[1] / "validation/scenes/paper1_fig8_rho179.toml"
    raw = copy.deepcopy(load_scene(path).raw)
    raw["effects"]["asperity_adhesion"]["model"] = "smoothed"
    problem, curve, ap, rt = stepped_and_traced(scene_from_dict(raw, str(path)))
    assert len(ap.jumps) == 1
    j = ap.jumps[0]
    assert j.d_fold - j.resolution <= curve.folds[0].d <= j.d_fold
    jumps = ap.jumps + rt.jumps
    released = sum(problem.energy(j.before.w, j.d_land) - problem.energy(j.after.w, j.d_land)
                   for j in jumps)
    bound = sum(abs(state_forces(problem, j.after)[2] - state_forces(problem, j.before)[2])
                * j.resolution for j in jumps)
    assert curve.cycle_work(force(problem)) == pytest.approx(released, abs=bound)
