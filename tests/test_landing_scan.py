"""The landing's scan of contact edges farther from the descent's (femadh.contact.landing:
EDGE_SCAN in :func:`_next_edges`, issue 21 goal 1).

Measured at full size (validation/results/sigma03_pulloff.md): on the stiction map's
sigma = 0.3 nm, p/psat = 0.05 point the retract's flat branch before the pull-off releases a
contact node per micro-fold; at d = 1.76836 nm (512 nodes, 1.71-nm follow band, 157 contact
nodes) the descent settled on 156 nodes and the corrector cycled at a residual of 2.3e-16 m
from every disk of 153-159 nodes: the landing failed and ended the run. From 151 nodes
(the descent's - 5) it converged in 6 iterations on a stable state of 155 nodes. That case
costs minutes; here the same situation is made on the small landing of
tests/test_landing_relax.py (the 2-mm slider at sigma = 0.3 nm, p/psat = 0.05, 253 nodes,
26 nm band spacing, its approach's second fold, built there from the 70-node branch state)
by letting the corrector fail from every disk within EDGE_SHIFTS of the descent's, as it
did there."""
import numpy as np
import pytest

from femadh.contact import landing
from femadh.contact.linalg import disk_size

from test_landing_relax import D_LAND, _check_landing, corner_case


@pytest.fixture(scope="module")
def case():
    """(scene, problem, d, descent (w, contact set), the state before the fold) of the
    landing whose polish from the descent fails (test_landing_relax's case, built there
    without tracing the approach: :func:`test_landing_relax.corner_case`)."""
    scene, p, before, descent = corner_case()
    return scene, p, D_LAND, descent, before


def _near_fail(monkeypatch, m, reach):
    """The corrector, as landing calls it, fails from every disk within ``reach`` nodes of
    the descent's m (as on the full-size case, where no equilibrium exists near those
    edges); records the start disks tried."""
    real = landing.solve_complementarity
    tried = []

    def solve(problem, d, w0, *, active0=None, **kw):
        k = disk_size(active0) if active0 is not None and active0.any() else None
        tried.append(k)
        st = real(problem, d, w0, active0=active0, **kw)
        if k is not None and abs(k - m) <= reach:
            st.converged = False
        return st
    monkeypatch.setattr(landing, "solve_complementarity", solve)
    return tried


def test_the_scan_lands_from_the_nearest_farther_edge(case, monkeypatch):
    """With no equilibrium reachable from the edges within EDGE_SHIFTS the scan tries the
    next farther edges both ways (+3 and -3 first) and returns a stable equilibrium of the
    collocation equations (checked independently: residual, gap bound, contact pressure,
    energy Hessian) whose energy lies below the departing surface's; no edge beyond the
    first distance that gave one is tried; the landing is on the disk it started from."""
    scene, p, d, (w, active), before = case
    m = disk_size(active)
    reach = max(abs(k) for k in landing.EDGE_SHIFTS)
    tried = _near_fail(monkeypatch, m, reach)
    st = landing._next_edges(p, d, w, active, tol=scene.tolerance, max_iter=scene.max_iter)
    assert st is not None
    _check_landing(p, st, scene.tolerance)
    # the neighbouring edges in EDGE_SHIFTS' order, then the next distance both ways and no
    # farther: measured, from +3 (73 nodes) the corrector converged on those 73 nodes
    assert tried == [m + k for k in landing.EDGE_SHIFTS] + [m + reach + 1, m - reach - 1]
    assert disk_size(st.active) == m + reach + 1
    # a landing: its energy below the departing surface's at the landing's separation
    assert p.energy(st.w, d) < p.energy(before.w, d)


def test_without_the_scan_the_landing_has_no_edge(case, monkeypatch):
    """The same failing corrector with EDGE_SCAN at EDGE_SHIFTS' reach (no scan) or with
    the neighbouring edges off (EDGE_SHIFTS empty: the scan goes with them): no landing."""
    scene, p, d, (w, active), before = case
    m = disk_size(active)
    reach = max(abs(k) for k in landing.EDGE_SHIFTS)
    _near_fail(monkeypatch, m, reach)
    monkeypatch.setattr(landing, "EDGE_SCAN", reach)
    assert landing._next_edges(p, d, w, active, tol=scene.tolerance,
                               max_iter=scene.max_iter) is None
    monkeypatch.setattr(landing, "EDGE_SCAN", 8)
    monkeypatch.setattr(landing, "EDGE_SHIFTS", ())
    assert landing._next_edges(p, d, w, active, tol=scene.tolerance,
                               max_iter=scene.max_iter) is None


def test_a_pull_off_lands_on_the_separated_state(case):
    """_separated: on the slider's member at d = 1.3 nm (between the approach's jump-in at
    1.11 nm and the retract's pull-off) the surface at the approach's deepest contact state
    carried there, a surface in contact with more energy than the separated state (the
    descent's minimum of a pull-off, measured at full size: -4.5569e-12 J in contact,
    -4.5815e-12 J separated), lands on the separated state: a stable equilibrium with no
    node in contact (checked independently); from a surface of lower energy than that
    state it is refused (a landing never climbs)."""
    from femadh.contact.complementarity import solve_complementarity

    scene, p, d_fold, _, before = case
    d = 1.3e-9
    free = landing._separated(p, d, np.zeros(p.grid.n), tol=scene.tolerance,
                              max_iter=scene.max_iter)
    # the undeformed surface itself lies above the separated state's energy (the laws pull
    # the surface down by a little): a landing from it
    assert free is not None and not free.active.any()
    _check_landing(p, free, scene.tolerance)
    e_free = p.energy(free.w, d)
    # a surface of lower energy: the contact state at that separation (the retract's
    # branch, reached by Newton from the fold's departing surface): no landing from it
    b = p.contour(d)
    A = before.active.copy()
    w0 = np.where(A, b - p.sigma, before.w)
    held = solve_complementarity(p, d, w0, tol=scene.tolerance, max_iter=scene.max_iter,
                                 active0=A)
    assert held.converged and held.stable and held.active.any()
    assert p.energy(held.w, d) < e_free
    assert landing._separated(p, d, held.w, tol=scene.tolerance,
                              max_iter=scene.max_iter) is None
