"""The smooth LJ sphere (no sigma-gap) as a building block: its problem at a Tabor parameter,
its deepest separation, its lateral length scales and its force with the exact tail.

Shared by the regime map (:mod:`femadh.studies.regime`), the peer benchmark, the layered-film
study in ``validation/`` and the tests. The Tabor parameter mu = (R dg^2 / (E*^2 z0^3))^(1/3)
with dg = A / (16 pi z0^2) (paper 1 eq 19) fixes E* at given R, A, z0.
"""
import math

from ..contact import ContactProblem
from ..elastic import GreenOperator, RadialGrid
from ..indenter import Sphere
from ..laws import LennardJones
from ..reference.adhesion import dmt_contact_radius, jkr_contact_radius
from ..reference.maugis import jkr_approach, maugis_length_units

#: a priori: LJ softening stiffness below this fraction of a node's (fixed graded grid)
STIFFNESS_TARGET = 0.4
#: compressive load (units pi R dg) at the deepest point of a curve without folds (DMT side)
PRELOAD = 0.5
#: fixed graded grid: uniform spacing up to this multiple of the JKR radius at PRELOAD
FINE_MARGIN = 1.15


def lateral_length(law, radius, e_star):
    """ell (m): the smaller of the elastocohesive length E* z0^2/dg (cohesive-zone width at a
    JKR-like edge) and sqrt(R z0 / 8) (the gap of the rigid paraboloid grows by z0/16 over it:
    the DMT side, where the law's range, not the edge, sets the lateral scale)."""
    return min(e_star_length(law, e_star), math.sqrt(radius * law.z0 / 8))


def e_star_length(law, e_star):
    """Elastocohesive length E* z0^2 / dg (m)."""
    return e_star * law.z0**2 / law.work_of_adhesion


def lj_sphere_problem(mu, radius, hamaker, z0, stiffness_target, min_nodes):
    """The smooth-sphere problem at Tabor mu on a fixed graded grid: uniform fine spacing (set
    by the LJ softening stiffness against a node's) up to where the contact edge travels.

    Returns (problem, lj, e_star, a, d_min): a is the analysis radius (m), d_min the
    separation (m) of the deepest point, where the JKR load is PRELOAD pi R dg.
    """
    lj = LennardJones(hamaker, z0)
    dg = lj.work_of_adhesion
    e_star = math.sqrt(radius * dg * dg / (mu**3 * z0**3))
    a_unit = maugis_length_units(radius, e_star, dg)[0]
    a = max(4.32 * a_unit, math.sqrt(2 * radius * 20 * z0))
    a_max = jkr_contact_radius(PRELOAD * math.pi * radius * dg, radius, e_star, dg)
    d_min = deepest_separation(mu, radius, e_star, lj)
    # node self-stiffness scales like 1/spacing: calibrate it on a coarse uniform probe
    probe = ContactProblem(GreenOperator(RadialGrid.uniform(a, 60), e_star), Sphere(radius),
                           {"lj": lj})
    ratio0, _, _, _ = probe.surface_force_stiffness()
    dr = a / 59.5 * stiffness_target / ratio0
    if dr >= a / (min_nodes - 0.5):
        grid = RadialGrid.uniform(a, min_nodes)
    else:
        grid = RadialGrid.graded(a, dr, FINE_MARGIN * a_max)
    problem = ContactProblem(GreenOperator(grid, e_star), Sphere(radius), {"lj": lj})
    return problem, lj, e_star, a, d_min


def deepest_separation(mu, radius, e_star, law):
    """Separation (m) of the deepest point: where the load is PRELOAD pi R dg in the nearer
    limit (DMT below mu = 1, JKR above), from where the rigid sphere's force vanishes
    (U(d) = 0: d = z0 / 4^(1/6) for LJ)."""
    dg, z0 = law.work_of_adhesion, law.z0
    load = PRELOAD * math.pi * radius * dg
    if mu < 1:
        delta = dmt_contact_radius(load, radius, e_star, dg) ** 2 / radius
    else:
        delta = jkr_approach(jkr_contact_radius(load, radius, e_star, dg), radius, e_star, dg)
    return z0 / 4 ** (1 / 6) - delta


def lj_force(problem, lj, d, w):
    """Force on the disk (N, attractive positive) of a state: the law's pressure integrated
    over the analysis disk plus the tail beyond it, where the surface is undeformed and the
    paraboloid's force is exactly -2 pi R U(b(a; d)) (Derjaguin is exact for a paraboloid:
    2 pi r dr = 2 pi R dh)."""
    a, radius = problem.grid.radius, problem.sphere.radius
    h = problem.contour(d) - w
    tail = -2 * math.pi * radius * float(lj.energy(d + a * a / (2 * radius)))
    return problem.grid.force(problem.pressure(h)) + tail
