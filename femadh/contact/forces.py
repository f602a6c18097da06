"""Forces of a state: pressures integrated over the annuli (paper 1 eqs 11-13 with their area
weights 2 pi r dr; the printed sums lack them)."""


def state_forces(problem, state):
    """(F_LJ, F_el, F_ex) in N for a state (eqs 11-13 with 2 pi r dr area weights).

    F_ex sums every effect (LJ, capillary, ...) minus the contact force.
    """
    g = problem.grid
    f_lj = g.force(state.p_effects["lj"]) if "lj" in state.p_effects else 0.0
    f_eff = sum(g.force(p) for p in state.p_effects.values())
    f_el = g.force(state.p_contact)
    return f_lj, f_el, f_eff - f_el
