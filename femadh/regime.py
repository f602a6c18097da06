"""Smooth-sphere Lennard-Jones adhesion regime map (beyond the papers).

A smooth elastic sphere against a flat with the LJ law of paper 1 eq (3) and no sigma-gap: the
repulsive term carries the contact. Swept in the Tabor parameter
mu = (R dg^2 / (E*^2 z0^3))^(1/3), dg = A / (16 pi z0^2) (eq 19), by choosing E* at fixed R, A,
z0. Each point is an approach-retract sweep with fold detection; the pull-off is the largest
tensile force on the retract branch (load-controlled pull-off), normalised by pi R dg and
compared with Maugis-Dugdale at lambda = 1.157 mu (Johnson & Greenwood 1997) and the JKR (1.5)
and DMT (2) limits. Classic computations of this problem: Greenwood 1997, Proc. R. Soc. A 453,
1277 ("Adhesion of elastic spheres"); Feng 2000, J. Colloid Interface Sci. 238, 318.
"""
from dataclasses import dataclass
import math
import time

import numpy as np

from .contact import ContactProblem, trace
from .effects import LennardJones
from .elastic import GreenOperator, RadialGrid
from .indenter import Sphere
from .output import state_forces
from .reference.maugis import lj_dugdale_lambda, maugis_pull_off

R_DEFAULT, A_DEFAULT, Z0_DEFAULT = 1e-6, 1e-19, 0.165e-9


@dataclass
class RegimePoint:
    mu: float
    e_star: float
    pull_off: float            # / (pi R dg)
    maugis: float              # / (pi R dg)
    jump_in: float | None      # d / z0 of the approach fold
    jump_out: float | None     # d / z0 of the retract fold
    hysteresis: float          # energy dissipated per cycle / (pi R dg z0)
    n_steps: int
    nodes: int
    wall_time: float
    curves: dict


#: node count is raised until the LJ softening stiffness is below this fraction of one node's
STIFFNESS_TARGET = 0.4


def lj_sphere(mu, *, nodes=None, steps=40, radius=R_DEFAULT, hamaker=A_DEFAULT, z0=Z0_DEFAULT,
              tol=1e-19, min_nodes=120):
    """Approach-retract sweep of a smooth LJ sphere at Tabor parameter mu.

    ``nodes=None`` picks the node count so that the LJ law's largest softening stiffness stays
    below STIFFNESS_TARGET of a single node's stiffness (K_kk grows like N), which keeps the
    discrete surface free of node-scale snapping (lattice trapping) at large mu.
    """
    t0 = time.perf_counter()
    lj = LennardJones(hamaker, z0)
    dg = lj.work_of_adhesion
    e_star = math.sqrt(radius * dg * dg / (mu**3 * z0**3))
    K = 4 * e_star / 3
    a_unit = (math.pi * dg * radius**2 / K) ** (1 / 3)          # Maugis length units
    d_unit = (math.pi**2 * dg**2 * radius / K**2) ** (1 / 3)
    a = max(3.0 * 1.44 * a_unit, math.sqrt(2 * radius * 20 * z0))
    def build(n):
        return ContactProblem(GreenOperator(RadialGrid.uniform(a, n), e_star), Sphere(radius),
                              {"lj": lj})

    if nodes is None:
        probe = build(min_nodes)
        ratio = probe.surface_force_stiffness()[0]
        nodes = max(min_nodes, int(math.ceil(min_nodes * ratio / STIFFNESS_TARGET)))
        problem = probe if nodes == min_nodes else build(nodes)
    else:
        problem = build(nodes)
    d0 = 12 * z0
    d_min = z0 - 2.1 * d_unit                                      # compressive ~ +pi R dg
    d = np.linspace(d0, d_min, steps + 1)
    ap = trace(problem, d, branch="approach", tol=tol)
    rt = trace(problem, d[::-1], branch="retract", tol=tol, start=ap.states[-1])

    def force(states):
        out = []
        for s in states:
            h_a = s.d + a * a / (2 * radius)
            tail = -2 * math.pi * radius * float(lj.energy(h_a))    # rigid LJ beyond a
            out.append(state_forces(problem, s)[2] + tail)
        return np.array(out)

    fa, fr = force(ap.states), force(rt.states)

    def branch_path(sweep):
        """(d, F) along a branch in visiting order, folds included (before, then landing)."""
        pts = []
        jumps = {id(j.before): j for j in sweep.jumps}
        states = list(sweep.states)
        for j in sweep.jumps:  # fold and landing states sit between grid states
            states += [j.before, j.after]
        sign = 1 if sweep.branch == "retract" else -1
        order = sorted(range(len(states)), key=lambda i: (sign * states[i].d,
                                                          0 if id(states[i]) in jumps else 1))
        for i in order:
            pts.append((states[i].d, force([states[i]])[0]))
        return np.array(pts)
    scale = math.pi * radius * dg
    # the grid may straddle a sharp force peak (DMT-like, small mu): re-trace the retract
    # branch finely between the neighbours of its largest tensile force
    k = int(np.argmax(fr))
    if 0 < k < len(rt.states) - 1:
        fine = np.linspace(rt.states[k - 1].d, rt.states[k + 1].d, 41)
        sub = trace(problem, fine, branch="retract", tol=tol, start=rt.states[k - 1])
        fr_peak = max(fr.max(), force(sub.states).max())
    else:
        fr_peak = fr.max()
    # hysteresis: work of the closed cycle, approach (d decreasing) then retract, along the
    # branches including their fold and landing states (the loop can be narrower than a step)
    fr_on_d = fr[::-1]
    trap = getattr(np, "trapezoid", None) or np.trapz
    pa, pr = branch_path(ap), branch_path(rt)
    hyst = float(trap(pr[:, 1], pr[:, 0]) + trap(pa[:, 1], pa[:, 0])) / (scale * z0)
    return RegimePoint(
        mu, e_star, float(fr_peak / scale), maugis_pull_off(lj_dugdale_lambda(mu)),
        ap.jumps[0].d_fold / z0 if ap.jumps else None,
        rt.jumps[-1].d_fold / z0 if rt.jumps else None, hyst,
        ap.n_solves + rt.n_solves, nodes, time.perf_counter() - t0,
        {"d": d, "approach": fa / scale, "retract": fr_on_d / scale})


def regime_map(mus, **kw):
    return [lj_sphere(mu, **kw) for mu in mus]
