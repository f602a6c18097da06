"""The sigma-gap corrector's pace without its physics moving: Newton-Krylov steps on a disk
contact reproduce the LU path's states, converge quadratically once the contact set settles,
give up on a step across a fold within their stagnation window (naming where and how far
they got), and a node snapping across the lattice is stepped over while the contact's own
snaps stay jumps."""
import math

import numpy as np
import pytest

from femadh.contact import complementarity as cm
from femadh.contact import snap, stepping
from femadh.contact.complementarity import solve_complementarity
from femadh.contact.linalg import TrailingCholesky, gmres
from femadh.contact.stepping import step_energy, total_force

from conftest import FIG4_TOL as TOL, fig4_problem, fig4_sweeps

#: 240 uniform nodes on the Fig 4 disk (sigma = 0.5 nm): more than KRYLOV_MIN_FREE free nodes
#: around both folds, so the Krylov path takes the steps
N = 240


@pytest.fixture(scope="module")
def fig4():
    p = fig4_problem(N)
    return p, fig4_sweeps(p)


def test_krylov_steps_reproduce_the_lu_path(fig4, monkeypatch):
    """The same states and folds as the LU corrector without the stagnation exit (the solver
    before this change): every grid state within 3x the tolerance (measured 2.2e-19 m on
    N = 240 over d = 2 .. -1 nm, tolerance 1e-19 m: both meet the residual tolerance, so
    they differ by about it), the folds at the same separation to a thousandth of their
    resolution (measured: the same to the last bit but one)."""
    p, (ap, re) = fig4
    assert ap.work["solves"] and ap.work["factorisations"] < ap.work["iterations"]
    monkeypatch.setattr(cm, "KRYLOV", False)
    monkeypatch.setattr(stepping, "STALL_ITER", None)
    ap0, re0 = fig4_sweeps(p)
    assert ap0.work["stagnated"] == re0.work["stagnated"] == 0
    for new, old in ((ap, ap0), (re, re0)):
        assert [s.d for s in new.states] == [s.d for s in old.states]
        for a, b in zip(new.states, old.states):
            assert np.max(np.abs(a.w - b.w)) <= 3 * TOL
            assert np.array_equal(a.active, b.active)
        assert len(new.jumps) == len(old.jumps) == 1
        assert new.jumps[0].d_fold == pytest.approx(old.jumps[0].d_fold,
                                                    abs=1e-3 * old.jumps[0].resolution)
    # and with less work: the LU path needs more iterations (measured 726 + 1012 against
    # 393 + 688 on the longer sweep)
    assert ap.work["iterations"] + re.work["iterations"] < \
        ap0.work["iterations"] + re0.work["iterations"]


def test_newton_converges_quadratically_once_the_contact_set_settles(fig4):
    """From the tangent predictor of the deepest approach state, the residuals of the
    iterations with an unchanged contact set fall with observed order ~2 (measured 1.95 and
    1.9 over the last three; a chord step would show ~1), down to the tolerance."""
    p, (ap, _) = fig4
    st = ap.states[-1]
    assert ap.states[-1].active.sum() > 0 and p.grid.n - st.active.sum() > cm.KRYLOV_MIN_FREE
    d = st.d - 0.05e-9
    w, act = stepping._predict(p, st, d)
    stats = {"history": []}
    new = solve_complementarity(p, d, w, tol=TOL, max_iter=40, active0=act, factor=st.lu,
                                stats=stats)
    assert new.converged and new.n_iter <= 6
    settled = []
    for res, _, same, _ in stats["history"]:
        settled = settled + [res] if same else []
    # residuals far above round-off (~1e-24 m here): the quadratic phase
    r = [x for x in settled if x > 1e-22]
    assert len(r) >= 3, stats["history"]
    orders = [math.log(r[k + 2] / r[k + 1]) / math.log(r[k + 1] / r[k])
              for k in range(len(r) - 2)]
    assert min(orders) > 1.6, (orders, stats["history"])
    assert settled[-1] <= TOL


def test_a_step_across_the_fold_gives_up_in_its_stagnation_window(fig4):
    """Beyond the jump-in fold no equilibrium continues the branch: from the branch's
    predictor, a corrector with the whole budget either runs to max_iter (measured: 40
    iterations ending at 1.4e-13 .. 1.9e-12 m) or, on some hosts' last bits, wanders into the
    landed contact state (measured with Haswell BLAS kernels at the landing separation: 32
    iterations to 28 contact nodes) - never a non-contact state. At the first separation of
    d_land, d_fold - 2, 3 resolutions where the whole budget fails (measured: d_land with
    Intel AVX-512 and Sandybridge kernels, d_fold - 2 resolutions on all three), the
    stagnation exit gives up STALL_ITER iterations after its last progress (measured at
    iteration 9), not converged, its diagnostics naming the separation, iterations and
    residuals - and the continuation's decision at the smallest step still has the whole
    budget (the fold is where it was, test above)."""
    p, (ap, _) = fig4
    j = ap.jumps[0]
    assert j.before.active.sum() == 0 < j.after.active.sum()
    d = None
    for dk in (j.d_land, j.d_fold - 2 * j.resolution, j.d_fold - 3 * j.resolution):
        w, act = stepping._predict(p, j.before, dk)
        full = solve_complementarity(p, dk, w, tol=TOL, max_iter=40, active0=act,
                                     factor=j.before.lu)
        if full.converged:
            assert full.active.sum() > 0, dk     # the landed state, not the branch
            continue
        assert full.n_iter == 40 and not full.diagnostics
        d = dk
        break
    assert d is not None
    stats = {}
    cut = solve_complementarity(p, d, w, tol=TOL, max_iter=40, active0=act,
                                factor=j.before.lu, stall_iter=cm.STALL_ITER, stats=stats)
    assert not cut.converged and cut.n_iter < 40
    why = cut.diagnostics["stagnated"]
    assert why["d_m"] == d and why["iterations"] == cut.n_iter
    assert why["iterations"] - why["since_iteration"] == cm.STALL_ITER
    assert why["residual_m"] == cut.residual and math.isfinite(cut.residual)
    assert why["best_residual_m"] > TOL
    assert stats == {"solves": 1, "iterations": cut.n_iter, "factorisations": 0,
                     "stagnated": 1}


def test_lattice_snaps_are_stepped_over_and_contact_snaps_stay_jumps(monkeypatch):
    """On 180 uniform nodes the retracting contact sheds a node across the lattice before it
    pulls off (whether a shed node shows as a landing depends on the path of the trial steps:
    on 150 nodes the halving's path met one and the bracketed fold search's does not; on 180
    nodes it meets two). Without the rule
    the continuation reports it as a jump whose landing released a few hundredths of the
    step's work (measured 0.026 at N = 240) next to the pull-off's ~140x; with it every
    reported jump releases more than 10x its step's work and the lattice snap is counted,
    not reported."""
    p = fig4_problem(180)

    def released(j):
        r, _, w, _ = step_energy(p, j.before, j.after, total_force(p, j.before),
                                 total_force(p, j.after))
        return r / w
    ap, re = fig4_sweeps(p)
    assert len(ap.jumps) == len(re.jumps) == 1
    assert all(released(j) > 10 for j in ap.jumps + re.jumps)
    snaps = ap.work.get("lattice_snaps", 0) + re.work.get("lattice_snaps", 0)
    assert snaps >= 1
    monkeypatch.setattr(stepping, "lattice_snap", lambda *a: False)
    ap1, re1 = fig4_sweeps(p)
    small = [released(j) for j in ap1.jumps + re1.jumps if released(j) <= 10]
    assert len(small) == snaps and all(x < stepping.FOLD_ENERGY_SHARE_MIN_STEP for x in small)
    big = [j.d_fold for j in ap1.jumps + re1.jumps if released(j) > 10]
    assert big == [j.d_fold for j in ap.jumps + re.jumps]


@pytest.mark.parametrize("dtype, tol", [(np.float64, 1e-11), (np.float32, 2e-6)])
def test_trailing_cholesky_solves_every_covered_trailing_block(dtype, tol, monkeypatch):
    """The reversed Cholesky's leading blocks are the trailing blocks' factors (no
    pivoting): each solve meets its own block to round-off - of double precision, and of the
    single precision the kept factor has by default (linalg.PRECONDITIONER_DTYPE; measured
    residual 3.4e-7 of the right-hand side here, condition number ~10) - a block beyond the
    positive definite part is refused, not solved."""
    from femadh.contact import linalg as la

    monkeypatch.setattr(la, "PRECONDITIONER_DTYPE", dtype)
    rng = np.random.default_rng(3)
    n = 40
    B = rng.standard_normal((n, n)) / math.sqrt(n)
    S = B @ B.T + np.eye(n)
    areas = rng.uniform(0.5, 2.0, n)
    D = np.zeros(n)
    pre = TrailingCholesky(S, areas, D, 4)
    assert pre.k_valid == n - 4
    for m in (4, 11, 30, n - 1):
        rhs = rng.standard_normal(n - m)
        x = pre.solve(m, rhs)
        assert x.dtype == np.float64
        assert np.max(np.abs(S[m:, m:] @ x - rhs)) < tol * np.max(np.abs(rhs))
    # a negative stiffness on node 20 makes every block that holds it indefinite
    D[20] = -10.0 / areas[20]
    pre = TrailingCholesky(S, areas, D, 0)
    assert pre.covers(21) and not pre.covers(20)
    with pytest.raises(ValueError, match="not covered"):
        pre.solve(20, np.ones(n - 20))


def test_gmres_meets_its_tolerance_or_says_it_did_not():
    """GMRES on a nonsymmetric system: the returned x meets the relative residual it claims
    (checked against A x, not GMRES's own estimate); too small a Krylov space says so."""
    rng = np.random.default_rng(5)
    n = 60
    A = np.eye(n) + 0.4 * rng.standard_normal((n, n)) / math.sqrt(n)
    b = rng.standard_normal(n)
    x, k, ok = gmres(lambda v: A @ v, lambda v: v, b, 1e-10, maxiter=60)
    assert ok and np.linalg.norm(A @ x - b) <= 1.01e-10 * np.linalg.norm(b)
    x2, k2, ok2 = gmres(lambda v: A @ v, lambda v: v, b, 1e-10, maxiter=3)
    assert not ok2 and k2 == 3 and np.linalg.norm(A @ x2 - b) > 1e-10 * np.linalg.norm(b)
    # a preconditioner that is the inverse: one iteration
    Ainv = np.linalg.inv(A)
    x3, k3, ok3 = gmres(lambda v: A @ v, lambda v: Ainv @ v, b, 1e-10)
    assert ok3 and k3 == 1


def test_the_stagnation_exit_turns_down_no_step_the_whole_budget_accepts(monkeypatch):
    """Each trial step that gave up in its stagnation window, solved again from the same start
    with the whole budget, is not a step the continuation accepts (measured on the N = 240
    sweep: it either ran to max_iter or converged across the fold, to the other branch); and
    the solve that decides each fold - the last one at its landing separation - had the whole
    budget."""
    p = fig4_problem(N)
    calls = []
    real = stepping.solve_complementarity

    def solve(problem, d, w0, **kw):
        st = real(problem, d, w0, **kw)
        calls.append((d, np.array(w0), kw, st))
        return st
    monkeypatch.setattr(stepping, "solve_complementarity", solve)
    monkeypatch.setattr(snap, "solve_complementarity", solve)     # the fold decisions'
    ap, re = fig4_sweeps(p)
    stalled = [c for c in calls if "stagnated" in c[3].diagnostics]
    assert stalled
    for d, w0, kw, st in stalled:
        full = real(p, d, w0, **{**kw, "stall_iter": None, "stats": None})
        assert not stepping._accept(full, w0, d), (d, full.n_iter)
    for j in ap.jumps + re.jumps:
        last = [c for c in calls if c[0] == j.d_land][-1]
        assert last[2]["stall_iter"] is None


def test_no_stagnation_exit_where_nodes_snap_on_their_own(monkeypatch):
    """The sec 6 slider with eq 20 as a step smoothed over 1 % of sigma on 100 nodes: the step
    softens 1.37x beyond a node's stiffness, so nodes snap on their own and the states reached
    depend on the path of step halvings. There the continuation keeps the whole budget on every
    step: its sweep is the one without the exit, state for state and jump for jump (measured
    with the exit: 8 jump-outs for 4, lattice states 0.2-0.9 nm before the pull-off)."""
    import warnings

    from femadh.runner.contact import solve_sweeps
    from validation.roughness import slider_scene

    scene = slider_scene(rho=179, smoothing=0.01).replace({"solver.nodes": 100})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")      # the narrow step is stiffer than a node
        p, sweeps, err = solve_sweeps(scene)
        assert err is None and p.surface_force_stiffness()[0] > 1
        monkeypatch.setattr(stepping, "STALL_ITER", None)
        _, plain, err0 = solve_sweeps(scene, p)
    assert err0 is None
    for b in ("approach", "retract"):
        assert [j.d_fold for j in sweeps[b].jumps] == [j.d_fold for j in plain[b].jumps]
        assert all(np.array_equal(x.w, y.w)
                   for x, y in zip(sweeps[b].states, plain[b].states))
        assert sweeps[b].work["stagnated"] == 0
