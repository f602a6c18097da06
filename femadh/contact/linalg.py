"""Factorisations that follow a moving contact edge."""
import numpy as np
from scipy import linalg


class TrailingLU:
    """One LU that solves every trailing block (K + D)[m:, m:] for m >= m0.

    When the contact set is a disk (nodes 0..m-1), the free-node Jacobian is the trailing block
    from m. Factorised in reversed node order, every trailing block is a *leading* block, and
    the LU of a leading block is the leading part of the full LU as long as partial pivoting
    made no row swap before it (checked: ``k_valid``). So moving the contact edge costs a
    triangular solve, not a new factorisation.
    """

    def __init__(self, K, D, m0, scale=None):
        n = K.shape[0]
        # reversed trailing block, a copy (the reversed slice is cheaper than fancy indexing)
        M = np.array(K[m0:, m0:][::-1, ::-1])
        M[np.diag_indices_from(M)] += D[m0:][::-1]
        # rows scaled by the annulus areas: diag(area) K is nearly symmetric (the energy
        # Hessian), for which partial pivoting rarely swaps rows - so one factorisation keeps
        # covering every trailing block
        self.scale = None if scale is None else np.asarray(scale, float)
        if self.scale is not None:
            M *= self.scale[m0:][::-1, None]
        self.n, self.m0 = n, m0
        self.lu, self.piv = linalg.lu_factor(M, check_finite=False)
        swaps = np.flatnonzero(self.piv != np.arange(n - m0))
        self.k_valid = int(swaps[0]) if swaps.size else n - m0
        self._block = (None, None)

    def covers(self, m):
        return m >= self.m0 and self.n - m <= self.k_valid

    def _lu_block(self, m):
        k = self.n - m
        if self._block[0] != k:
            lu = self.lu if k == self.lu.shape[0] else np.ascontiguousarray(self.lu[:k, :k])
            self._block = (k, (lu, self.piv[:k]))
        return self._block[1]

    def solve(self, m, rhs):
        """x with (K + D)[m:, m:] x = rhs (rhs in natural node order m..n-1)."""
        if m >= self.n:
            return np.zeros(0)
        if not self.covers(m):  # a pivot from outside the block: LAPACK would read past it
            raise ValueError(f"trailing block from node {m} is not covered (m0 = {self.m0}, "
                             f"valid leading size {self.k_valid})")
        if self.scale is not None:
            rhs = rhs * self.scale[m:]
        return linalg.lu_solve(self._lu_block(m), rhs[::-1], check_finite=False)[::-1]


def disk_size(A):
    """m if the active set is exactly the nodes 0..m-1, else None."""
    m = int(A.sum())
    return m if A[:m].all() else None
