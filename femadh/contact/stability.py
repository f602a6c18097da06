"""Stability of an equilibrium: the inertia of the symmetric energy Hessian on the free nodes.

A state is a strict local minimum of the total energy (elastic + interaction, paper 1 eqs 5-10
in energy form) on the nodes that are free to move iff the Hessian

    H_II = sym(S)_II + diag(area_I P'(h_I)),   S = diag(area) K,

is positive definite; nodes held at h = sigma are fixed. The test is a Cholesky factorisation
(LAPACK potrf): it succeeds iff H_II is positive definite. This is the only stability decision
in femadh's stepping solver. (The Newton factorisation is of the collocation Jacobian
K + diag(P'), which is not symmetric; the signs of its pivots relative to its diagonal are not
the Hessian's inertia: with a free node's own diagonal negative, a saddle read as stable.)

A certificate first (:class:`ElasticCertificate`): where the free nodes are a disk's
complement (the trailing block m..n-1) and the laws are collocated, H_II is positive definite
with a margin whenever a cheap upper bound on the softening measured against the elastic
stiffness alone stays below CERT_LIMIT; that answer ("stable") is then the factorisation's
without it. The bound uses only a factorisation of sym(S) made once per grid (it does not
depend on the state). Near a fold the bound exceeds CERT_LIMIT and the Cholesky of H_II decides,
as it always did: the certificate can only say "stable" where the Cholesky would, never
"unstable", so no decision changes.
"""
import weakref

import numpy as np
from scipy.linalg import lapack

from ..errors import ConvergenceError

#: the certificate answers "stable" only when its bound on the largest eigenvalue of
#: E^1/2 S_II^-1 E^1/2 (E the softening; :class:`ElasticCertificate`) is below this: then
#: H_II >= (1 - CERT_LIMIT) S_II, a margin of a tenth of the elastic stiffness, far above the
#: round-off of any factorisation (relative ~n eps = 3e-13 at 3000 nodes) - the Cholesky of
#: H_II succeeds there too (checked: every certified state of a Fig 4 sweep and of random
#: softenings has the margin, tests/test_stability_certificate.py; every bundled scene's
#: headline numbers are bit-identical with and without the certificate,
#: validation/results/newton_pace_fig4fast3.md)
CERT_LIMIT = 0.9
#: the nodes next to the contact edge (or the axis, without contact) whose softening the
#: bound takes exactly (a dense test of the block); the others enter by the trace of their
#: part. Tried in turn, each only if the smaller one could not prove the bound: the softening
#: zone spans more nodes on a finer grid. Measured on the Fig 4 scene at accuracy 1e-3 (383
#: tests, 595 nodes): a block of 64 certifies 310, 128 certifies 338 and the exact largest
#: eigenvalue (any block) 341 at this limit; at 1e-4 (2904 nodes) 128 alone certified 180
#: of 387, these three 318
EDGE_BLOCKS = (128, 512, 1024)
#: :meth:`ElasticCertificate.refutes` answers "not positive definite" only when the edge
#: block's lambda_max exceeds 1 by this: a negative curvature of 1e-4 of the elastic
#: stiffness along its direction, against a Cholesky's relative round-off of ~n eps kappa(S)
#: (3e-13 x 1e5 at most here)
REFUTE_MARGIN = 1e-4
#: free nodes below which the Cholesky is as cheap as the certificate's bookkeeping
CERT_MIN_FREE = 96
#: Cholesky tests of one problem before its certificate is built (the build is a Cholesky
#: and a triangular inversion of sym(S), about two tests' work: a problem tested only once
#: or twice - a member's few states - does not pay for it)
CERT_BUILD_AFTER = 2


def is_positive_definite(M):
    """True iff the symmetric matrix M is positive definite (Cholesky succeeds); M is copied."""
    if M.size == 0:
        return True
    _, info = lapack.dpotrf(M, lower=False, clean=False, overwrite_a=False)
    return info == 0


class ElasticCertificate:
    """A sufficient test of H_II = S_II - E + E_+ > 0 for every trailing block I = m..n-1.

    S = sym(diag(area) K) is positive definite and does not depend on the state. In reversed
    node order every trailing block S_II is a leading block S_k (k = n - m), whose Cholesky
    factor R_k is the leading block of the full factor R, and R_k^-1 the leading block of
    R^-1 (triangular). With E = diag(max(-area P', 0)) the softening (E_+ the stiffening,
    dropped: it only helps), S_k - E = R_k^T (I - R_k^-T E R_k^-1) R_k, which is positive
    definite iff lambda_max(M) < 1 for M = X X^T, X = E^1/2 R_k^-1 (k x k, upper triangular).
    Split the nodes into B, the b (EDGE_BLOCKS) next to the contact edge (the last indices in
    reversed order: the smallest gaps, where the softening is), and the rest: for a positive
    semi-definite M, lambda_max(M) <= lambda_max(M_BB) + trace(M_RR). M_BB = X_B X_B^T with
    X_B = E_B^1/2 R^-1[B, B] (rows B of the triangular inverse start at B), and
    trace(M_RR) = sum_i e_i q_i(k), q_i(k) = sum_{j <= k-1} (R^-1)_ij^2 (cumulated once per
    grid). So one test costs O(k + 2 b^3 / 3) against the Cholesky's k^3/3.

    Memory: R^-1 and its cumulated squares, 2 n^2 doubles (135 MB at 2900 nodes), also at
    the build's peak (:data:`femadh.scene.resources.GREEN_ARRAYS` counts them).
    """

    def __init__(self, S_sym):
        n = S_sym.shape[0]
        R, info = lapack.dpotrf(np.array(S_sym[::-1, ::-1], order="F"), lower=False,
                                clean=True, overwrite_a=True)
        self.ok = info == 0
        if not self.ok:     # sym(S) itself not positive definite (never for an elastic S)
            return
        rinv, info = lapack.dtrtri(R, lower=False, overwrite_c=True)
        self.ok = info == 0 and bool(np.all(np.isfinite(rinv)))
        if not self.ok:
            return
        self.n = n
        self.rinv = rinv
        # q[i, j] = sum_{l <= j} rinv[i, l]^2; column k - 1 read per test: Fortran order.
        # Built in place, column by column (the same sums in the same order as np.cumsum):
        # the build holds rinv and q, 2 n^2 doubles, not the 3 n^2 of a squared temporary
        # and its cumulated copy (tracemalloc: 3.00 -> 2.00 n^2 at its peak)
        q = np.empty_like(rinv, order="F")
        np.square(rinv, out=q)
        for j in range(1, n):
            np.add(q[:, j], q[:, j - 1], out=q[:, j])
        self.q = q

    def tail(self, e, b):
        """trace(M_RR) = sum_i e_i (S_k^-1)_ii over the nodes outside the edge block (the
        first k - b in reversed order), k = e.size."""
        k = e.size
        return float(e[:k - b] @ self.q[:k - b, k - 1]) if k > b else 0.0

    def _edge_test(self, e, b, room):
        """True iff room I - M_BB is positive definite (LAPACK potrf), M_BB = X_B X_B^T for
        the last b nodes: X_B X_B^T by LAPACK lauum (the product of a triangular matrix with
        its transpose, b^3/3 flops), then a Cholesky (b^3/3)."""
        k = e.size
        X = np.array(self.rinv[k - b:k, k - b:k], order="F")
        X *= np.sqrt(e[k - b:])[:, None]
        G, _ = lapack.dlauum(X, lower=False, overwrite_c=True)
        G *= -1.0
        G[np.diag_indices_from(G)] += room
        _, info = lapack.dpotrf(G, lower=False, clean=False, overwrite_a=True)
        return info == 0

    def refutes(self, e):
        """True if S_k - diag(e) restricted to the edge block is not positive definite with a
        margin: lambda_max(M_BB) > 1 + REFUTE_MARGIN. Then S_k - diag(e) has a direction of
        negative curvature (-REFUTE_MARGIN relative to S_k along it), and so has every
        H_II <= S_k - diag(e) (a Hessian whose free nodes all soften, e its softening or
        any part of it): the Cholesky of H_II fails."""
        return not self._edge_test(e, min(EDGE_BLOCKS[0], e.size), 1.0 + REFUTE_MARGIN)

    def certifies(self, e):
        """True if S_k - diag(e) is positive definite with lambda_max(M) < CERT_LIMIT.

        e : ndarray (k,), >= 0, the softening (N/m) of the free nodes in *reversed* order
        (e[k - 1] is node m, the first free node). The edge blocks of EDGE_BLOCKS are tried
        in turn (a larger one only while it is at most half the free nodes: its test then
        costs at most a quarter of the Cholesky of H_II); the first that proves the bound
        answers."""
        k = e.size
        for i, size in enumerate(EDGE_BLOCKS):
            b = min(size, k)
            if i and 2 * b > k:
                break
            room = CERT_LIMIT - self.tail(e, b)
            if room > 0 and self._edge_test(e, b, room):
                return True
            if b == k:
                break
        return False


#: per problem: [Cholesky tests so far, its ElasticCertificate or None]
_CERTIFICATES = weakref.WeakKeyDictionary()


def _certificate(problem, count=True):
    """The problem's certificate once it has had CERT_BUILD_AFTER stability tests, else None
    (``count``: this call is one more test)."""
    entry = _CERTIFICATES.get(problem)
    if entry is None:
        entry = _CERTIFICATES[problem] = [0, None]
    if entry[1] is None and entry[0] >= CERT_BUILD_AFTER:
        entry[1] = ElasticCertificate(problem.S_sym)
    entry[0] += count
    cert = entry[1]
    return cert if cert is not None and cert.ok else None


def refuted_positive_definite(problem, D, m):
    """True when the energy Hessian sym(S) + diag(area D) on the free nodes m..n-1 (a disk's
    complement; D the collocated law Jacobian P'(h), Pa/m, on every node) is proven not
    positive definite by its edge block (:meth:`ElasticCertificate.refutes`); False when it
    cannot tell (not a verdict). Only where every free node softens (D <= 0), and only once
    the problem's certificate exists (its stability tests built it)."""
    if D.ndim != 1 or getattr(problem, "banded", True) is not False:
        return False
    k = D.size - m
    if k < CERT_MIN_FREE:
        return False
    cert = _certificate(problem, count=False)
    if cert is None:
        return False
    aD = problem.areas[m:] * D[m:]
    if not (np.all(np.isfinite(aD)) and np.all(aD <= 0)):
        return False
    return cert.refutes(-aD[::-1])


def certified_stable(problem, h, free):
    """True when the certificate proves the state stable; False when it cannot tell (not a
    verdict: the Cholesky decides then). Only trailing free sets of collocated laws with at
    least CERT_MIN_FREE free nodes are tried."""
    if getattr(problem, "banded", True) is not False:
        return False
    if free is None:            # every node free (as in ContactProblem.energy_hessian)
        free = np.ones(h.size, bool)
    n = free.size
    k = int(np.count_nonzero(free))
    m = n - k
    if k < CERT_MIN_FREE or not free[m:].all():
        return False
    cert = _certificate(problem)
    if cert is None:
        return False
    # (finite: a law's non-finite derivative raises in dpressure, naming the law and gap)
    D = problem.areas[m:] * problem.dpressure(h[m:])
    return cert.certifies(np.maximum(-D[::-1], 0.0))


def is_stable(problem, h, free):
    """Whether the state with gaps h (m) is an energy minimum on the nodes ``free`` (bool mask;
    None: every node)."""
    if certified_stable(problem, h, free):
        return True
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
