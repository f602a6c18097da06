"""Paper 1's Hertz closure (femadh.contact.closure): Newton in (w_free, r_c) with the edge
condition evaluated at r = r_c.

Every tolerance is a small multiple (<= 10x) of the error measured with this code; the measured
value is in the comment. Paper values are text statements of paper 1 sec 4 (figures are not in
the text we have).
"""
import math

import numpy as np
import pytest

from femadh.contact import AsperityGap, ContactProblem
from femadh.contact import closure as cl
from femadh.contact.closure import trace as cl_trace
from femadh.laws import LennardJones, eq20_pressure
from femadh.elastic import GreenOperator, RadialGrid
from femadh.errors import ConvergenceError
from femadh.indenter import Sphere
from femadh.contact.forces import state_forces
from femadh.reference import hertz_load

from conftest import E_STAR, HAMAKER, Z0

R2MM = 2e-3
TOL = 1e-19  # the scenes' tolerance, 1e-10 nm


def problem(n, sigma, *, hamaker=HAMAKER, adhesion=0.0, laws=None, check_laws=True):
    a = math.sqrt(2 * R2MM * 10e-9)                 # delta = a^2/2R = 10 nm, as the paper
    eff = laws if laws is not None else {"lj": LennardJones(hamaker, Z0)}
    return ContactProblem(GreenOperator(RadialGrid.uniform(a, n), E_STAR), Sphere(R2MM), eff,
                          AsperityGap(sigma, "hertz-closure", adhesion), check_laws=check_laws)


def grid(start, stop, step=0.2):
    return np.round(np.arange(start, stop - 1e-6 * np.sign(step), -step if stop < start
                              else step), 10) * 1e-9


# --------------------------------------------------------------------------- Hertz limit

def test_without_lj_the_closure_is_hertz():
    """A = 0: r_c = sqrt(R (sigma - d)), F_el = 4E* r_c^3/(3R), w = b - sigma inside, exactly
    (the Hertz displacement is closed form, the edge condition is evaluated at r_c): the only
    error left is the solver's tolerance. With A = 0 the edge residual is
    G = d - sigma + r_c^2/R, so |G| <= tol bounds |r_c - a| by tol R/(2a)."""
    sigma = 1e-9
    p = problem(100, sigma, hamaker=0.0)
    sw = cl.trace_closure(p, np.array([2.0, 0.5, -1.0, -3.0, -5.0]) * 1e-9, branch="approach",
                          tol=TOL)
    assert sw.states[0].r_c == 0.0 and not sw.jumps
    for s in sw.states[1:]:
        a = math.sqrt(R2MM * (sigma - s.d))
        assert s.converged and s.stable
        bound = TOL * R2MM / (2 * a)                 # 1e-16 m at a = 1 um
        assert abs(s.r_c - a) <= bound               # measured 1.4e-17 m at a = 1 um
        F_el = state_forces(p, s)[1]
        assert abs(F_el / hertz_load(a, R2MM, E_STAR) - 1) <= 3 * bound / a  # F ~ a^3
        b = p.contour(s.d)
        assert np.array_equal(s.w[s.active], b[s.active] - sigma)     # clamped, exactly
        # eq 10 also holds inside when there is no LJ (the Hertz field is the exact solution),
        # to the tolerance: the r_c error moves W_H by 2a dr_c/R <= tol (measured 1.4e-20 m)
        assert s.diagnostics["eq10_violation_inside_m"] <= TOL


# --------------------------------------------------------------------------- Jacobian

@pytest.mark.parametrize("sigma, d, r_c0", [(1e-9, -1e-9, 2e-6), (0.5e-9, 0.8e-9, 1.8e-6)])
@pytest.mark.parametrize("edge", ["node inside", "node outside"])
def test_joint_jacobian_matches_finite_differences(sigma, d, r_c0, edge):
    """The bordered Jacobian, r_c column and d column included, against central differences,
    with the contact edge on either side of the node of the cut annulus (its node clamped, or
    free with only the annulus's outer part loaded)."""
    p = problem(100, sigma)
    cs = cl.ClosureSystem(p)
    st = cl.solve_closure_state(p, d, np.zeros(100), tol=TOL, r_c0=r_c0, system=cs)
    assert st.converged
    m, j = cs.split(st.r_c)
    lo, node, hi = cs.edges[j], cs.nodes[j], cs.edges[j + 1]
    r_c = 0.5 * (node + hi) if edge == "node inside" else 0.5 * (lo + node)
    w = cs.clamp(st.w, d, r_c)
    ev = cs.evaluate(d, w, r_c, jac=True)
    assert (ev.m == ev.j) == (edge == "node outside")
    J = ev.jacobian("r_c")

    def res(ww, rr, dd=d):
        e = cs.evaluate(dd, ww, rr)
        return np.append(e.F, e.G)

    fd = np.zeros_like(J)
    for k in range(ev.m, cs.n):
        eps = 1e-6 * sigma
        wp, wm = w.copy(), w.copy()
        wp[k] += eps
        wm[k] -= eps
        fd[:, k - ev.m] = (res(wp, r_c) - res(wm, r_c)) / (2 * eps)
    eps = 1e-9 * r_c
    fd[:, -1] = (res(w, r_c + eps) - res(w, r_c - eps)) / (2 * eps)
    fd_d = (res(w, r_c, d + 1e-6 * sigma) - res(w, r_c, d - 1e-6 * sigma)) / (2e-6 * sigma)
    # w block: entries O(1); measured <= 3.8e-10 (round-off of the differences)
    assert np.max(np.abs(J[:, :-1] - fd[:, :-1])) < 4e-9
    # r_c column (Hertz, ring influence dD/da, edge row d/dr_c): measured <= 7.8e-8 relative
    assert np.max(np.abs(J[:, -1] - fd[:, -1])) / np.max(np.abs(fd[:, -1])) < 8e-7
    # d column (tangent predictor, landing scan): measured <= 2.2e-10 relative
    d_col = np.append(ev.f_d, ev.g_d)
    assert np.max(np.abs(d_col - fd_d)) / np.max(np.abs(fd_d)) < 3e-9


# --------------------------------------------------------------------------- sigma = 1 nm

@pytest.fixture(scope="module")
def fig3_closure():
    p = problem(100, 1e-9)
    ds = grid(2.0, -5.0)
    a = cl.trace_closure(p, ds, branch="approach", tol=TOL)
    return p, a


def test_sigma_1nm_sweep_reaches_minus_5nm(fig3_closure):
    """The old fixed-r_c closure stalled at d = -3.6..-3.8 nm; the joint Newton goes to -5 nm."""
    p, a = fig3_closure
    assert a.states[-1].d == pytest.approx(-5e-9, abs=1e-21)
    assert not a.jumps                                   # sigma = 1 nm: no snap (paper)
    assert all(s.converged and s.stable for s in a.states)
    # F_LJ(-5 nm): N = 100 0.27596, N = 200 0.27591, N = 400 0.275911 mN; 1e-3 is 6x the
    # N = 100 difference from N = 400 (1.6e-4)
    assert state_forces(p, a.states[-1])[0] == pytest.approx(0.275911e-3, rel=1e-3)


def test_edge_condition_and_eq10_outside_hold_eq10_inside_is_violated(fig3_closure):
    p, a = fig3_closure
    sigma = p.sigma
    contact = [s for s in a.states if s.r_c > 0]
    assert len(contact) >= 30
    for s in a.states:
        assert s.residual <= TOL                         # max|w - w10| free + |edge|
        assert s.diagnostics["edge_residual_m"] <= TOL   # w(r_c) = b(r_c) - sigma
    for s in contact:
        assert np.all(s.h[s.active] == sigma)            # eq 8 inside, by construction
        assert np.min(s.h[~s.active]) > sigma            # and the gap opens outside
    # eq 10 inside: violated, growing with the load; max 0.18968 nm (N = 100), 0.18972
    # (N = 200, 400): 19 % of sigma. Tolerance 10x the N = 100 to 400 difference.
    v = [s.diagnostics["eq10_violation_inside_m"] for s in contact]
    assert np.all(np.diff(v) > 0)
    assert max(v) == pytest.approx(0.18972e-9, rel=2.5e-3, abs=0)


# --------------------------------------------------------------------------- sigma = 0.5 nm

@pytest.fixture(scope="module")
def fig4_closure():
    p = problem(200, 0.5e-9)                             # the scene's N
    ds = grid(2.0, -3.0)
    a = cl.trace_closure(p, ds, branch="approach", tol=TOL)
    r = cl.trace_closure(p, ds[::-1], branch="retract", tol=TOL, start=a.states[-1])
    return p, a, r


def test_sigma_half_nm_snap_in_snap_out_and_hysteresis(fig4_closure):
    p, a, r = fig4_closure
    assert all(s.converged and s.stable for s in a.states + r.states)
    assert all(s.residual <= TOL for s in a.states + r.states)
    (jin,), (jout,) = a.jumps, r.jumps
    res = 0.2e-9 * cl_trace.MIN_STEP_FRACTION                 # folds located to 1.95e-4 nm
    assert jin.resolution == pytest.approx(res, rel=1e-9, abs=0)   # measured 7.5e-13
    assert jout.resolution == pytest.approx(res, rel=1e-9, abs=0)
    # snap-in: the free surface's fold (the same as the complementarity model's, 1.1098 nm)
    assert jin.before.r_c == 0 and jin.after.r_c > 0
    assert jin.d_fold == pytest.approx(1.10977e-9, abs=2 * res)
    assert jin.after.r_c == pytest.approx(1.4633e-6, rel=4e-3)  # N=100: 1.4686 (3.6e-3)
    # snap-out: the closure branch's fold, at a larger d: hysteresis
    assert jout.before.r_c > 0 and jout.after.r_c == 0
    assert jout.d_fold == pytest.approx(1.29141e-9, abs=3e-12)  # N=100: 1.29395 (2.5e-12)
    assert jout.d_fold - jin.d_fold > 0.15e-9                    # measured 0.182 nm
    # on the grid: at d = 1.2 nm contact on retract, free on approach (the paper saw none)
    k = int(np.argmin([abs(s.d - 1.2e-9) for s in a.states]))
    kr = int(np.argmin([abs(s.d - 1.2e-9) for s in r.states]))
    assert a.states[k].r_c == 0 and r.states[kr].r_c > 1e-6


def test_closure_reproduces_paper_fig4(fig4_closure):
    """Paper sec 4: "the minimum value of -F_ex is about -0.3 mN, and r_c = 3.7 um at F_ex = 0,
    as seen from Fig 4(e)". "About 0.3" has one digit (+-0.05 mN: ~15 %); 3.7 um is read off
    the paper's own plot: we allow 10 % and 5 %. Measured (N = 200): 0.31095 mN (+3.7 %) at
    d = 0.2 nm, r_c = 3.6196 um (-2.2 %); N = 100: 0.31149 mN, 3.6243 um."""
    p, a, r = fig4_closure
    f = np.array([state_forces(p, s)[2] for s in a.states])
    assert f.max() == pytest.approx(0.3e-3, rel=0.10)
    # the scene's N = 200 value at 2x its N-sensitivity (N = 100 vs 200: 1.7e-3)
    assert f.max() == pytest.approx(0.31095e-3, rel=3.5e-3, abs=0)
    rc = np.array([s.r_c for s in a.states])
    k = int(np.flatnonzero((f[:-1] > 0) & (f[1:] <= 0) & (rc[:-1] > 0))[0])
    r0 = rc[k] + f[k] / (f[k] - f[k + 1]) * (rc[k + 1] - rc[k])
    assert r0 == pytest.approx(3.7e-6, rel=0.05)
    # eq 10 inside is violated by up to 1.875 nm, 3.75 sigma (N = 100: 1.874)
    v = max(s.diagnostics["eq10_violation_inside_m"] for s in a.states)
    assert v == pytest.approx(1.875e-9, rel=1.5e-3, abs=0)             # 3x its N-sensitivity 5e-4


def test_stability_rule_flips_at_the_fold():
    """Inside the hysteresis loop (d = 1.2 nm) the closure has two contact states: the small
    one (between the free branch and the snap-out fold) has det J > 0 - unstable - the large
    one det J < 0, as in the Hertz limit."""
    p = problem(100, 0.5e-9)
    cs = cl.ClosureSystem(p)
    free = cl.solve_closure_state(p, 1.2e-9, np.zeros(100), tol=TOL, system=cs)
    assert free.r_c == 0 and free.stable
    pts, _, crossings = cl_trace._scan_branch(cs, free.w, free.d, 0.5 * cs.nodes[1], +1, 1.2e-9,
                                        tol=TOL, max_iter=40, stop_at_first=False,
                                        r_to=3e-6)
    assert [s for _, s in crossings] == [False, True]
    d_star = np.array([q.d for q in pts])
    r_star = np.array([q.r_c for q in pts])
    k = int(np.argmax(d_star))               # the snap-out fold: max of d*(r_c)
    assert crossings[0][0] < r_star[k] < crossings[1][0]


# --------------------------------------------------------------------------- errors

class _NanBelow:
    """LJ whose pressure is nan for gaps below h_nan (a broken law)."""

    def __init__(self, h_nan, lo=0.0):
        self.lj, self.h_nan, self.lo = LennardJones(HAMAKER, Z0), h_nan, lo

    def pressure(self, h):
        p = self.lj.pressure(h)
        return np.where((h < self.h_nan) & (h > self.lo), np.nan, p)

    def dpressure(self, h):
        return self.lj.dpressure(h)

    def energy(self, h):
        return self.lj.energy(h)


def test_nan_in_the_law_is_named_not_a_nan_residual():
    sigma = 1e-9
    # nan between sigma and 1.05 sigma: first met on a free node next to the contact edge
    p = problem(100, sigma, laws={"lj": _NanBelow(1.05 * sigma, lo=1.0000001 * sigma)},
                check_laws=False)   # the law check would refuse it before any solve
    with pytest.raises(ConvergenceError) as exc:
        cl.trace_closure(p, grid(2.0, -1.0), branch="approach", tol=TOL)
    msg = str(exc.value)
    assert "non-finite gap-law pressure P(h)" in msg and "node" in msg and "d = " in msg
    assert "iteration" in msg and "residual = nan" not in msg
    assert exc.value.sweep.states                      # the states before it are kept
    # nan at sigma itself: the clamped contact's pressure, named at set-up
    p = problem(100, sigma, laws={"lj": _NanBelow(1.5 * sigma)}, check_laws=False)
    with pytest.raises(ConvergenceError, match=r"P\(sigma\)"):
        cl.ClosureSystem(p)


def test_no_stable_state_error_shows_the_scan():
    """Asked to land on the contact branch at a d above its snap-out fold (no contact state
    there), the scan reports the d range it covered and that d*(r_c) - d has no sign change."""
    p = problem(100, 0.5e-9)
    free = cl.solve_closure_state(p, 1.5e-9, np.zeros(100), tol=TOL)
    with pytest.raises(ConvergenceError) as exc:
        cl.land_closure(p, free, 1.5e-9, branch="approach", tol=TOL)
    msg = str(exc.value)
    assert "no sign change" in msg and "contact branch scanned over r_c" in msg
    assert "nan" not in msg


# --------------------------------------------------------------------------- eq 20

def test_asperity_adhesion_acts_over_the_contact_only():
    """Eq 20 in the closure: the constant P_LJa on r < r_c (force P_LJa pi r_c^2 exactly); it
    makes touch-down a snap and raises the adhesion (sec 6, rho = 179 um^-2, sigma = 1.08 nm)."""
    sigma = 1.08e-9
    p_lja = eq20_pressure(0.94e-6, 0.06, 179e12, 0.5)
    p0 = problem(100, sigma)
    p1 = problem(100, sigma, adhesion=p_lja)
    ds = grid(1.4, 0.4)
    s0 = cl.trace_closure(p0, ds, branch="approach", tol=TOL)
    s1 = cl.trace_closure(p1, ds, branch="approach", tol=TOL)
    for s in s1.states:
        F_a = p1.grid.force(s.p_effects["asperity_adhesion"])
        # measured 2.2e-16 relative
        assert F_a == pytest.approx(p_lja * math.pi * s.r_c**2, rel=2e-15, abs=0)
    f0 = max(state_forces(p0, s)[2] for s in s0.states)
    f1 = max(state_forces(p1, s)[2] for s in s1.states)
    # eq 20's pull grows with the contact (P_LJa D(r_c, r_c) ~ r_c): touch-down is a fold and
    # the surface snaps into a finite contact there (N = 200: at 1.2465 nm, to 1.437 um)
    (jump,) = s1.jumps
    assert jump.before.r_c == 0 and jump.after.r_c > 1e-6
    assert not s0.jumps
    # measured on this 0.2-nm grid: 0.02682 (no eq 20) and 0.16121 mN (N = 200: 0.16124)
    assert f0 == pytest.approx(0.02682e-3, rel=2e-3)
    assert f1 == pytest.approx(0.16121e-3, rel=2e-3)


# --------------------------------------------------------------------------- FE fallback

def test_interpolated_influence_tracks_the_exact_one(fig3_closure):
    """The interpolation used for operators without an influence function (FE), run on the
    Green compliance: first order in the edge position. Measured at sigma = 1 nm, d = -3 nm,
    N = 100: r_c 1.6e-4 relative, F_ex 7.3e-4 relative."""
    p, a = fig3_closure
    exact = next(s for s in a.states if abs(s.d + 3e-9) < 1e-15)
    approx = cl.solve_closure_state(p, exact.d, exact.w, tol=TOL, r_c0=exact.r_c,
                                    system=cl.ClosureSystem(p, cl.InterpolatedInfluence(p)))
    assert approx.converged and approx.stable
    # 3x the measured differences (1.6e-4, 7.3e-4)
    assert approx.r_c == pytest.approx(exact.r_c, rel=5e-4, abs=0)
    assert state_forces(p, approx)[2] == pytest.approx(state_forces(p, exact)[2], rel=2.2e-3,
                                                        abs=0)


def test_closure_reproduces_the_papers_fig8():
    """Sec 6 slider (sigma = z_m = 1.08 nm, eq 20 with p = 0.5) with the paper's closure and
    A = 16 pi z0^2 dg = 8.21e-20 J (eq 19 with its dg = 0.06 J/m^2): the paper's Fig 8 max
    adhesion 0.05 and 0.151 mN for rho = 100 and 179 um^-2, which its text gives to 2 and 3
    digits (+-5 % is the reading accuracy); femadh 0.048315 and 0.148991 mN at N = 100
    (N = 200: 0.048300, 0.148956; 3.1e-4 and 2.3e-4), pinned at 1e-3."""
    from validation.paper1 import closure_sweeps, max_adhesion
    from validation.roughness import slider_scene

    for rho, paper, ours in ((100, 0.05, 0.048315), (179, 0.151, 0.148991)):
        sc = slider_scene("8.211e-20 J", rho=rho).replace({"solver.nodes": 100})
        p, sweeps, err = closure_sweeps(sc)
        assert err is None
        value = max(max_adhesion(p, sw)[0] for sw in sweeps.values())
        assert value == pytest.approx(paper, rel=0.05)
        assert value == pytest.approx(ours, rel=1e-3, abs=0)
