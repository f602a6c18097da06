"""Independent campaign (2026-11-25): contact behaviour no other test pinned down.

- a continuation started on a saddle (an unstable equilibrium between the folds of the
  Tabor mu = 2 S-curve) must leave it at once: every later state it records is an energy
  minimum, by its flag and by the smallest eigenvalue of the energy Hessian;
- a sigma-gap state with every node on the constraint has no free direction: it is a minimum;
- the moving band's contact edge is the linear interpolation of the gap between the nodes
  that straddle the edge gap;
- the paper's closure differentiates the Green disk displacement in the disk radius and in r:
  those derivatives are the finite differences of the displacement itself.
"""
import numpy as np
from scipy import optimize

from femadh.contact import AsperityGap, ContactProblem, solve_state, trace
from femadh.contact.arclength import trace_curve
from femadh.elastic import GreenOperator, RadialGrid
from femadh.indenter import Sphere
from femadh.studies.smooth_sphere import lj_sphere_problem

from conftest import E_STAR, HAMAKER, Z0

TOL = 1e-19


def test_a_sweep_started_on_a_saddle_slides_off_it():
    problem, lj, e_star, a, d_min = lj_sphere_problem(2.0, 1e-6, HAMAKER, Z0, 0.4, 120)
    curve = trace_curve(problem, 12 * Z0, d_min, tol=TOL, scale=Z0, ds=0.2, ds_max=2.0)
    i1, i2 = (f.index for f in curve.folds)
    p = curve.points[(i1 + i2) // 2]
    start = solve_state(problem, p.d, p.w, tol=TOL, max_iter=40)
    assert start.converged and not start.stable          # a saddle between the folds
    for sign in (1, -1):
        ds = p.d + sign * np.linspace(0.0, 0.3, 7) * Z0
        sw = trace(problem, ds, branch="approach" if sign < 0 else "retract", tol=TOL,
                   start=start)
        assert len(sw.jumps) >= 1                       # it leaves the saddle by a jump
        for s in sw.states[1:]:
            assert s.converged and s.stable
            lam = np.linalg.eigvalsh(problem.energy_hessian(s.h, ~s.active))[0]
            assert lam > 0


def test_full_contact_state_is_stable():
    """Every node held at h = sigma by a positive contact pressure: the energy Hessian on the
    free nodes is empty and the state a (constrained) minimum."""
    R, sigma = 2e-3, 0.5e-9
    a = 0.2e-6
    p = ContactProblem(GreenOperator(RadialGrid.uniform(a, 20), E_STAR), Sphere(R), {},
                       AsperityGap(sigma))
    # the sphere's sag over the disk is a^2/(2R) = 1e-11 m: pressing 1 nm past sigma puts
    # every node in contact
    d = sigma - 1e-9
    st = solve_state(p, d, np.zeros(p.grid.n), tol=TOL, max_iter=40)
    assert st.converged and np.all(st.active)
    assert np.all(st.p_contact > 0)
    assert st.stable


def test_contact_edge_interpolates_the_gap_linearly():
    from femadh.discretisation.moving import contact_edge

    R, a, n = 1e-6, 0.2e-6, 41
    p = ContactProblem(GreenOperator(RadialGrid.uniform(a, n), E_STAR), Sphere(R), {})
    d = 0.3e-9
    w = np.zeros(n)
    h = p.contour(d)
    r = p.grid.nodes
    for gap in (0.5e-9, 1.1e-9, 3.7e-9, 9.0e-9):
        edge = contact_edge(p, w, d, gap)
        k = int(np.flatnonzero(h <= gap)[-1])
        assert r[k] <= edge <= r[k + 1]
        # exact crossing of the rigid profile, d + shape(r*) = gap; the chord through the
        # straddling nodes is off by O(dr^2 / R): measured <= 6.3e-3 dr; tolerance 0.02 dr (3x)
        exact = optimize.brentq(lambda x: d + float(p.sphere.shape(x)) - gap, r[k], r[k + 1])
        assert abs(edge - exact) < 0.02 * (r[1] - r[0])


def test_closure_disk_influence_derivatives_are_the_derivatives_of_the_green_disk():
    """The paper's closure differentiates the disk displacement D(r, a) of the load inside the
    contact edge in a (a ring load at the rim) and in r; both must be the derivatives of
    femadh.elastic.green.disk_displacement (central differences, step 1e-6 a)."""
    from femadh.contact.closure.influence import (disk_displacement_da,
                                                  disk_displacement_dr_inside)
    from femadh.elastic import disk_displacement

    a = 1e-6
    r = np.array([0.0, 0.1, 0.3, 0.6, 0.9, 0.97, 1.03, 1.2, 2.0, 5.0]) * a
    h = 1e-6 * a
    fd = (disk_displacement(r, a + h, E_STAR) - disk_displacement(r, a - h, E_STAR)) / (2 * h)
    # measured: max relative difference 1.4e-10 (difference round-off); tolerance 1e-8
    assert np.max(np.abs(disk_displacement_da(r, a, E_STAR) / fd - 1)) < 1e-8
    ri = np.array([0.02, 0.1, 0.3, 0.6, 0.9, 0.97]) * a
    fd = (disk_displacement(ri + h, a, E_STAR) - disk_displacement(ri - h, a, E_STAR)) / (2 * h)
    # measured: max relative difference 3.4e-9 (r = 0.02 a); tolerance 1e-7
    assert np.max(np.abs(disk_displacement_dr_inside(ri, a, E_STAR) / fd - 1)) < 1e-7
