"""A reduced member's solve count is every corrector solve it made: the solves of a lattice
fold search that fails (and falls back to tracing the grid step) are counted too, so the
member's reported cost (summary.json grid.member_solves) is what it spent.

The fold search (:func:`femadh.runner.members._lattice_fold`) runs on stubs here: its solver
calls are counted by a spy, the member's count must equal them (an identity, not a model)."""
from types import SimpleNamespace

import numpy as np
import pytest

from femadh.contact import complementarity, landing, stepping
from femadh.runner import members


def _state(converged=True):
    return SimpleNamespace(d=1e-9, w=np.zeros(3), h=np.ones(3), lu=None, converged=converged,
                           stable=converged, active=np.zeros(3, bool))


@pytest.mark.parametrize("how", ["landing fails", "solve budget spent"])
def test_a_failed_fold_search_counts_its_solves(monkeypatch, how):
    """The search starts from one Newton solve near the fine run's fold (m.near), then either
    every corrector step is refused and the landing does not converge, or every step is
    accepted until MAX_FOLD_SOLVES (here 5) is spent: both end the search (_NotReduced, the
    fallback), and the member has counted the near solve and each corrector or landing
    solve the spy saw."""
    calls = []

    def solve(p, d, w, **kw):
        calls.append("corrector")
        return _state(converged=how == "solve budget spent")

    def land(p, d, w, **kw):
        calls.append("landing")
        return _state(converged=False)

    monkeypatch.setattr(complementarity, "solve_complementarity", solve)
    monkeypatch.setattr(landing, "land", land)
    monkeypatch.setattr(stepping, "total_force", lambda p, s: 0.0)
    monkeypatch.setattr(stepping, "crossed_fold", lambda *a, **k: False)
    monkeypatch.setattr(members, "MAX_FOLD_SOLVES", 5)
    m = SimpleNamespace(problem=SimpleNamespace(sigma=None),
                        scene=SimpleNamespace(tolerance=1e-12, max_iter=50), solves=0)

    def near(snap, d):
        m.solves += 1               # as _Member.near counts its Newton solve
        return _state()
    m.near = near
    with pytest.raises(members._NotReduced):
        members._lattice_fold(m, 1e-9, 0.99e-9, None, None)
    expected = ["corrector", "landing"] if how == "landing fails" else ["corrector"] * 6
    assert calls == expected
    assert m.solves == 1 + len(calls)
