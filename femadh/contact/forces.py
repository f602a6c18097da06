"""Forces of a state: pressures integrated over the annuli (paper 1 eqs 11-13 with their area
weights 2 pi r dr; the printed sums lack them), and the force the laws exert beyond the
analysis radius."""
import math

import numpy as np


def state_forces(problem, state):
    """(F_LJ, F_el, F_ex) in N for a state (eqs 11-13 with 2 pi r dr area weights).

    F_ex sums every effect (LJ, capillary, ...) minus the contact force.
    """
    g = problem.grid
    f_lj = g.force(state.p_effects["lj"]) if "lj" in state.p_effects else 0.0
    f_eff = sum(g.force(p) for p in state.p_effects.values())
    f_el = g.force(state.p_contact)
    return f_lj, f_el, f_eff - f_el


def tail_force(problem, d):
    """Force (N, attractive positive) of the laws beyond the analysis radius on the undeformed
    paraboloid: 2 pi R int_{h_a}^inf P dh = -2 pi R U(h_a), h_a = b(a; d)."""
    a, R = problem.grid.radius, problem.sphere.radius
    h_a = np.array([d + problem.sphere.shape(a)])
    return float(-2 * math.pi * R * sum(np.asarray(e.energy(h_a))[0]
                                        for e in problem.effects.values()))
