"""Stability of an equilibrium: the inertia of the symmetric energy Hessian on the free nodes.

A state is a strict local minimum of the total energy (elastic + interaction, paper 1 eqs 5-10
in energy form) on the nodes that are free to move iff the Hessian

    H_II = sym(S)_II + diag(area_I P'(h_I)),   S = diag(area) K,

is positive definite; nodes held at h = sigma are fixed. The test is a Cholesky factorisation
(LAPACK potrf): it succeeds iff H_II is positive definite. This is the only stability decision
in femadh's stepping solver. (The Newton factorisation is of the collocation Jacobian
K + diag(P'), which is not symmetric; the signs of its pivots relative to its diagonal are not
the Hessian's inertia: with a free node's own diagonal negative, a saddle reads as stable.)
"""
import numpy as np
from scipy.linalg import lapack

from ..errors import ConvergenceError


def is_positive_definite(M):
    """True iff the symmetric matrix M is positive definite (Cholesky succeeds); M is copied."""
    if M.size == 0:
        return True
    _, info = lapack.dpotrf(M, lower=False, clean=False, overwrite_a=False)
    return info == 0


def is_stable(problem, h, free):
    """Whether the state with gaps h (m) is an energy minimum on the nodes ``free`` (bool mask)."""
    H = problem.energy_hessian(h, free)
    if not np.all(np.isfinite(H)):
        k = int(np.flatnonzero(~np.all(np.isfinite(H), axis=1))[0])
        raise ConvergenceError(f"stability test: the energy Hessian is not finite (free node "
                               f"{k}, gap {h[free][k]:.6g} m)")
    if getattr(problem, "banded", True) is False:
        # sym(S) + a diagonal is symmetric to the bit: its transpose is the same matrix in
        # LAPACK's order, factorised in place (the wrapper's transposing copy of a C-ordered
        # H: 0.53 ms against the factorisation's 2.8 ms at ~600 nodes); a sub-grid law's
        # tridiagonal part is symmetric only to round-off, and keeps its copy
        _, info = lapack.dpotrf(H.T, lower=False, clean=False, overwrite_a=True)
        return info == 0
    return is_positive_definite(H)
