"""The max-adhesion bracket the sink keeps (femadh.runner.sink.Sink's peak bookkeeping) across
a grid exchange (femadh.runner.tracing.exchange_grid), a resume (Sink.load) and a failed fold
re-solve (Sink._fold_fields): synthetic sequences of committed records.

The bracket [prev, best, next] is interpolated node by node (femadh.runner.peak.state_between):
its states must be on one grid (the peak's problem's) and hold displacements."""
from types import SimpleNamespace

import numpy as np
import pytest

from femadh.runner.sink import Committed, Sink
from femadh.runner.tracing import exchange_grid


def _problem(n):
    """A stand-in problem of n nodes on [0, 1 um] without a gap constraint: what exchange_grid
    reads (grid.n, grid.nodes, sigma)."""
    return SimpleNamespace(grid=SimpleNamespace(n=n, nodes=np.linspace(0.0, 1e-6, n)),
                           sigma=None)


def _sink(problem):
    s = Sink.__new__(Sink)
    s.problem, s.writer = problem, None
    s.peak, s._prev, s._need_next, s._rival = None, None, False, None
    s.peak_problem = s.rival_problem = problem
    s.pieces, s.last, s.committed, s.curve_pieces = {}, {}, {}, {}
    return s


def _rec(d, f, n):
    return Committed(d, np.full(n, -d), np.zeros(n, bool), 0.0, f)


def _commit(sink, d, f):
    snap = _rec(d, f, sink.problem.grid.n)
    sink._track_peak("retract", snap)
    return snap


def _on_peak_grid(sink):
    n = sink.peak_problem.grid.n
    return [np.size(s.w) for s in sink.peak[2:5] if s is not None], n


def test_exchange_moves_the_next_candidates_neighbour():
    """A peak completed on 5 nodes stays there; the next (larger) state, after the exchange
    to 7 nodes, is bracketed by the last state before the exchange, carried to 7 nodes."""
    sink = _sink(_problem(5))
    for d, f in ((1.0e-9, 1.0), (1.1e-9, 3.0), (1.2e-9, 2.0)):
        _commit(sink, d, f)
    assert sink.peak[4] is not None         # complete on the old grid
    old_peak = list(sink.peak)
    exchange_grid(sink, sink.problem, _problem(7))
    assert all(np.size(s.w) == 5 for s in old_peak[2:5])    # the kept peak left as it was
    _commit(sink, 1.3e-9, 5.0)
    _commit(sink, 1.4e-9, 4.0)
    sizes, n = _on_peak_grid(sink)
    assert n == 7 and sizes == [7, 7, 7], sizes


def test_exchange_moves_a_landing_neighbour():
    """A fold after the completed peak: its landing (never in sink.last) is the next
    candidate's previous neighbour and must go on to the new grid; the fold record itself
    stays on its own."""
    sink = _sink(_problem(5))
    for d, f in ((1.0e-9, 1.0), (1.1e-9, 3.0), (1.2e-9, 2.0)):
        _commit(sink, d, f)
    before, after = _rec(1.25e-9, 2.5, 5), _rec(1.3e-9, 2.0, 5)
    sink._track_fold("retract", before, after)
    exchange_grid(sink, sink.problem, _problem(7))
    assert np.size(after.w) == 5            # the fold's record on its own grid
    _commit(sink, 1.4e-9, 5.0)
    _commit(sink, 1.5e-9, 4.0)
    sizes, n = _on_peak_grid(sink)
    assert n == 7 and sizes == [7, 7, 7], sizes


def test_resume_replay_leaves_a_neighbour_with_a_surface():
    """A resume replays the committed rows and folds as records without displacements and
    reads back those of the peak's, the rival's and each branch's last state
    (Sink.load). The last row at its landing's separation is the landing's own state: the
    next peak's previous neighbour must be that row (read back), not the landing's record
    (no surface: refine_peak failed on w = None)."""
    sink = _sink(_problem(5))
    blank = lambda d, f: Committed(d, None, None, 0.0, f)     # noqa: E731 (a replayed record)
    for d, f in ((1.0e-9, 3.0), (1.1e-9, 2.0)):
        sink._track_peak("retract", blank(d, f))
    sink._track_fold("retract", blank(1.15e-9, 1.5), blank(1.2e-9, 1.0))
    sink._track_peak("retract", blank(1.2e-9, 1.0))          # the landing's row
    # what load() reads back: the peak's bracket and the last state of each branch
    for s in [x for x in sink.peak[2:5] if x is not None] + list(sink.last.values()):
        s.w = np.full(5, -s.d)
    _commit(sink, 1.3e-9, 5.0)       # the resumed run's next state: a new peak
    _commit(sink, 1.4e-9, 4.0)
    assert all(s.w is not None for s in sink.peak[2:5]), [s.w for s in sink.peak[2:5]]
    assert sink.peak[2].d == 1.2e-9


class _Solve:
    """Stand-ins for femadh.contact's solve_state and trace and the sink's state_forces: the
    neighbour's re-solve converges (or not, or raises), the re-trace to the fold state
    raises (a kill -9 resume whose fold state does not trace again)."""

    def __init__(self, monkeypatch, converged=True, raises=False, force=2.0):
        import femadh.contact as contact
        import femadh.runner.sink as sink_mod
        from femadh.errors import ConvergenceError

        def solve_state(p, d, w, **kw):
            if raises:
                raise ConvergenceError("stand-in: no stiffness", d=d)
            return SimpleNamespace(d=d, w=w, converged=converged, stable=converged)

        def trace(*a, **kw):
            raise ConvergenceError("stand-in: the step to the fold state failed")
        monkeypatch.setattr(contact, "solve_state", solve_state)
        monkeypatch.setattr(contact, "trace", trace)
        monkeypatch.setattr(sink_mod, "state_forces", lambda p, st: (0.0, 0.0, force))


def _resumed(tmp_path, peak_is_fold):
    """A replayed sink whose peak bracket holds a fold state without displacements (no
    checkpoint in tmp_path), its committed neighbour the row k = 0 at 1.0 nm."""
    sink = _sink(_problem(5))
    sink.scene = SimpleNamespace(tolerance=1e-12, max_iter=10)
    sink.result = SimpleNamespace(warnings=[])
    fields = {0: (1.0e-9, np.full(5, -1e-9), None, np.zeros(5))}
    row = _rec(1.0e-9, 2.0, 5)
    fold = Committed(1.05e-9, None, None, np.nan, 3.0 if peak_is_fold else 1.0)
    fold.near = 0
    if peak_is_fold:        # the fold's last state is the largest F_ex: its own next
        sink.peak = ["retract", 3.0, row, fold, fold]
    else:                   # a landing is the peak's previous neighbour
        sink.peak = ["retract", 4.0, fold, _rec(1.1e-9, 4.0, 5), _rec(1.2e-9, 3.5, 5)]
    sink._fold_fields(tmp_path, [fold], fields)
    return sink


def test_failed_fold_peak_keeps_its_grid_force(tmp_path, monkeypatch):
    """The fold's last state is the peak and does not trace again: the largest adhesion is
    its recorded grid force at its separation (the stand-in neighbour, 2.0, made the
    bracket one point and the headline its force: below the grid maximum, 3.0)."""
    from femadh.runner.peak import peak_adhesion

    _Solve(monkeypatch)
    sink = _resumed(tmp_path, peak_is_fold=True)
    F, d, _ = peak_adhesion(None, *sink.peak[2:5], sink.scene)
    assert F >= sink.peak[1] and d == 1.05e-9, (F, d)
    assert sink.result.warnings


def test_failed_neighbour_resolve_is_no_nan(tmp_path, monkeypatch):
    """The neighbour's re-solve does not converge: no NaN F_ex enters the bracket (the
    landing side is cut at the best state), and a warning says so."""
    _Solve(monkeypatch, converged=False)
    sink = _resumed(tmp_path, peak_is_fold=False)
    assert all(np.isfinite(s.f_ex) for s in sink.peak[2:5])
    assert sink.peak[2] is sink.peak[3]
    assert "did not re-solve" in sink.result.warnings[0]


def test_neighbour_resolve_error_is_the_fallbacks(tmp_path, monkeypatch):
    """The neighbour's re-solve raises a ConvergenceError: the fallback's failure (a
    warning), not the resume's."""
    _Solve(monkeypatch, raises=True)
    sink = _resumed(tmp_path, peak_is_fold=False)
    assert all(np.isfinite(s.f_ex) for s in sink.peak[2:5])
    assert sink.result.warnings


def _fold_sink(delta, r, D=0.2e-9, c=1e-3, d_f=1.3e-9, F_f=3e-5):
    """A retract piece ending at a fold: F = F_f - c sqrt(d_f - d) (a saddle-node's
    square-root branch, c in N/m^0.5), the last stable state delta before the fold, the
    committed state before it a grid step D earlier; the jump recorded with resolution r."""
    F = lambda d: F_f - c * np.sqrt(d_f - d)        # noqa: E731
    sink = _sink(_problem(5))
    prev = _rec(d_f - delta - D, F(d_f - delta - D), 5)
    before = _rec(d_f - delta, F(d_f - delta), 5)
    sink._track_peak("retract", prev)
    sink._track_fold("retract", before, _rec(d_f + 0.1e-9, 1e-6, 5))
    res = SimpleNamespace(jumps=[{"branch": "retract", "resolution_m": r}])
    return sink, res, F_f - before.f_ex


def test_fold_end_error_bounds_the_rise_to_the_fold():
    """The maximum at a fold's last state: the d error holds the jump's resolution r and the
    force error bounds the square-root branch's rise to the fold, exactly where the fold is
    r beyond the state (the bound's worst case) and above it nearer; the secant times r (the
    linear term) falls short of the rise by ~sqrt(D / r) = 32 at r = D / 1024."""
    from femadh.runner.estimates import fold_end_error

    D = 0.2e-9
    r = D / 1024                # the stepping's fold resolution, 2^-10 of the grid step
    for delta, tight in ((r, True), (0.5 * r, False), (0.01 * r, False)):
        sink, res, rise = _fold_sink(delta, r, D)
        branch, f, prev, best, nxt = sink.peak
        assert nxt is best
        got = fold_end_error(sink, res, branch, prev, best, nxt, best.d)
        assert got is not None and got[0] == r
        # (tight: equal to round-off, measured 2e-12 relative; 1e-9 allowed)
        assert got[1] >= rise * (1 - 1e-9), (got, rise)
        if tight:
            assert got[1] == pytest.approx(rise, rel=1e-9, abs=0)
            secant = (best.f_ex - prev.f_ex) / D * r
            assert secant < rise / 20
    # a maximum inside the bracket (the search's own d), or no recorded resolution: none
    assert fold_end_error(sink, res, branch, prev, best, nxt, best.d - 1e-12) is None
    res.jumps[0]["resolution_m"] = 0.0
    assert fold_end_error(sink, res, branch, prev, best, nxt, best.d) is None
