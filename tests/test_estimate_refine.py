"""The refine-until-met loop and the bounds guard of the shared error machinery
(femadh.estimate), on manufactured error models whose answers are known in closed form."""
import math

import pytest

from femadh.estimate import Budget, outside_bounds, refine_until_met, worst_relative


def model(c, p, nodes_per_unit=1.0):
    """An attempt at spacing h: relative error C h^p exactly, nodes 1/h (a 1D family)."""
    calls = []

    def attempt(h):
        calls.append(h)
        return {"h": h, "nodes": nodes_per_unit / h}, c * h**p, None

    def refine(h, result, error, why):
        return h / 2

    def nodes(h, result, nxt):
        return nodes_per_unit / nxt
    return attempt, refine, nodes, calls


@pytest.mark.parametrize("target", [1e-2, 1e-3, 3e-4])
def test_halving_stops_at_the_first_spacing_that_meets_the_target(target):
    """Error 0.5 h^2 from h = 0.2: the loop stops at the first h = 0.2 / 2^k with
    0.5 h^2 <= target, k = ceil(log2(0.2 sqrt(0.5 / target))) (closed form), and reports
    that attempt's error."""
    attempt, refine, nodes, calls = model(0.5, 2.0)
    out = refine_until_met(0.2, attempt, refine, target, Budget(10, 10**6), nodes)
    k = max(0, math.ceil(math.log2(0.2 * math.sqrt(0.5 / target))))
    assert out.met and out.stop == "met"
    assert calls == [0.2 / 2**i for i in range(k + 1)]
    assert out.setting == calls[-1] and out.error == pytest.approx(0.5 * calls[-1]**2,
                                                                   rel=1e-15, abs=0)
    assert out.error <= target < 0.5 * (2 * calls[-1])**2 or k == 0


def test_budget_of_refinements_and_of_nodes_end_the_loop_with_the_reason():
    """Target 1e-6 at error h^2 from h = 0.1 needs h <= 1e-3 (7 halvings): two refinements
    stop at h = 0.025 ("refinements", 3 attempts); a node budget of 50 (nodes 1/h) stops
    before h = 0.0125 would need 80 ("nodes", attempts at 0.1 ... 0.025)."""
    attempt, refine, nodes, calls = model(1.0, 2.0)
    out = refine_until_met(0.1, attempt, refine, 1e-6, Budget(2, 10**6), nodes)
    assert not out.met and out.stop == "refinements" and calls == [0.1, 0.05, 0.025]
    attempt, refine, nodes, calls = model(1.0, 2.0)
    out = refine_until_met(0.1, attempt, refine, 1e-6, Budget(10, 50), nodes)
    assert not out.met and out.stop == "nodes" and calls == [0.1, 0.05, 0.025]
    assert out.setting == 0.025 and len(out.steps) == 3


def test_an_unresolved_attempt_is_refined_even_when_its_estimate_is_small():
    """A guard's refusal (why) is never 'met': the loop refines while the refusal lasts
    (here up to h = 0.05) and stops at the first resolved attempt; a refusal no refinement
    addresses ends the loop with its reason."""
    def attempt(h):
        return h, 0.0, ("trapped" if h > 0.05 else None)
    out = refine_until_met(0.2, attempt, lambda h, r, e, w: h / 2, 1e-3, Budget(5, 10**6),
                           lambda h, r, n: 1 / n)
    assert out.met and out.setting == 0.05 and [s["why"] for s in out.steps] == [
        "trapped", "trapped", None]
    out = refine_until_met(0.2, attempt, lambda h, r, e, w: None, 1e-3, Budget(5, 10**6),
                           lambda h, r, n: 1 / n)
    assert not out.met and out.stop == "no refinement" and out.why == "trapped"


def test_bad_budget_and_target_are_refused_in_one_line():
    with pytest.raises(ValueError, match="max_refinements"):
        Budget(-1, 100)
    attempt, refine, nodes, _ = model(1.0, 2.0)
    with pytest.raises(ValueError, match="accuracy must be > 0"):
        refine_until_met(0.1, attempt, refine, 0.0, Budget(1, 10), nodes)


def test_outside_bounds_on_both_sides_of_the_bound_plus_the_error():
    """A value may pass a bound by its estimated error, not more (upper and lower)."""
    assert not outside_bounds(2.01, 0.011, 1.5, 2.0)
    assert outside_bounds(2.01, 0.009, 1.5, 2.0)
    assert not outside_bounds(1.49, 0.011, 1.5, 2.0)
    assert outside_bounds(1.49, 0.009, 1.5, 2.0)
    assert not outside_bounds(1.0, 0.0, upper=1.0)
    assert outside_bounds(1.0 + 1e-6, 0.0, upper=1.0)


def test_worst_relative_uses_each_floor():
    """The quantity furthest from its accuracy, relative to max(|value|, floor)."""
    vals = {"a": 2.0, "b": 0.01, "c": None}
    errs = {"a": 0.02, "b": 0.005, "c": 1.0}
    assert worst_relative(vals, errs) == ("b", pytest.approx(0.5))
    assert worst_relative(vals, errs, {"b": 1.0}) == ("a", pytest.approx(0.01))
