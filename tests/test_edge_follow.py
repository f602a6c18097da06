"""A band that follows the sigma-gap contact edge with its cohesive zone resolved (issue 21,
goal 1: the stiction map's sigma = 0.3 nm column): the zone's outer gap, the softening a node
at the edge meets, the spacing cap of a follow band and its estimate members, the exchange
rule that leads the edge's travel, and a small sigma = 0.3 nm sweep whose fine band stays on
the edge through the jump-in fold."""
import csv
import math

import numpy as np
import pytest

import femadh
from conftest import fields_by_state
from femadh.discretisation import GridFamily
from femadh.discretisation import moving, plan
from femadh.discretisation.moving import EdgeBand, zone_gap
from femadh.elastic import GreenOperator
from femadh.runner import adaptive
from femadh.runner.estimates import variant
from femadh.runner.run import run
from femadh.scene import build_problem

SLIDER = "validation/scenes/paper1_slider_meniscus.toml"
SIGMA = 0.3e-9


def corner(rel, **more):
    """The stiction map's sigma = 0.3 nm point at relative pressure ``rel``."""
    return femadh.load_scene(SLIDER).replace({"effects.asperity_gap.sigma": "0.3 nm",
                                              "effects.capillary.relative_pressure": rel,
                                              "sweep.start": "4 nm", **more})


def band_problem(scene, h, lo=2.8e-6, hi=3.2e-6, radius=1.4142e-5):
    fam = GridFamily(radius, hi, 8 * h, inner=lo)
    return build_problem(scene, operator=GreenOperator(fam.member(h), scene.e_star))


def test_the_zone_ends_where_the_softening_falls_to_a_tenth():
    """LJ alone (p/psat 0.95: the meniscus edge 23 nm up the gap, its secant softening 1e14
    Pa/m against LJ's 1.8e18): the zone ends where -P' has fallen to ZONE_FRACTION of its
    value at sigma; P ~ h^-3 far from z0 gives 10^(1/4) sigma = 0.533 nm, the (z0/h)^6
    repulsion (z0/sigma = 0.55) moves it by 2 % (measured 0.5436 nm). At p/psat 0.15 the
    meniscus edge h_c + 2w (0.570 nm) lies beyond and its secant softening (7.6e17 Pa/m) is
    above a tenth of LJ's: the zone ends at the meniscus edge."""
    wet = corner(0.95)
    g = zone_gap(wet.effects, SIGMA)
    assert g == pytest.approx(10**0.25 * SIGMA, rel=0.03, abs=0)
    lj = wet.effects["lj"]
    h = np.array([SIGMA, g])
    soft = -lj.dpressure(h)
    assert soft[1] / soft[0] == pytest.approx(moving.ZONE_FRACTION, rel=0.01, abs=0)
    dry = corner(0.15)
    cap = dry.effects["capillary"]
    assert cap.edge_softening(SIGMA) > moving.ZONE_FRACTION * soft[0]
    assert zone_gap(dry.effects, SIGMA) == pytest.approx(cap._center + 2 * cap.width,
                                                         rel=1e-12, abs=0)
    assert zone_gap({}, SIGMA) == SIGMA


def test_the_edge_ratio_sums_the_meniscus_step_and_grows_with_the_spacing():
    """At p/psat 0.05 the meniscus edge (0.36 nm) sits inside the LJ zone: a node at the
    contact edge meets LJ's softening (1.80e18 Pa/m) plus the step's secant (2.07e18), and
    the ratio is their sum over K_kk: 2.15x the p/psat 0.95 ratio (LJ alone; measured 0.512
    and 0.238 at 6 nm). K_kk ~ E*/h: halving the spacing halves the ratio (measured 0.512 ->
    0.255 from 6 to 3 nm, 0.4 % off)."""
    dry, wet = corner(0.05), corner(0.95)
    r_dry, r_wet = (plan.edge_trapping_ratio(band_problem(s, 6e-9)) for s in (dry, wet))
    lj, cap = dry.effects["lj"], dry.effects["capillary"]
    ratio = (cap.edge_softening(SIGMA) - lj.dpressure(np.array([SIGMA]))[0]) / \
        (-lj.dpressure(np.array([SIGMA]))[0])
    assert r_dry / r_wet == pytest.approx(ratio, rel=1e-3, abs=0)      # 2.147
    half = plan.edge_trapping_ratio(band_problem(dry, 3e-9))
    assert half / r_dry == pytest.approx(0.5, rel=0.02, abs=0)


def test_the_coarsest_member_of_a_follow_band_sits_at_the_edge_limit():
    """follow_safe_spacing caps the fine member so that its coarsest estimate member (twice
    the spacing) meets EDGE_SAFE: measured on that member, 0.300 (the ratio's log part
    moves it by < 1 %)."""
    sc = corner(0.05)
    h = plan.follow_safe_spacing(band_problem(sc, 6e-9))
    assert 1.5e-9 < h < 2.0e-9                                        # 1.76 nm
    coarsest = band_problem(sc, h * plan.MIN_MEMBER_RATIO**2)
    assert plan.edge_trapping_ratio(coarsest) == pytest.approx(plan.EDGE_SAFE, rel=0.02,
                                                               abs=0)


def test_the_adaptive_plan_follows_the_edge_only_where_the_static_band_is_too_big():
    """The sigma = 0.3 nm corner (static member capped at 3.7 nm over 5.6 um: ~1800 nodes)
    gets a follow trial at its follow-safe spacing, of a few hundred nodes at most as it
    starts; the bundled Fig 4 scene (static member 285 nodes) stays static."""
    from femadh.discretisation import plan_grid

    sc = corner(0.05)
    p = plan_grid(sc.effects, SIGMA, sc.sphere, sc.analysis_radius, sc.d_values, 1e-3)
    tr = adaptive._follow_trial(sc, p.family, p.spacing)
    assert tr is not None and tr.follow == pytest.approx(
        adaptive.FOLLOW_HALF_SPACINGS * tr.spacing, rel=1e-12, abs=0)
    assert tr.family.grading == pytest.approx(adaptive.FOLLOW_GRADING_SPACINGS * tr.spacing,
                                              rel=1e-12, abs=0)
    assert p.family.count(0.98 * 3.7e-9) > adaptive.FOLLOW_NODES
    assert tr.spacing < 2.0e-9 and tr.nodes < 200
    fig4 = femadh.load_scene("validation/scenes/paper1_fig4.toml")
    q = plan_grid(fig4.effects, fig4.gap.sigma, fig4.sphere, fig4.analysis_radius,
                  fig4.d_values, 1e-3)
    assert adaptive._follow_trial(fig4, q.family, q.spacing) is None
    # nor when the accuracy's refinement takes its static band past FOLLOW_NODES (Fig 4 at
    # 1e-4 refines to ~1090 nodes): the trapping cap alone decides
    fine = q.spacing * 0.15
    assert q.family.count(fine) > adaptive.FOLLOW_NODES
    assert adaptive._follow_trial(fig4, q.family, fine) is None


def test_the_band_leads_the_edges_travel():
    """The travel-aware exchange on a rigid sphere (gap b(r) = d + r^2 / 2R, edges at
    sqrt(2 R (g - d))): the first state (direction unknown) keeps a band that holds it; once
    the edge moves, the band is rebuilt to cover LEAD_STEPS grid steps of the travel ahead
    and is kept while NEED_STEPS of it fit; a landing starts the track afresh."""
    sc = corner(0.95)
    R, step, half, h = sc.sphere.radius, 0.2e-9, 40e-9, 2e-9

    def build(g, first):
        return build_problem(sc, operator=GreenOperator(g, sc.e_star))
    band = EdgeBand(1.4142e-5, h, half, 8 * h, build, edge_gap=0.5e-9, inner_gap=SIGMA,
                    step=step)

    def edges(d):
        return [math.sqrt(2 * R * (g - d)) for g in (SIGMA, 0.5e-9)]
    d0 = -1e-9
    lo, hi = edges(d0)
    pb = band.problem(lo, hi)
    w = np.zeros(pb.grid.n)
    assert band.regrid(pb, w, d0) is None                   # it holds the edges
    d1 = d0 - step                                          # approach: the edge moves out
    new = band.regrid(pb, np.zeros(pb.grid.n), d1)
    lo1, hi1 = edges(d1)
    move = lo1 - lo
    assert move > 2 * half                                  # 169 nm per grid step
    span = band.spans[id(new)]
    assert span[0] == pytest.approx(lo1, rel=0, abs=h)
    # (the band reads both edges on the grid the states were solved on, between its nodes)
    (_, h0), (_, h1) = (band.edges(pb, np.zeros(pb.grid.n), x) for x in (d0, d1))
    assert h1 - h0 == pytest.approx(edges(d1)[1] - hi, rel=0.05, abs=0)
    assert span[1] == pytest.approx(h1 + moving.LEAD_STEPS * (h1 - h0), rel=1e-12, abs=0)
    r = new.grid.nodes
    fine = (r > span[0] - 0.5 * half) & (r < span[1] + 0.5 * half)
    assert np.allclose(np.diff(r[fine]), h, rtol=1e-6, atol=0)
    # one more step fits in the lead (NEED_STEPS < LEAD_STEPS): kept
    assert band.regrid(new, np.zeros(new.grid.n), d1 - step) is None
    # a landing: no travel read across the jump; its direction unknown, the band covers the
    # last travel's size both ways (here 158 nm: beyond the lead behind the edge, rebuilt)
    m = max(abs(x) for x in band.move)
    e2 = band.edges(new, np.zeros(new.grid.n), d1 - 2 * step)
    again = band.regrid(new, np.zeros(new.grid.n), d1 - 2 * step, landed=True)
    assert band.track is None and again is not None
    assert band.spans[id(again)] == pytest.approx(
        (e2[0] - moving.LEAD_STEPS * m, e2[1] + moving.LEAD_STEPS * m), rel=1e-12, abs=0)


@pytest.fixture(scope="module")
def small_sweep(tmp_path_factory):
    """A 0.1-mm sphere at the stiction map's driest sigma = 0.3 nm point (p/psat 0.05:
    the meniscus edge inside the LJ zone) through its jump-in, on a band of 1.76 nm (the
    follow-safe spacing) that follows the edge: measured 1.5-5.7 s (load 2-12)."""
    sc = corner(0.05, **{"sphere.radius": "0.1 mm", "sweep.start": "1.2 nm",
                         "sweep.stop": "-0.6 nm", "sweep.step": "0.2 nm",
                         "sweep.directions": ["approach"]})
    grid = {"spacing": 1.76e-9, "band": 0.8e-6, "grading": 1.4e-8, "follow": 4.2e-8}
    out = tmp_path_factory.mktemp("edgefollow") / "run"
    res = run(variant(sc, grid=grid, radius=3e-6), out, figures=False, progress=False,
              estimate="peak")
    return sc, grid, res, out


def test_the_fine_band_stays_on_the_edge_through_the_jump_in(small_sweep):
    """Through the jump-in fold (the contact appears 0.4 um out and grows to 0.9 um) the grid
    is exchanged as the edge travels; every committed contact state has its edge node, its
    neighbours and the whole cohesive zone out to zone_gap at the band's own spacing (read
    back from fields.csv: each state on its own grid); the largest grid holds fewer nodes
    than half the static band of that spacing over the edge's travel (measured 201 against
    495: the band leads the edge's travel of ~100 nm per grid step)."""
    sc, grid, res, out = small_sweep
    assert res.status == "converged", res.error
    assert [j["branch"] for j in res.jumps] == ["approach"]
    assert res.grid["regrids"] >= 3
    H = grid["spacing"]
    zone = zone_gap(sc.effects, SIGMA)
    in_contact, sizes = 0, set()
    for r, h in fields_by_state(out).values():
        sizes.add(r.size)
        touching = np.flatnonzero(h <= SIGMA * (1 + 1e-9))
        if not touching.size:
            continue
        in_contact += 1
        k = int(touching[-1])
        end = int(np.flatnonzero(h <= zone)[-1]) + 1
        assert np.allclose(np.diff(r[k - 1:end + 1]), H, rtol=1e-6, atol=0)
    assert in_contact >= 4 and len(sizes) >= 2
    static = GridFamily(3e-6, grid["band"], grid["grading"]).count(H)
    assert 2 * max(sizes) < static


def test_the_followed_deepest_state_is_the_static_bands_own(small_sweep):
    """The deepest state of the follow run, carried to the static band [0, 0.8 um] of the same
    spacing and re-solved there: its F_ex and F_LJ agree to 3e-3 and 1e-3 (measured 1.8e-3 and
    3.7e-4 against the static band's own whole sweep: the follow band's graded contact
    interior and far field)."""
    from femadh.contact.forces import state_forces
    from femadh.discretisation.moving import carry_state

    sc, grid, res, out = small_sweep
    s = variant(sc, grid={k: v for k, v in grid.items() if k != "follow"}, radius=3e-6)
    static = build_problem(s)
    # the follow run's deepest state, re-solved on its own last grid (rebuilt from its r)
    rows = []
    with open(out / "fields.csv", newline="") as f:
        for row in csv.DictReader(f):
            rows.append(row)
    deepest = [r for r in rows if r["state"] == rows[-1]["state"]]
    r_nodes = np.array([float(r["r_m"]) for r in deepest])
    w = np.array([float(r["w_m"]) for r in deepest])
    from femadh.elastic import RadialGrid
    from femadh.contact import solve_state
    fgrid = RadialGrid.from_nodes(r_nodes, 3e-6, fine_radius=r_nodes[-1])
    fpb = build_problem(s, operator=GreenOperator(fgrid, s.e_star))
    d = sc.d_values[-1]
    own = solve_state(fpb, d, w, tol=s.tolerance, max_iter=s.max_iter,
                      active0=fpb.contour(d) - w <= SIGMA * (1 + 1e-9))
    assert own.converged and own.stable
    f_lj, _, f_ex = state_forces(fpb, own)
    st = carry_state(fpb, static, own, tol=s.tolerance, max_iter=s.max_iter)
    assert st.converged and st.stable
    g_lj, _, g_ex = state_forces(static, st)
    assert f_ex == pytest.approx(g_ex, rel=3e-3, abs=0)
    assert f_lj == pytest.approx(g_lj, rel=1e-3, abs=0)


def test_a_failed_landing_falls_back_to_the_static_band_only_where_it_is_affordable():
    """The static band [0, band] at a follow band's spacing: the sigma = 0.3 nm corner's
    (3.78 nm over 12.1 um: 3234 nodes, measured 37 s for the carry alone at load 8) is
    refused, the Fig 4 follow test's (39 nm over 5.9 um, 177 nodes) kept."""
    sc = corner(0.95)

    def build(g, first):
        return build_problem(sc, operator=GreenOperator(g, sc.e_star))
    fine = EdgeBand(1.4142e-5, 3.78e-9, 9e-8, 3e-8, build, 0.5e-9, SIGMA, step=0.2e-9)
    assert GridFamily(1.4142e-5, 12.1e-6, 3e-8).count(3.78e-9) > moving.WIDEN_MAX_NODES
    assert not fine.widen_affordable(12.1e-6)
    coarse = EdgeBand(2.53e-5, 39e-9, 1e-6, 1e-6, build, 1.5e-9, 0.5e-9, step=0.4e-9)
    assert coarse.widen_affordable(5.9e-6)
