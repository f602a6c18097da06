"""The edge route's family stops on the whole error it states, not on its grid part alone.

A synthetic family (no solves): members whose max adhesion converges as F0 + c h^2 exactly,
so Richardson's grid part of the finest member is exact, and given tail and tolerance
parts. Found by review: the family stopped once the grid part alone met the target, the
run then added the tail and failed a request one more member meets ("not met ... stopped:
met", small scene at 1e-4: grid 8.4e-5 + tail 2.0e-5 of the force)."""
from types import SimpleNamespace

import pytest

from femadh.runner import edge_route

F0, C, H0 = 1.0e-5, 2.0e9, 4.0e-9        # N, N/m^2, m: grid parts 3.2e-3, 1.6e-3, 8e-4, 4e-4 of F0


@pytest.fixture
def synthetic(monkeypatch):
    """``family`` on members with F = F0 + C h^2 and the fold at d = h (no solves)."""
    def trace(scene, c_star, h, h0, a0, a_run, c_low, c_high):
        best = SimpleNamespace(max_adhesion=F0 + C * h * h, fold=SimpleNamespace(d=h))
        return SimpleNamespace(n=int(1e-6 / h)), best, 0.0
    monkeypatch.setattr(edge_route, "trace", trace)
    monkeypatch.setattr(edge_route, "_nodes_of", lambda a0, c, h, h0: int(1e-6 / h))
    pil = SimpleNamespace(c_star=1e-6, c_fold=0.5e-6, h0=H0)
    scene = SimpleNamespace(analysis_radius=1e-5)
    return lambda target, other=None, tail_stops=True: edge_route.family(
        scene, pil, target, other=other, tail_stops=tail_stops)


def grid_part(n):
    """The exact grid part of the n-th member (h = H0 / sqrt2^(n-1)): C h^2."""
    return C * (H0 / 2 ** ((n - 1) / 2)) ** 2


def test_the_grid_part_has_the_target_less_the_other_parts(synthetic):
    """Target 1e-3 of F: the grid part alone meets it with 3 members (C h3^2 = 8e-4 of F,
    Richardson exact here); with a tail of 3e-4 and a tolerance of 1e-5 of F the family takes
    a fourth (grid 4e-4 + 3.1e-4 = 7.1e-4; three members' 8e-4 + 3.1e-4 would exceed it)."""
    target = 1e-3
    alone = synthetic(target)
    assert alone.met and len(alone.h) == 3
    assert alone.error == pytest.approx(grid_part(3), rel=1e-6, abs=0)   # (exact up to round-off)
    with_tail = synthetic(target, other=lambda fam: (3e-4 * F0, 1e-5 * F0))
    assert with_tail.met and len(with_tail.h) == 4
    assert with_tail.error == pytest.approx(grid_part(4), rel=1e-6, abs=0)
    assert with_tail.error + 3.1e-4 * F0 <= target * abs(with_tail.value)


def test_a_tail_beyond_safety_stops_the_family_for_the_disk(synthetic):
    """A tail above SAFETY (0.6) of the target where the disk can grow: the family stops at
    its third member saying so ("tail"), for the disk to grow. Where it cannot, the grid
    takes what the tail leaves (0.7 of the target: the fifth member's 2e-4 meets it); where
    tail and tolerance leave nothing, the family stops at once, saying so."""
    from femadh.estimate.refine import SAFETY

    fam = synthetic(1e-3, other=lambda fam: (1.01 * SAFETY * 1e-3 * F0, 0.0))
    assert not fam.met and fam.stop == "tail" and len(fam.h) == 3
    fam = synthetic(1e-3, other=lambda fam: (0.7e-3 * F0, 0.0), tail_stops=False)
    assert fam.met and len(fam.h) == 5
    assert fam.error == pytest.approx(grid_part(5), rel=1e-6, abs=0)
    fam = synthetic(1e-3, other=lambda fam: (0.5e-3 * F0, 0.6e-3 * F0))
    assert not fam.met and len(fam.h) == 3 and "no share" in fam.stop
