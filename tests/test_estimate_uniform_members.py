"""A uniform grid's estimate members: N/2 and N/4, or N/sqrt2 and N/2 where the N/4 member
would be near-trapped (femadh.runner.estimates.uniform_member_nodes).

The Fig 4 scene (sigma = 0.5 nm): the N = 200 run's N/2 and N/4 members soften at 0.48 and
0.96 of a node's own stiffness and land micro-jump after micro-jump; their grid part of the
largest adhesion was 3.2x its error, of the pull-off 6 lattice steps
(validation/results/effectivity.md). Members at N/sqrt2 and N/2 (measured against the 5-nm
reference, validation/results/accuracy.md): F_LJ at the deepest state 1.49 -> 1.17, the
largest adhesion 13.4 -> 11.1, the pull-off 7.0 -> 6.8."""
import pytest

import femadh
from femadh.discretisation.plan import TRAP_SAFE, trapping_ratio
from femadh.runner.estimates import coarser_members, variant
from femadh.scene import build_problem

FIG3 = "validation/scenes/paper1_fig3.toml"
FIG4 = "validation/scenes/paper1_fig4.toml"


def _uniform(path, n):
    """The scene on a uniform grid of n nodes (its accuracy setting dropped)."""
    return variant(femadh.load_scene(path), nodes=n)


@pytest.mark.parametrize("path, n, family", [
    # Fig 4: the run's own trapping ratio 0.24 at N = 200, 0.12 at 400 and 0.06 at 800, so
    # N/4 at 0.96, 0.48 and 0.24: the finer pair at 200 and 400 only
    (FIG4, 200, (141, 100)), (FIG4, 400, (283, 200)), (FIG4, 800, (400, 200)),
    # Fig 3 (LJ without sigma): N/4 of N = 100 at 0.06
    (FIG3, 100, (50, 25))])
def test_members_follow_the_quarter_members_softening(path, n, family):
    """The pair is chosen by the N/4 member's trapping ratio, measured here on the N/4
    member's own grid (the rule predicts it from the run's by the spacing ratio), and
    the ratios the estimate divides by are the spacings the members' grids actually have."""
    sc = _uniform(path, n)
    pb = build_problem(sc)
    r, members, r2 = coarser_members(sc, pb)
    assert tuple(m.nodes for _, m in members) == family
    quarter = trapping_ratio(build_problem(_uniform(path, n // 4)))
    assert (family[0] != n // 2) == (quarter > TRAP_SAFE)
    h = [float(build_problem(m).grid.nodes[1]) for _, m in members]
    h0 = float(pb.grid.nodes[1])
    if family[0] == n // 2:
        assert r == 2.0 and r2 is None          # (as before: the even ratio)
    else:
        # the uneven ratios Richardson takes (observed_order_uneven), to round-off
        assert r == pytest.approx(h[0] / h0, rel=1e-12, abs=0)
        assert r2 == pytest.approx(h[1] / h[0], rel=1e-12, abs=0)
        # and the coarsest member is no coarser than N/2: at most twice the run's spacing
        assert h[1] / h0 < 2.01


def test_the_estimate_divides_by_the_members_uneven_ratios(monkeypatch):
    """A uniform run whose members are N/sqrt2 and N/2 (the Fig 4 scene at N = 100, its own
    trapping ratio 0.48: N/4 at 1.9) takes its grid part from Richardson over the ratios its
    members' spacings have (observed_order_uneven): 99.5/70.5 and 70.5/49.5, recorded in the
    result."""
    from femadh.runner import estimates

    seen = []
    real = estimates.discretisation

    def spy(*a, **kw):
        seen.append(kw)
        return real(*a, **kw)
    monkeypatch.setattr(estimates, "discretisation", spy)
    sc = variant(femadh.load_scene(FIG4), nodes=100).replace(
        {"sweep.start": "1.2 nm", "sweep.stop": "0.6 nm"})
    res = femadh.run(sc, progress=False, figures=False)
    assert res.status == "converged"
    assert res.grid["members"] == ["N = 71", "N = 50"]
    assert res.grid["member_ratio"] == pytest.approx(99.5 / 70.5, rel=1e-12, abs=0)
    assert res.grid["member_ratio2"] == pytest.approx(70.5 / 49.5, rel=1e-12, abs=0)
    assert seen and seen[0]["ratio"] == res.grid["member_ratio"] \
        and seen[0]["ratio2"] == res.grid["member_ratio2"]
