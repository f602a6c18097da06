"""The adaptive run and accuracy mode on the shared refine-until-met loop, and the failure
kind that picks their refinement (``result.failure_kind``, by the exception's type, never by
a message's words).

The loops are driven by a scripted ``run``: each trial's result (status, failure kind,
estimate) is given, and what the loop asks next (spacing, band, analysis radius, nodes) is
read off the trials it runs. The real runs at the end check that a guard's refusal reaches
the result with its kind."""
import math

import numpy as np
import pytest

import femadh
from conftest import adaptive_scene
from femadh.discretisation import family as family_mod
from femadh.errors import ConvergenceError, Interrupted, MeshResolutionWarning, TimeLimitReached
from femadh.estimate import (AnalysisRadiusError, BoundError, GuardError, TrappingError,
                             check_state, failure_kind)
from femadh.runner import accuracy, adaptive, estimates
from femadh.runner.result import ContactResult

FIG3 = "validation/scenes/paper1_fig3.toml"



def scripted(script):
    """A ``run`` that answers the k-th trial with ``script[k]`` (a dict: status, kind, error
    text, relative grid and tail errors, members, contact edge) and records each trial's
    discretisation: (band spacing, band, analysis radius, follow) of a banded trial, (nodes,
    analysis radius) of a uniform one."""
    seen = []

    def run(trial, out_dir, **kw):
        g = trial.grid
        seen.append((g["spacing"], g["band"], trial.analysis_radius, g.get("follow"))
                    if g else (trial.nodes, trial.analysis_radius))
        s = script[min(len(seen) - 1, len(script) - 1)]
        res = ContactResult(trial.name, trial, status=s.get("status", "converged"),
                            error=s.get("error"))
        res.failure_kind = s.get("kind")
        res.timings["total_s"] = 0.01
        res.branches = {"approach": {"r_c_m": np.array([s.get("edge", 0.0)])}}
        res.grid = {"members": [] if s.get("members_failed") else ["r h", "r^2 h"]}
        if res.status == "converged":
            F = 1e-5
            res.headline = {"max_adhesion_N": F, "F_ex_deepest_N": F, "F_LJ_deepest_N": F}
            res.estimates = {"max_adhesion_N": {
                "total": (s.get("grid", 0.0) + s.get("tail", 0.0)) * F,
                "tail": s.get("tail", 0.0) * F}}
        return res
    return run, seen


def test_the_failure_kind_not_its_words_picks_the_remedy():
    """A contact at the analysis radius (kind "analysis_radius", its text saying nothing of
    it) doubles the disk at the same spacing; a stalled landing whose text happens to name
    the analysis radius (kind "convergence") and a node snapping alone (kind "trapping")
    each halve the spacing at the same disk; the fourth trial meets the target (estimate
    0.5 of it): converged, four steps, each failure's kind recorded."""
    sc = adaptive_scene(accuracy=1e-2)
    run, seen = scripted([
        {"status": "failed", "kind": "analysis_radius", "error": "guard at d = -3 nm"},
        {"status": "failed", "kind": "convergence",
         "error": "landing after the fold near the analysis radius: Newton 200 iterations"},
        {"status": "failed", "kind": "trapping", "error": "lattice trapping"},
        {"grid": 5e-3}])
    res = adaptive.run_adaptive(sc, None, run=run)
    assert res.status == "converged" and res.accuracy["met"], res.error
    (h0, b0, a0, _), (h1, b1, a1, _), (h2, b2, a2, _), (h3, b3, a3, _) = seen
    assert (a1, h1, b1) == (2 * a0, h0, b0)
    assert (a2, h2) == (a1, 0.5 * h1) and (a3, h3) == (a2, 0.5 * h2)
    steps = res.accuracy["steps"]
    assert [s.get("refined_for") for s in steps] == ["analysis_radius", "convergence",
                                                     "trapping", None]
    assert steps[-1]["grid_rel_error"] == pytest.approx(5e-3, rel=1e-12, abs=0)


def test_members_failed_refine_and_a_last_run_without_them_is_not_judged():
    """No coarser member converged: the grid error is unknown, the spacing shrinks by
    MAX_FACTOR (never reported met); after MAX_TRIALS runs so, the run fails 'not judged'
    with the accuracy kind, its last run's nodes and spacing named."""
    sc = adaptive_scene(accuracy=1e-2)
    run, seen = scripted([{"grid": 1e-4, "members_failed": True}])
    res = adaptive.run_adaptive(sc, None, run=run)
    assert len(seen) == adaptive.MAX_TRIALS
    for (h, *_), (h_next, *_) in zip(seen, seen[1:]):
        assert h_next == pytest.approx(adaptive.MAX_FACTOR * h, rel=1e-12, abs=0)
    assert res.status == "failed" and res.failure_kind == "accuracy"
    assert "not judged" in res.error and f"{res.accuracy['nodes']} nodes" in res.error
    assert not res.accuracy["met"]


def test_a_budget_spent_names_the_accuracy_reached_the_nodes_the_time_and_the_need():
    """An estimate that stays at 1.5x the target: each refinement takes the factor
    (s / 1.5)^(1/p), s the aim near the target (AIM^(1/c) 1.5^(-(1-c)/c), c =
    ORDER_SPREAD), p = FIRST_ORDER for the first, then the assumed ORDER (an estimate that
    did not fall shows none);
    MAX_TRIALS runs, then one line naming the accuracy reached,
    the nodes, the runs, the time and about how many nodes the request needs (the family's
    count at the spacing the assumed order gives)."""
    from femadh.discretisation.plan import GRADING_FRACTION

    sc = adaptive_scene(accuracy=1e-2)
    run, seen = scripted([{"grid": 1.5e-2}])
    res = adaptive.run_adaptive(sc, None, run=run)
    assert len(seen) == adaptive.MAX_TRIALS
    c = adaptive.ORDER_SPREAD
    aim = adaptive.AIM ** (1 / c) * 1.5 ** (-(1 - c) / c) / 1.5
    for i, ((h, *_), (h_next, *_)) in enumerate(zip(seen, seen[1:])):
        # the first refinement at FIRST_ORDER (no earlier run), then ORDER (no fall)
        p = adaptive.FIRST_ORDER if i == 0 else adaptive.ORDER
        assert h_next == pytest.approx(aim ** (1 / p) * h, rel=1e-12, abs=0)
    last = res.accuracy["steps"][-1]
    fam = family_mod.GridFamily(last["analysis_radius_m"], last["band_m"],
                                GRADING_FRACTION * last["band_m"])
    need = fam.count(last["spacing_m"] * (1 / 1.5) ** (1 / adaptive.ORDER))
    assert res.status == "failed" and res.failure_kind == "accuracy"
    assert "estimated relative error 0.015" in res.error
    assert f"with {last['nodes']} nodes after {adaptive.MAX_TRIALS} runs" in res.error
    assert f"needs about {need} nodes" in res.error and " s)" in res.error


def test_a_stopped_trial_ends_the_loop():
    """A trial stopped by its time limit (or a signal) is the user's budget, not the
    grid's failure: no further trial, the status kept."""
    for status, kind in (("time limit", "time_limit"), ("interrupted", "interrupted")):
        run, seen = scripted([{"status": status, "kind": kind, "error": status}])
        res = adaptive.run_adaptive(adaptive_scene(accuracy=1e-2), None, run=run)
        assert len(seen) == 1 and res.status == status


def test_a_feature_that_left_the_band_widens_it_and_a_tail_grows_the_disk():
    """A contact edge beyond BAND_FILL of the band widens the band to 1.2 edge / BAND_FILL
    at the same spacing and disk; a tail above SAFETY of the target doubles the disk at the
    same spacing and band."""
    sc = adaptive_scene(accuracy=1e-2)
    run, seen = scripted([{}, {"grid": 1e-3, "tail": 1.2e-2}, {"grid": 1e-3}])
    res = adaptive.run_adaptive(sc, None, run=_edge_first(run, seen))
    assert res.status == "converged", res.error
    (h0, b0, a0, _), (h1, b1, a1, _), (h2, b2, a2, _) = seen
    edge = res.accuracy["steps"][0]["band_left_m"]
    assert edge > adaptive.BAND_FILL * b0
    assert (h1, a1) == (h0, a0) and b1 == pytest.approx(1.2 * edge / adaptive.BAND_FILL,
                                                        rel=1e-12, abs=0)
    assert (h2, b2, a2) == (h1, b1, 2 * a1) and res.accuracy["steps"][1]["tail_grew_radius"]


def _edge_first(run, seen):
    """``run`` whose first trial's contact edge sits at 0.99 of that trial's band."""
    def wrapped(trial, out_dir, **kw):
        res = run(trial, out_dir, **kw)
        if len(seen) == 1:
            res.branches = {"approach": {"r_c_m": np.array([0.99 * trial.grid["band"]])}}
        return res
    return wrapped


def test_a_member_beyond_the_node_limit_ends_the_request_in_one_line(monkeypatch):
    """With the family's node limit at 400, an estimate at 10x the target shrinks h by
    MIN_FACTOR until the next member would exceed it: the run stops there, naming the limit
    and the spacing asked for, the last run's results kept."""
    monkeypatch.setattr(family_mod, "MAX_NODES", 400)
    monkeypatch.setattr(adaptive, "MAX_NODES", 400)
    run, seen = scripted([{"grid": 0.1}])
    res = adaptive.run_adaptive(adaptive_scene(accuracy=1e-2), None, run=run)
    assert 1 <= len(seen) < adaptive.MAX_TRIALS
    assert res.status == "failed" and res.failure_kind == "accuracy"
    asked = seen[-1][0] * adaptive.MIN_FACTOR
    assert f"more than 400 nodes (band spacing {asked * 1e9:.3g} nm" in res.error
    assert all(s["nodes"] <= 400 for s in res.accuracy["steps"])


def test_a_tail_that_falls_short_names_the_analysis_radius_not_a_node_count(monkeypatch):
    """The force beyond the disk stays above SAFETY of the target through every run (it falls
    as a^-2 while each run doubles the disk): the budget of runs ends the request, and the
    line names the tail and the analysis radius it needs - from the tail's observed decay
    over the last doubling, a_last (t_last / (SAFETY target))^(1/2) - never a node count (a
    finer spacing would not help). With one run only there is no decay to read: "a larger
    analysis radius"."""
    sc = adaptive_scene(accuracy=1e-2)
    script = [{"grid": 1e-3, "tail": 4.0 * 4.0**-k} for k in range(adaptive.MAX_TRIALS)]
    run, seen = scripted(script)
    res = adaptive.run_adaptive(sc, None, run=run)
    assert len(seen) == adaptive.MAX_TRIALS
    for (h, b, a, _), (h_next, b_next, a_next, _) in zip(seen, seen[1:]):
        assert (h_next, b_next, a_next) == (h, b, 2 * a)
    last, t_last = res.accuracy["steps"][-1], script[-1]["tail"]
    assert res.status == "failed" and res.failure_kind == "accuracy"
    a_need = last["analysis_radius_m"] * (t_last / (adaptive.SAFETY * 1e-2)) ** 0.5
    assert f"{t_last:.2g} of it the force beyond the analysis radius " \
        f"{last['analysis_radius_m'] * 1e6:.4g} um" in res.error
    assert f"needs an analysis radius of about {a_need * 1e6:.3g} um" in res.error
    assert "a^-2 " in res.error and "needs about" not in res.error, res.error
    monkeypatch.setattr(adaptive, "MAX_TRIALS", 1)
    run, seen = scripted(script)
    res = adaptive.run_adaptive(sc, None, run=run)
    assert len(seen) == 1 and "needs a larger analysis radius" in res.error, res.error


def test_only_the_node_budget_reads_as_too_many_nodes(monkeypatch):
    """A ValueError of a member other than the node budget's (here from its problem's
    trapping-safe spacing) keeps its own words - the step and the value - instead of
    reading "the grid would need more than 4000 nodes"."""
    def broken(problem):
        raise ValueError("law 'lj': stiffness at gap step 3 is nan")
    monkeypatch.setattr(adaptive, "safe_spacing", broken)
    run, seen = scripted([{"grid": 1e-3}])
    with pytest.raises(ValueError, match="stiffness at gap step 3 is nan"):
        adaptive.run_adaptive(adaptive_scene(accuracy=1e-2), None, run=run)
    assert seen == []


def test_accuracy_mode_refines_by_the_failure_kind():
    """Uniform accuracy mode: "analysis_radius" doubles N and quadruples delta (the disk
    doubles, the spacing stays); "trapping" and "bound" double N; a stalled continuation
    ("convergence") is no grid's failure: the request ends with the run's own error."""
    sc = femadh.load_scene(FIG3).replace({"solver.nodes": 100, "solver.accuracy": 1e-2})
    delta0 = sc.analysis_radius**2 / (2 * sc.sphere.radius)
    run, seen = scripted([
        {"status": "failed", "kind": "analysis_radius", "error": "x"},
        {"status": "failed", "kind": "trapping", "error": "y"},
        {"status": "failed", "kind": "bound", "error": "z"},
        {"status": "failed", "kind": "convergence",
         "error": "stalled at the analysis radius; nodes snap on their own; Derjaguin"}])
    res = accuracy.run_to_accuracy(sc, None, run=run)
    assert [n for n, _ in seen] == [100, 200, 400, 800]
    radii = [a for _, a in seen]
    assert radii[1] == pytest.approx(2 * radii[0], rel=1e-12, abs=0)
    assert radii[1:] == [radii[1]] * 3
    assert res.status == "failed" and res.error.startswith("stalled") and len(seen) == 4
    assert delta0 > 0


def test_failure_kinds_follow_the_exception_types():
    assert [failure_kind(e) for e in (
        AnalysisRadiusError("a"), TrappingError("t", ratio=1.2), BoundError("b"),
        GuardError("g"), ConvergenceError("c"), TimeLimitReached(1.0), Interrupted(2),
        ValueError("v"))] == ["analysis_radius", "trapping", "bound", "guard", "convergence",
                              "time_limit", "interrupted", "error"]


def test_a_real_run_carries_its_guards_kind():
    """The Fig 3 slider pushed to d = -50 nm on the paper's 10-nm disk (uniform nodes): the
    contact fills the disk and check_state refuses it as AnalysisRadiusError; the run's
    result carries the kind (what accuracy mode switches on), summary.json too. A trapped
    grid (sigma = 0.4 nm on 60 nodes) carries "trapping"."""
    sc = femadh.load_scene(FIG3).replace(
        {"sweep.stop": "-50 nm", "sweep.step": "1 nm", "sweep.directions": ["approach"],
         "solver.nodes": 200})
    res = femadh.run(sc, progress=False, estimate=False)
    assert res.status == "failed" and res.failure_kind == "analysis_radius"
    assert res.summary()["failure_kind"] == "analysis_radius"
    trapped = femadh.load_scene(FIG3).replace({"solver.nodes": 60,
                                               "effects.asperity_gap.sigma": "0.4 nm"})
    # the scene's a-priori stiffness warning comes first (60 nodes at sigma = 0.4 nm)
    with pytest.warns(MeshResolutionWarning, match="snap on their own"):
        res = femadh.run(trapped, progress=False, estimate=False)
    assert res.status == "failed" and res.failure_kind == "trapping", res.error


def test_the_bounds_guard_reaches_the_result_as_its_kind(monkeypatch):
    """The Derjaguin-Bradley guard's refusal (runner.estimates.guard_bounds raises a
    BoundError) ends the run with kind "bound": the real guard, its bound test forced."""
    from femadh.runner import estimates

    monkeypatch.setattr(estimates, "outside_bounds", lambda *a, **k: True)
    sc = femadh.load_scene(FIG3).replace({"solver.nodes": 60, "sweep.stop": "-1 nm"})
    res = femadh.run(sc, progress=False, estimate="peak")
    assert res.status == "failed" and res.failure_kind == "bound" and "bound" in res.error


def test_check_state_refuses_the_analysis_radius_as_its_own_type():
    """A contact at 0.95 of the disk (above EDGE_FRACTION = 0.9) is an AnalysisRadiusError,
    a GuardError of kind "analysis_radius"; the guard's words are unchanged."""
    from types import SimpleNamespace

    pb = SimpleNamespace(grid=SimpleNamespace(radius=1e-6), node_softening_ratio=lambda h: 0.0)
    st = SimpleNamespace(r_c=0.95e-6, d=0.0, h=np.ones(3), active=np.zeros(3, bool))
    with pytest.raises(AnalysisRadiusError, match="analysis radius") as e:
        check_state(pb, st)
    assert isinstance(e.value, GuardError) and failure_kind(e.value) == "analysis_radius"


def test_the_follow_switch_hands_each_trial_its_follow_band(monkeypatch):
    """FOLLOW_NODES = 0 (follow always): the trial's [solver.grid] carries follow = FOLLOW_HALF
    of the band, and the operator handed to the run is the follow member as the trace
    starts (centred on r = 0: fewer nodes than the static member of the same spacing, the
    count recorded); the default (None) keeps the static band."""
    from femadh.discretisation.moving import follow_family
    from femadh.discretisation.plan import GRADING_FRACTION

    monkeypatch.setattr(adaptive, "FOLLOW_NODES", 0)
    ops = []
    run, seen = scripted([{"grid": 1e-3}])

    def spy(trial, out_dir, **kw):
        ops.append(kw["operator"].grid.n)
        return run(trial, out_dir, **kw)
    res = adaptive.run_adaptive(adaptive_scene(accuracy=1e-2), None, run=spy)
    (h, band, a, follow), = seen
    assert follow == pytest.approx(adaptive.FOLLOW_HALF * band, rel=1e-12, abs=0)
    step = res.accuracy["steps"][0]
    fam = family_mod.GridFamily(a, band, GRADING_FRACTION * band)
    follow_n = follow_family(a, follow, fam.grading, 0.0).member(h).n
    assert ops == [step["nodes"]] == [follow_n] and follow_n < fam.member(h).n
    monkeypatch.setattr(adaptive, "FOLLOW_NODES", None)
    run, seen = scripted([{"grid": 1e-3}])
    adaptive.run_adaptive(adaptive_scene(accuracy=1e-2), None, run=run)
    assert seen[0][3] is None


def test_an_error_part_that_is_not_finite_is_never_met():
    """A headline number whose estimated error is NaN (a part that could not be estimated):
    the relative error is infinite, so neither accuracy mode nor the adaptive loop calls the
    request met (max() dropped the NaN: (1e-4, 0) was returned, below any target)."""
    from types import SimpleNamespace

    hl = {"max_adhesion_N": 1e-5, "F_ex_deepest_N": -1e-3, "F_LJ_deepest_N": 2e-4}
    good = {"max_adhesion_N": {"total": 1e-9, "tail": 0.0},
            "F_ex_deepest_N": {"total": 1e-9, "tail": 0.0}}
    grid, tail = estimates.judged_errors(SimpleNamespace(headline=hl, estimates=good))
    assert grid == pytest.approx(1e-4, rel=1e-12, abs=0) and tail == 0.0
    for part in ("total", "tail"):
        bad = {**good, "F_LJ_deepest_N": {"total": 1e-9, "tail": 0.0, part: math.nan}}
        assert estimates.judged_errors(SimpleNamespace(headline=hl, estimates=bad)) == \
            (math.inf, math.inf)
