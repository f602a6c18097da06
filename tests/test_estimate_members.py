"""The estimate's coarser members solved only where the headline numbers are read
(femadh.runner.members), the members placed by the contact edge for the forces at the deepest
separation, Richardson over uneven ratios, and the FE-mesh Richardson through the shared
function."""
import copy
import math
from types import SimpleNamespace
import warnings

import numpy as np
import pytest

import femadh
from conftest import fig4_banded
from femadh.errors import MeshResolutionWarning
from femadh.estimate.richardson import (ENVELOPE_ORDER, MAX_ORDER, ORDER, discretisation,
                                        observed_order, observed_order_uneven)
from femadh.runner import estimates, members
from femadh.scene import scene_from_dict

SCENES = "validation/scenes"


def _run(scene, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshResolutionWarning)
        return femadh.run(scene, progress=False, figures=False, **kw)


def _fig4_short():
    """The Fig 4 slider on an explicit banded grid (30 nm in a 5.9-um band, a = 12.6 um),
    swept 1.6 -> 0.6 nm and back: its jump-in (1.11 nm), its largest adhesion (0.86 nm) and
    its pull-off (1.18 nm) in 12 states."""
    return fig4_banded("1.6 nm", "0.6 nm")


@pytest.fixture(scope="module")
def fig4_both():
    """The short Fig 4 run with reduced members and with members traced whole (the members
    placed by the deepest contact edge off in both: the two ways of solving the same
    members are compared); "deferred": the reduced run's estimate made again on a copy of
    its result as an adaptive trial's whose request (1e-12) it misses
    (:func:`femadh.runner.estimates.estimate_errors`, ``defer``: the sweep is not traced
    twice), "met" as one whose request (1.0) it meets, "unrested" a second copy of
    "deferred"."""
    import copy

    sc = _fig4_short()
    out = {}
    estimate = estimates.estimate_errors

    def twice(scene, res, *a, **kw):
        twins = {name: copy.deepcopy(res) for name in ("deferred", "met", "unrested")}
        done = estimate(scene, res, *a, **kw)
        if estimates.REDUCED_MEMBERS:
            for name, defer in (("met", 1.0), ("unrested", 1e-12), ("deferred", 1e-12)):
                twin = twins[name]
                twin.estimates = estimate(scene, twin, *a, **{**kw, "defer": defer})
                out[name] = twin
        return done
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(estimates, "deepest_locked", lambda *a, **k: None)
        mp.setattr(estimates, "estimate_errors", twice)
        for reduced in (True, False):
            mp.setattr(estimates, "REDUCED_MEMBERS", reduced)
            out[reduced] = _run(sc)
    # the run's life after its estimate, as the copy's
    for name in ("deferred", "met", "unrested"):
        out[name].status = out[True].status
    return out


#: the numbers femadh.runner.estimates.judged_errors judges a trial by (and where the peak is)
JUDGED = ("max_adhesion_N", "F_ex_deepest_N", "F_LJ_deepest_N", "d_at_max_adhesion_m")


def _record(res):
    """Everything the estimate writes into a result, in its order (dicts as item lists)."""
    return (list(res.headline.items()), list(res.estimates.items()), list(res.grid.items()),
            list(res.warnings), res.status)


def test_a_deferred_estimate_completed_is_the_whole_estimate_bit_for_bit(fig4_both):
    """An adaptive trial's estimate in two parts: deferred, the judged numbers' breakdown is
    already the whole estimate's (==, every part) and the members solved the deepest state
    and the peak only (4 and 4 solves where the whole estimate took 18 and 20: the folds'
    walks and landings and the zero-force radii are the rest); completed
    (:func:`femadh.runner.estimates.complete_estimate`, for the trial the loop keeps):
    headline, breakdown, grid record and warnings equal to the whole estimate's, in the
    same order, every float to the bit (the members' judged parts were solved before the
    first member's rest: the order changes no bit)."""
    whole, deferred = fig4_both[True], fig4_both["deferred"]
    assert whole.status == deferred.status == "converged"
    assert getattr(whole, "pending_estimate", None) is None
    assert deferred.pending_estimate is not None
    for q in JUDGED:
        assert deferred.estimates[q] == whole.estimates[q], q
        assert deferred.headline[f"{q}_error"] == whole.headline[f"{q}_error"], q
    # the folds' members are the rest: the partial breakdown has no grid part for them
    assert "grid" in whole.estimates["jump_out_d_m"]
    assert "grid" not in deferred.estimates.get("jump_out_d_m", {})
    part = [m["solves"] for m in deferred.grid["member_solves"]]
    full = [m["solves"] for m in whole.grid["member_solves"]]
    assert len(full) == 2 and all(p < f for p, f in zip(part, full)), (part, full)
    estimates.complete_estimate(deferred)
    assert deferred.pending_estimate is None
    # (the one difference: the record that the loop judged it on the partial breakdown)
    assert deferred.grid.pop("judged_deferred") is True
    assert _record(deferred) == _record(whole)
    estimates.complete_estimate(deferred)          # nothing left: the result stays
    assert _record(deferred) == _record(whole)


def test_a_deferred_estimate_that_meets_its_request_is_whole_at_once(fig4_both):
    """The judged numbers' breakdown meets the request (1.0): the rest is solved at once,
    nothing is left pending, and the estimate is the whole one (hysteresis and zero-force
    radii included), record for record and bit for bit."""
    met, whole = fig4_both["met"], fig4_both[True]
    assert getattr(met, "pending_estimate", None) is None
    assert "grid" in met.estimates["hysteresis_J"]
    assert _record(met) == _record(whole)


def test_a_members_rest_that_fails_traces_the_member_whole(fig4_both, monkeypatch):
    """A reduced member whose rest cannot be solved (a FemadhError in
    :meth:`~femadh.runner.members.ReducedMember.rest`) when the deferred estimate is
    completed: the member is traced whole, as :func:`estimate_errors` without ``defer``
    does - the breakdown equals the one of members traced whole (the rest never falls back
    on the member's judged numbers: its folds and radii would be missing or the fine run's)."""
    from femadh.errors import ConvergenceError

    def rest(self):
        raise ConvergenceError("no rest here")

    def failing(self):
        try:
            rest(self)
        except ConvergenceError as exc:
            return None, str(exc)
    unrested, traced = fig4_both["unrested"], fig4_both[False]
    monkeypatch.setattr(members.ReducedMember, "rest", failing)
    estimates.complete_estimate(unrested)
    assert [m["reduced"] for m in unrested.grid["member_solves"]] == [False, False]
    assert [m["why"] for m in unrested.grid["member_solves"]] == ["no rest here"] * 2
    assert list(unrested.estimates.items()) == list(traced.estimates.items())


def test_reduced_members_give_the_whole_trace_estimate(fig4_both):
    red, whole = fig4_both[True], fig4_both[False]
    assert red.status == whole.status == "converged"
    assert [m["reduced"] for m in red.grid["member_solves"]] == [True, True]
    assert [m["reduced"] for m in whole.grid["member_solves"]] == [False, False]
    assert len(red.jumps) == 2
    g = {k: (red.estimates[k]["grid"], whole.estimates[k]["grid"])
         for k in whole.estimates if "grid" in whole.estimates[k]}
    assert set(g) >= {"max_adhesion_N", "F_LJ_deepest_N", "F_ex_deepest_N", "jump_in_d_m",
                      "jump_out_d_m", "hysteresis_J"}
    # the folds: the same lattice point of the same grid step - equal to the round-off of
    # the separations (the two searches reach the lattice point by different sums: measured
    # 3 ulps of the fold's d; a lattice step is 2^-10 of a grid step, ~1e9 ulps), their
    # energy to round-off (measured 1e-12 relative)
    for k in ("jump_in_d_m", "jump_out_d_m"):
        assert abs(g[k][0] - g[k][1]) <= 16 * np.spacing(abs(red.headline[k])), k
    assert g["hysteresis_J"][0] == pytest.approx(g["hysteresis_J"][1], rel=1e-9, abs=0)
    # one state at the deepest separation: the same equilibrium to the solver tolerance
    # (measured 1e-11 of the force)
    for k in ("F_LJ_deepest_N", "F_ex_deepest_N"):
        assert abs(g[k][0] - g[k][1]) <= 1e-9 * abs(red.headline[k]), k
    # the peak searched within an eighth of a grid step of the fine run's: its optimum to
    # the search's tolerance (measured 2.9e-6 of the force, 1e-3 of the grid part)
    assert abs(g["max_adhesion_N"][0] - g["max_adhesion_N"][1]) <= \
        1e-5 * red.headline["max_adhesion_N"]


def test_reduced_members_solve_a_fraction_of_the_whole_trace(fig4_both):
    """A member solves the deepest state, the peak's neighbourhood, each fold's lattice and
    the zero-force interval: ~20 corrector solves here (measured 18, 19), where tracing it
    whole takes its 12 states' steps and halves each fold's step ten times (~60)."""
    solves = [m["solves"] for m in fig4_both[True].grid["member_solves"]]
    assert all(s <= 30 for s in solves), solves


def test_uniform_grids_keep_their_members_traced_whole():
    base = femadh.load_scene(f"{SCENES}/paper1_fig3.toml")
    res = _run(estimates.variant(base, nodes=60))
    assert res.status == "converged"
    assert [m["reduced"] for m in res.grid["member_solves"]] == [False, False]
    assert "uniform grid" in res.grid["member_solves"][0]["why"]


def _f_lj_on(ref, fine, st, sc):
    """F_LJ (N) of the state ``st`` of problem ``fine`` carried to the finer problem ``ref``
    and solved there (one Newton solve from the interpolated state)."""
    from femadh.contact.complementarity import solve_complementarity
    from femadh.contact.forces import state_forces
    from femadh.discretisation.moving import interpolate_state

    w0, act = interpolate_state(fine, ref, st.d, st.w)
    sr = solve_complementarity(ref, st.d, w0, tol=sc.tolerance, max_iter=sc.max_iter,
                               active0=act)
    assert sr.converged and sr.stable
    return state_forces(ref, sr)[0]


def test_locked_deepest_estimate_effectivity_against_a_fine_reference():
    """The Fig 3 scene at accuracy 1e-2 (58 nodes, band spacing 137 nm): the grid part of
    F_LJ at the deepest separation against the same family's state at a sixteenth of the
    spacing (one Newton solve from the fine state). Measured: estimate -2.82e-7 N (the
    finest difference bounded by the coarser at DECAY_ORDER; -2.14e-7 read from it alone),
    error -8.4e-8 N, effectivity 3.36 (2.55); the family's own members (193, 273 nm: across
    the edge's node-crossing sawtooth) gave 7.2e-3 relative, effectivity 24."""
    from femadh.contact import trace
    from femadh.contact.forces import state_forces
    from femadh.scene import build_problem

    base = femadh.load_scene(f"{SCENES}/paper1_fig3.toml")
    raw = copy.deepcopy(base.raw)
    raw["solver"]["accuracy"] = 1e-2
    res = _run(scene_from_dict(raw, base.path, bare_numbers=False))
    assert res.status == "converged" and "deepest_member_spacings_m" in res.grid
    g = res.grid

    def member(h):
        sc = estimates.variant(base, grid={"spacing": h, "band": g["band_m"],
                                           "grading": g["grading_m"]},
                               radius=g["analysis_radius_m"])
        return sc, build_problem(sc)
    sc, fine = member(g["spacing_m"])
    st = trace(fine, sc.d_values, branch="approach", tol=sc.tolerance,
               max_iter=sc.max_iter).states[-1]
    assert state_forces(fine, st)[0] == pytest.approx(res.headline["F_LJ_deepest_N"],
                                                      rel=1e-9, abs=0)
    _, ref = member(g["spacing_m"] / 16)
    true = _f_lj_on(ref, fine, st, sc) - res.headline["F_LJ_deepest_N"]
    est = res.estimates["F_LJ_deepest_N"]["grid"]
    # the grid part is the uneven Richardson of the placed members at their own ratios
    (h1, h2), (lv1, lv2) = g["deepest_member_spacings_m"], g["deepest_members"]
    decay = estimates.decay_order(fine, h2 / g["spacing_m"])
    assert decay == estimates.DECAY_ORDER       # a sigma-gap, trapping-safe members
    assert est == discretisation(
        {"F_LJ_deepest_N": res.headline["F_LJ_deepest_N"]}, lv1, lv2,
        ratio=h1 / g["spacing_m"], ratio2=h2 / h1, decay_order=decay)["F_LJ_deepest_N"]
    assert est * true > 0                       # the side the error is on
    assert 0.5 <= est / true <= 5.0, est / true


def test_locked_spacings_put_the_edge_at_the_fine_grids_fraction_of_a_spacing():
    grid = SimpleNamespace(nodes=np.arange(0, 200) * 40e-9)
    problem = SimpleNamespace(grid=grid)
    r_e = 3.5512e-6
    hs = members.locked_spacings(problem, r_e, 7e-6, math.sqrt(2))
    frac = (r_e / 40e-9) % 1
    assert len(hs) == 2
    for k, h in enumerate(hs, start=1):
        assert (r_e / h) % 1 == pytest.approx(frac, abs=1e-9)
        # near the family's ratio (the nearest whole count of spacings to the edge)
        assert h / 40e-9 == pytest.approx(math.sqrt(2) ** k, rel=0.05)
    # an edge too close to the centre for MIN_EDGE_SPACINGS: no placed members
    assert members.locked_spacings(problem, 15 * 40e-9, 7e-6, math.sqrt(2)) is None
    # an edge beyond the band's uniform part: none
    assert members.locked_spacings(problem, 6.99e-6, 7e-6, math.sqrt(2)) is None


def test_contact_edge_between_nodes_from_a_three_halves_gap():
    h, sigma, r_e, d = 40e-9, 1e-9, 3.5512e-6, -5e-9
    r = np.arange(0, 150) * h
    b = d + r**2 / 4e-3
    gap = sigma + np.where(r > r_e, 2e2 * np.clip(r - r_e, 0, None) ** 1.5, 0.0)
    problem = SimpleNamespace(sigma=sigma, grid=SimpleNamespace(nodes=r),
                              contour=lambda dd: b + (dd - d))
    snap = SimpleNamespace(d=d, w=b - gap, active=r <= r_e)
    assert members.contact_edge(problem, snap) == pytest.approx(r_e, rel=1e-12, abs=0)
    assert members.contact_edge(problem, SimpleNamespace(d=d, w=b - sigma - 1e-9,
                                                         active=np.zeros(r.size, bool))) \
        is None


@pytest.mark.parametrize("r1, r2, p", [(1.3, 1.5, 1.2), (1.5, 1.35, 1.4), (1.4, 1.45, 2.0)])
def test_uneven_richardson_recovers_a_known_order(r1, r2, p):
    q = {h: 2.0 + 0.3 * h**p for h in (1.0, r1, r1 * r2)}
    fine, coarse, coarser = q[1.0], q[r1], q[r1 * r2]
    assert observed_order_uneven(fine, coarse, coarser, r1, r2) == pytest.approx(p, rel=1e-9)
    est = discretisation({"x": fine}, {"x": coarse}, {"x": coarser}, ratio=r1, ratio2=r2)["x"]
    exact = 2.0 - fine
    used = min(MAX_ORDER, max(ORDER, p))
    assert est == pytest.approx((fine - coarse) / (r1**used - 1), rel=1e-9, abs=0)
    if p <= MAX_ORDER:
        assert est == pytest.approx(exact, rel=1e-6, abs=0)
    # equal ratios: the even formula's order
    assert observed_order_uneven(fine, q[r1], 2.0 + 0.3 * (r1 * r1)**p, r1, r1) == \
        pytest.approx(observed_order(fine, q[r1], 2.0 + 0.3 * (r1 * r1)**p, r1), rel=1e-9)
    # oscillating members: no order
    assert observed_order_uneven(fine, coarse, 2 * coarse - coarser, r1, r2) is None


@pytest.mark.parametrize("r1, r2", [(1.3, 1.5), (1.5, 1.35), (1.414, 1.36)])
def test_uneven_envelope_scales_the_coarser_difference_by_the_model(r1, r2):
    """Oscillating members at uneven ratios: the coarser difference d2 = Q(r1 h) - Q(r1 r2 h)
    enters the envelope as the finest difference it implies under Q = Q* + C h^p,
    d2 (r1^p - 1) / (r1^p (r2^p - 1)). With d2 of the model's size C r1^p (r2^p - 1) (h = 1)
    and a smaller finest difference of the other sign, the estimate is C with the finest
    difference's sign (exact to round-off; 1/r2^p in place of the factor was 0.91-1.08x)."""
    p, C = ENVELOPE_ORDER, 0.3
    fine = 2.0 + C
    coarse = fine + 0.1 * C                          # d1 = -0.1 C
    coarser = coarse - C * r1**p * (r2**p - 1)       # d2 = +C r1^p (r2^p - 1): oscillating
    assert observed_order_uneven(fine, coarse, coarser, r1, r2) is None
    est = discretisation({"x": fine}, {"x": coarse}, {"x": coarser}, ratio=r1, ratio2=r2)["x"]
    assert est == pytest.approx(-C, rel=1e-12, abs=0)


def test_fe_mesh_richardson_is_the_shared_function():
    """The layered FE mesh part (Q_h - Q_coarse) / (r^3 - 1), as the runner wrote it by hand,
    from estimate/richardson.discretisation; the homogeneous one, the Green function's
    difference; non-finite numbers left out."""
    fine = {"a": 1.25e-4, "b": -3.0e-9, "c": math.nan, "d": 7.0}
    coarse = {"a": 1.27e-4, "b": -2.9e-9, "c": 1.0, "e": 2.0}
    r = 1.43
    got = discretisation(fine, coarse, ratio=r, order=estimates.FE_ORDER)
    assert set(got) == {"a", "b"}
    for k in got:
        assert got[k] == (fine[k] - coarse[k]) / (r**estimates.FE_ORDER - 1)
    green = estimates.fe_against_green(fine, coarse)
    assert green == {"a": coarse["a"] - fine["a"], "b": coarse["b"] - fine["b"]}


def _slider_uniform(nodes):
    """The slider meniscus scene on an explicit uniform grid, swept 1 -> -5 nm in 0.5 nm
    (its deepest state: the contact edge at 3.7 um, F_LJ there 2.97e-4 N)."""
    base = femadh.load_scene(f"{SCENES}/paper1_slider_meniscus.toml")
    raw = copy.deepcopy(base.raw)
    raw["solver"].pop("accuracy", None)
    raw["solver"]["nodes"] = nodes
    raw["sweep"].update(start="1 nm", stop="-5 nm", step="0.5 nm")
    return scene_from_dict(raw, base.path, bare_numbers=False)


def test_uniform_grid_gets_members_placed_by_the_deepest_edge():
    """A uniform grid's F_LJ at the deepest separation: its N/2 and N/4 members put the
    contact edge at other fractions of a spacing (the slider scene's N = 100, 200, 400 err
    +1.6e-3, -4.0e-4, -2.6e-5 there: a sawtooth, not a convergence), so its grid part comes
    from members uniform to the analysis radius at the spacings that keep the fine grid's
    fraction. Against N = 1600 on the same disk (one Newton solve from the fine state; its
    own error ~5e-6 of the force, from N = 800's 1.7e-5 at order 2): measured grid part
    -1.84e-8 N against an error of -9.56e-9 N, effectivity 1.92; the N/2, N/4 members gave
    -1.16e-7 N (effectivity 12.1)."""
    from femadh.scene import build_problem

    sc = _slider_uniform(400)
    got = {}
    orig = estimates.deepest_locked

    def keep(scene, problem, sink, *a, **k):
        got.update(problem=problem, state=sink.committed["approach"][-1])
        got["locked"] = orig(scene, problem, sink, *a, **k)
        return got["locked"]
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(estimates, "deepest_locked", keep)
        res = _run(sc)
    assert res.status == "converged"
    assert res.grid["kind"] == "uniform" and res.grid.get("deepest_members_placed")
    # the uniform grid's record stays the scene's (no state-dependent spacings in it)
    assert "deepest_member_spacings_m" not in res.grid
    h = float(got["problem"].grid.nodes[1])
    assert got["locked"][0][0] == pytest.approx(2 * h, rel=0.02, abs=0)
    fine, st = got["problem"], got["state"]
    ref = build_problem(estimates.variant(sc, nodes=1600))
    true = _f_lj_on(ref, fine, st, sc) - res.headline["F_LJ_deepest_N"]
    est = res.estimates["F_LJ_deepest_N"]["grid"]
    assert est * true > 0                       # the side the error is on
    assert 0.5 <= est / true <= 5.0, (est, true)

