"""The sigma-gap contact branch traced in its edge radius (femadh/contact/sigma_edge.py):
Hertz's limit, complementarity along the branch, its states as solutions of the runner's
collocation problem on their scaled grids, dd/dc against finite differences, and the
branch's largest force against the runner's solver on the same fixed grid.

Small sizes: the stiction map's point sigma = 0.489 nm, p/psat 0.15 (LJ, sigma-gap and the
sub-grid capillary step) on the 5.25-nm edge grid of validation/sigma_edge.py's pilot
(125 nodes); ~2 CPU-s in all."""
import math

import numpy as np
import pytest

import femadh
from femadh.contact import AsperityGap, ContactProblem, solve_state
from femadh.contact.edge_branch import edge_grid
from femadh.contact.sigma_edge import (SigmaEdgeBranch, hertz_guess, tail_between,
                                       trace_retract)
from femadh.elastic import GreenOperator, RadialGrid
from femadh.indenter import Sphere

SCENE = "validation/scenes/paper1_slider_meniscus.toml"
E_STAR = 5.848e10


def _hertz_branch(h, sigma=3e-10):
    g, k = edge_grid(20e-6, 1e-6, h, 24 * h, 8 * h)
    return SigmaEdgeBranch(GreenOperator(g, E_STAR), k, Sphere(2e-3), {}, AsperityGap(sigma),
                           1e-19)


def test_hertz_limit():
    """Without surface forces the branch is Hertz's: d = sigma - c^2/R, F = -4 E* c^3/3R.
    The scaled grid makes the discrete state self-similar (the same relative error at c and
    1.5 c: measured equal to 4e-13), the error is first order in h/c (ratio 2.000 from 20 to
    10 nm: the edge node's multiplier pinned to 0 where Hertz's p ~ (c - r)^1/2) and its
    first-order Richardson extrapolation meets Hertz: measured 5.4e-6 (d) and 1.7e-5 (F)."""
    R, sigma = 2e-3, 3e-10
    errs = {}
    for h in (20e-9, 10e-9):
        br = _hertz_branch(h, sigma)
        for c in (1e-6, 1.5e-6):
            w0, d0 = hertz_guess(br, c)
            st = br.solve(c, w0, d0)
            assert st is not None and st.residual <= 1e-19
            # the guess is Hertz's continuum state: the discrete one's d to its O(h) error
            # (measured 0.70 % and 0.35 % of the interference at 20 and 10 nm)
            assert abs(st.d - d0) < 0.015 * c * c / R
            # complementarity: every held node pushes, every free gap is open
            assert st.p_c[:br.k].min() > 0
            assert st.h[br.k + 1:].min() > sigma
            delta = c * c / R
            errs[h, c] = ((st.d - (sigma - delta)) / delta,
                          br.force(st) / (-4 * E_STAR * c ** 3 / (3 * R)) - 1,
                          br.slope(st) / (-2 * c / R) - 1)
    for h in (20e-9, 10e-9):
        assert errs[h, 1e-6] == pytest.approx(errs[h, 1.5e-6], rel=1e-9, abs=0)
    for j in range(3):
        ratio = errs[20e-9, 1e-6][j] / errs[10e-9, 1e-6][j]
        assert ratio == pytest.approx(2.0, rel=0.02), j       # measured 1.994-2.004
    rich = [2 * errs[10e-9, 1e-6][j] - errs[20e-9, 1e-6][j] for j in range(3)]
    assert abs(rich[0]) < 2e-5 and abs(rich[1]) < 5e-5, rich


@pytest.fixture(scope="module")
def point():
    scene = femadh.load_scene(SCENE).replace({"effects.asperity_gap.sigma": "0.489 nm",
                                              "effects.capillary.relative_pressure": 0.15})
    a_run = scene.discretisation.analysis_radius
    g, k = edge_grid(2 * a_run, 1e-6, 5.25e-9, 24 * 5.25e-9, 8 * 5.25e-9)
    br = SigmaEdgeBranch(GreenOperator(g, scene.body.e_star), k, scene.sphere, scene.effects,
                         scene.gap, scene.tolerance)
    return scene, br, trace_retract(br, 1e-6, 0.5e-6, 8e-6)


def test_branch_complementarity(point):
    """Every state of the traced retract (deep contact to the pull-off fold and past it) holds
    complementarity: multipliers >= 0 inside (measured >= 0.097 of the largest),
    free gaps above sigma (measured >= 1.2e-3 sigma); d(c) has its maximum at the fold."""
    scene, br, r = point
    sigma = scene.gap.sigma
    for st in r.states + [r.fold, r.best]:
        assert st.residual <= scene.tolerance
        assert st.p_c[:br.k].min() > 0
        assert st.h[br.k + 1:].min() > sigma
    assert r.fold.d >= max(s.d for s in r.states)
    # the largest tension is interior (c* ~ 1.47 um, d* ~ 0.92 nm: the runner's peak at
    # 0.922 nm) and on the stable side of the fold
    assert not r.at_fold and r.best.c > r.fold.c
    assert 0.90e-9 < r.best.d < 0.94e-9


def test_states_solve_the_runners_equations(point):
    """At the fold, the largest force and the deepest state: the runner's ContactProblem on
    the scaled grid (a Green operator built afresh on the scaled nodes, the sub-grid capillary
    step) has the branch's compliance times lam (measured 2e-16 relative), the state's
    residual of eq 6 is below the runner's tolerance, the runner's stability test passes and
    its semismooth Newton from the state stops at once on it (1 iteration, w moved by
    < 1e-19 m: measured 7e-20)."""
    from femadh.contact.stability import is_stable

    scene, br, r = point
    for st in (r.fold, r.best, r.states[-1]):
        grid = RadialGrid.from_nodes(st.lam * br.nodes0, br.radius(st))
        op = GreenOperator(grid, scene.body.e_star)
        err = np.abs(op.compliance - st.lam * br.C0).max() / np.abs(op.compliance).max()
        assert err < 1e-13
        pb = ContactProblem(op, scene.sphere, dict(scene.effects), scene.gap)
        assert np.abs(st.w - pb.C @ (pb.pressure(st.h) - st.p_c)).max() <= scene.tolerance
        held = np.arange(br.n) <= br.k
        assert is_stable(pb, st.h, ~held)
        # the branch's own problem on the scaled grid is that problem: its sub-grid step
        # built on the scaled nodes (a step kept on the reference nodes is off by lam^-2:
        # lam = 0.63-1.59 here), so its stability verdict is the runner's
        own = st.problem.pressure(st.h)
        assert np.abs(own - pb.pressure(st.h)).max() <= 1e-12 * np.abs(own).max()
        assert br.stable(st)
        sol = solve_state(pb, st.d, st.w, tol=scene.tolerance, max_iter=scene.max_iter,
                          active0=held)
        assert sol.converged and sol.n_iter <= 1
        assert np.abs(sol.w - st.w).max() < 1e-19
        assert not sol.active[br.k + 1:].any() and sol.active[:br.k].all()


def test_slope_against_finite_differences(point):
    """dd/dc from the linearised system against central differences of solved states
    (relative step 1e-5: measured agreement 1e-8 of the slope), and dw/dc on the free
    nodes; at the fold dd/dc vanishes (to 1e-6 of the slope a step away)."""
    scene, br, r = point
    st = r.best
    dw, dd = br.tangent(st)
    eps = 1e-5 * st.c
    hi = br.solve(st.c + eps, st.w, st.d)
    lo = br.solve(st.c - eps, st.w, st.d)
    fd = (hi.d - lo.d) / (2 * eps)
    assert dd == pytest.approx(fd, rel=1e-6, abs=0)
    fdw = (hi.w[br.k + 1:] - lo.w[br.k + 1:]) / (2 * eps)
    assert np.abs(dw - fdw).max() < 1e-5 * np.abs(fdw).max()
    assert abs(r.fold.dd_dc) < 1e-6 * abs(r.states[-1].dd_dc)


def test_largest_force_against_the_runners_curve(point):
    """The branch's largest force against the runner's solver on a fixed grid (the branch's
    reference grid scaled to put node k at c*): at the branch's d* the runner's semismooth
    Newton from the branch's state returns it (F_ex equal to 1e-9: measured 9e-13); at
    d* +- 0.01 and 0.02 nm (the edge 14-28 nm away, 2-4 of the 7.7-nm nodes) the fixed
    grid's states, each solved from the branch's state, lie below the branch - its junction
    states are the upper envelope of the fixed grid's node-by-node curve - by its lattice
    sawtooth, measured 1.3e-3 to 3.0e-3 relative at this spacing (6e-3 allowed)."""
    scene, br0, r0 = point
    c = r0.best.c
    s = c / 1e-6
    g, k = edge_grid(br0.base.grid.radius * s, c, 5.25e-9 * s, 24 * 5.25e-9 * s,
                     8 * 5.25e-9 * s)
    br = SigmaEdgeBranch(GreenOperator(g, scene.body.e_star), k, scene.sphere, scene.effects,
                         scene.gap, scene.tolerance)
    best = br.solve(c, np.interp(g.nodes, r0.best.lam * br0.nodes0, r0.best.w), r0.best.d)
    assert best is not None
    F_branch = br.force(best)
    # the same state on either grid (the grids are scalings of one)
    assert F_branch == pytest.approx(br0.force(r0.best), rel=1e-9, abs=0)
    pb = ContactProblem(br.base, scene.sphere, dict(scene.effects), scene.gap)
    rel = []
    for d in best.d + np.array([0, 1, 2, -1, -2]) * 1e-11:
        w0 = np.minimum(best.w, pb.contour(d) - scene.gap.sigma)
        st = solve_state(pb, d, w0, tol=scene.tolerance, max_iter=200,
                         active0=pb.contour(d) - w0 <= scene.gap.sigma * (1 + 1e-9))
        assert st.converged and st.stable
        rel.append(pb.grid.force(st.p_total) / F_branch - 1)
    assert abs(rel[0]) < 1e-9
    assert all(-6e-3 < x < 0 for x in rel[1:]), rel


def test_tail_between_against_quadrature():
    """The laws' force between two radii on the undeformed paraboloid against a fine
    trapezoid of P(h(r)) 2 pi r dr (LJ and the capillary step; measured 1e-7 relative)."""
    scene = femadh.load_scene(SCENE).replace({"effects.asperity_gap.sigma": "0.3 nm"})
    R, d = scene.sphere.radius, 1.2e-9
    a1, a2 = 8e-6, 20e-6
    r = np.linspace(a1, a2, 200001)
    h = d + r * r / (2 * R)
    P = sum(np.asarray(e.pressure(h)) for e in scene.effects.values())
    ref = np.trapezoid(P * 2 * math.pi * r, r)
    got = tail_between(scene.effects, scene.sphere, d, a1, a2)
    assert got == pytest.approx(ref, rel=1e-5, abs=0)


def test_bad_input():
    g, k = edge_grid(20e-6, 1e-6, 20e-9, 480e-9, 160e-9)
    op = GreenOperator(g, E_STAR)
    with pytest.raises(ValueError, match="complementarity"):
        SigmaEdgeBranch(op, k, Sphere(2e-3), {}, AsperityGap(3e-10, "hertz-closure"), 1e-19)
    with pytest.raises(ValueError, match="complementarity"):
        SigmaEdgeBranch(op, k, Sphere(2e-3), {}, AsperityGap(3e-10, adhesion=1e6), 1e-19)
    with pytest.raises(ValueError, match="edge node"):
        SigmaEdgeBranch(op, 0, Sphere(2e-3), {}, AsperityGap(3e-10), 1e-19)


def test_start_by_homotopy_keeps_complementarity():
    """Where Newton from Hertz's state fails (sigma = 0.4889 nm, p/psat 0.15 on a 2-nm grid at
    c = 1 um: measured), the homotopy in the laws' strength reaches the branch's state: the
    same state as on a 4-nm grid where Newton from Hertz converges directly (d within 3e-4
    relative: measured 2.3e-4), complementarity holding. Without the homotopy's
    complementarity guard it ended on a root with a free gap below sigma at d = 3.43 nm."""
    from femadh.contact.sigma_edge import start_state

    scene = femadh.load_scene(SCENE).replace({"effects.asperity_gap.sigma": "0.4889 nm",
                                              "effects.capillary.relative_pressure": 0.15})
    a = 20 * scene.discretisation.analysis_radius
    out = {}
    for h in (2e-9, 4e-9):
        g, k = edge_grid(a, 1e-6, h, 24 * h, 8 * h)
        br = SigmaEdgeBranch(GreenOperator(g, scene.body.e_star), k, scene.sphere,
                             scene.effects, scene.gap, scene.tolerance)
        direct = br.solve(1e-6, *hertz_guess(br, 1e-6))
        st = start_state(br, 1e-6)
        assert br.complementary(st) and st.residual <= scene.tolerance
        out[h] = (direct, st)
    assert out[2e-9][0] is None                       # the case the homotopy is for
    assert out[4e-9][0] is not None and out[4e-9][0].d == out[4e-9][1].d
    assert out[2e-9][1].d == pytest.approx(out[4e-9][1].d, rel=3e-4, abs=0)


def test_states_at_the_sweeps_separations(point):
    """The routed run's retract (femadh/runner/edge_sweep.py) reads the branch at the
    sweep's separations: traced on up to d = -2 nm (extend_deep: d falls monotonically with
    c on the stable part, complementarity on every new state), a state placed at each
    separation by secant in c (its d within 1e-6 of its bracket's width), polished there
    by the runner's corrector in at most one iteration to a converged, stable state at
    exactly that d with the branch's contact set (nodes 0..k-1, the edge node either way);
    the fold's state as the runner's (as_runner_state: its residual within the tolerance,
    nodes 0..k held). A separation outside the stable part has no state."""
    from femadh.contact.sigma_edge import (as_runner_state, extend_deep, runner_state,
                                           state_at_separation)

    scene, br, r = point
    stable = extend_deep(br, r, -2e-9)
    assert stable[0] is r.fold and stable[-1].d <= -2e-9
    assert all(a.d > b.d and a.c < b.c for a, b in zip(stable, stable[1:]))
    for s in stable:
        p, g = br.complementarity(s)
        assert p >= 0 and g > 0
    width = max(a.d - b.d for a, b in zip(stable, stable[1:]))
    for d in (-2e-9, -0.4e-9, 0.92e-9, 1.2e-9, r.fold.d - 1e-11):
        bst = state_at_separation(br, stable, d)
        assert abs(bst.d - d) <= 1e-6 * width
        pb, st = runner_state(bst, d, scene.tolerance, scene.max_iter)
        assert st.converged and st.stable and st.n_iter <= 1 and st.d == d
        assert st.active[:br.k].all() and not st.active[br.k + 1:].any()
        assert pb.grid.n == br.n and pb.grid.nodes[br.k] == pytest.approx(bst.c, rel=1e-12,
                                                                          abs=0)
    pb, st = as_runner_state(r.fold, scene.tolerance)
    assert st.converged and st.residual <= scene.tolerance
    assert st.active.sum() == br.k + 1 and st.d == r.fold.d
    assert state_at_separation(br, stable, r.fold.d + 1e-10) is None
    assert state_at_separation(br, stable, stable[-1].d - 1e-10) is None


def test_a_separation_within_the_landings_resolution_of_the_fold_gets_its_state(point):
    """The routed retract (femadh/runner/edge_sweep.py) lands the jump-out at most at the
    sweep's first separation beyond the fold: one within 2^-10 of a step beyond the fold
    (here 1e-13 m) gets the landing as its state (found by review: it got none, the curve
    one row short), and every separation has exactly one retract state."""
    from types import SimpleNamespace

    from femadh.runner.edge_sweep import trace_retract_sweep

    scene, br, r = point
    d_f = r.fold.d
    ds = [d_f - 0.5e-9, d_f + 1e-13, d_f + 0.5e-9]
    states, jumps = [], []
    sink = SimpleNamespace(plan=lambda branch, n: None, writer=None, problem=None,
                           state=lambda branch, st: states.append(st.d),
                           jump=lambda j: jumps.append(j))
    sc = SimpleNamespace(d_values=ds[::-1], tolerance=scene.tolerance,
                         max_iter=scene.max_iter)
    out = trace_retract_sweep(sc, sink, br, r)
    assert out["departed"] == d_f and len(jumps) == 1
    assert jumps[0].d_fold == d_f and jumps[0].d_land == ds[1]
    assert jumps[0].resolution == ds[1] - d_f       # where it landed, not the landing step
    assert states == ds
