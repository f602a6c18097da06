"""Factorisations that follow a moving contact edge, and the Krylov solver they precondition."""
import math
import warnings

import numpy as np
from scipy import linalg
from scipy.linalg import blas, lapack


# LAPACK called directly on float64 arrays: the bits of scipy.linalg.lu_factor, lu_solve and
# solve_triangular with check_finite=False (which call these same routines, after a batch
# decorator, an array-namespace lookup and a routine lookup by dtype that cost more than the
# LAPACK call itself on the corrector's small systems: in a profile of the whole suite,
# scipy.linalg's 556 000 wrapped calls - 185 000 LU factorisations, 284 000 LU solves, the
# rest Cholesky and triangular solves - spent ~12 s under the profiler in the wrappers' own
# Python: the batch decorator 5.6 s, the array-namespace conversions 5.2 s, the routine
# lookup 1.4 s; validation/results/hotpath.md); any other dtype, shape or an empty system
# goes through scipy's own functions
_GETRF, _GETRS, _TRTRS = lapack.dgetrf, lapack.dgetrs, lapack.dtrtrs
_POTRF, _POTRS = lapack.dpotrf, lapack.dpotrs
_SPOTRF = lapack.spotrf
_F8 = np.dtype(np.float64)


def _plain(a, ndim):
    """Whether ``a`` is a non-empty float64 ndarray of ``ndim`` dimensions (what the direct
    LAPACK calls take; anything else goes through scipy's own function)."""
    return type(a) is np.ndarray and a.dtype == _F8 and a.ndim == ndim and a.size > 0


def _direct_matrix(a):
    return _plain(a, 2) and a.shape[0] == a.shape[1]


def _direct_system(m, b):
    return _direct_matrix(m) and _plain(b, 1) and b.shape[0] == m.shape[0]


def lu_factor(a, overwrite_a=False):
    """(lu, piv) of a square float matrix a: scipy.linalg.lu_factor(a, check_finite=False,
    overwrite_a=overwrite_a), the same LAPACK getrf call and the same warning on an exactly
    singular matrix, without its wrappers."""
    if not _direct_matrix(a):
        return linalg.lu_factor(a, check_finite=False, overwrite_a=overwrite_a)
    lu, piv, info = _GETRF(a, overwrite_a=overwrite_a)
    if info < 0:
        raise ValueError(f"illegal value in {-info}th argument of internal getrf (lu_factor)")
    if info > 0:
        warnings.warn(f"Diagonal number {info} is exactly zero. Singular matrix.",
                      linalg.LinAlgWarning, stacklevel=2)
    return lu, piv


def lu_solve(lu_and_piv, b):
    """x with a x = b from a's :func:`lu_factor`: scipy.linalg.lu_solve(lu_and_piv, b,
    check_finite=False), the same LAPACK getrs call, without its wrappers."""
    lu, piv = lu_and_piv
    if not _direct_system(lu, b):
        return linalg.lu_solve(lu_and_piv, b, check_finite=False)
    x, info = _GETRS(lu, piv, b, trans=0, overwrite_b=False)
    if info != 0:
        raise ValueError(f"illegal value in {-info}th argument of internal gesv|posv")
    return x


def cho_factor(a, overwrite_a=False):
    """(c, lower) of a symmetric positive definite float matrix a: scipy.linalg.cho_factor(a,
    check_finite=False, overwrite_a=overwrite_a), the same LAPACK potrf call (upper factor,
    the other triangle left as it was) and the same LinAlgError where a is not positive
    definite, without its wrappers (the landing's damped descent factorises ~26 000 small
    Hessians in the suite)."""
    if not _direct_matrix(a):
        return linalg.cho_factor(a, check_finite=False, overwrite_a=overwrite_a)
    c, info = _POTRF(a, lower=False, overwrite_a=overwrite_a, clean=False)
    if info > 0:
        raise linalg.LinAlgError(f"{info}-th leading minor of the array is not positive "
                                 "definite")
    if info < 0:
        raise ValueError(f"LAPACK reported an illegal value in {-info}-th argument on entry "
                         "to \"POTRF\".")
    return c, False


def cho_solve(c_and_lower, b):
    """x with a x = b from a's :func:`cho_factor`: scipy.linalg.cho_solve(c_and_lower, b,
    check_finite=False), the same LAPACK potrs call, without its wrappers."""
    c, lower = c_and_lower
    if not _direct_system(c, b):
        return linalg.cho_solve(c_and_lower, b, check_finite=False)
    x, info = _POTRS(c, b, lower=lower, overwrite_b=False)
    if info != 0:
        raise ValueError(f"illegal value in {-info}th argument of internal potrs")
    return x


def cho_factor_single(H, diag):
    """The upper Cholesky factor U (float32, LAPACK's order) with U^T U = H + D in single
    precision, D the diagonal matrix that makes the diagonal ``diag`` (the damped diagonal,
    formed in double by the caller); None where LAPACK spotrf finds a leading minor not
    positive definite in single precision, or a pivot is not a finite positive number there.
    Raises FloatingPointError where an entry is beyond single precision's range (a question
    for the double factorisation, not an answer "not positive definite").

    Parameters
    ----------
    H : ndarray (k, k), float64, C order
        Symmetric (its strictly lower triangle is read: the upper one of its transpose, which
        is LAPACK's Fortran order without a copy); its diagonal is not read.
    diag : ndarray (k,), float64
        The diagonal of the matrix to factorise (rounded to single precision once).

    Why single: spotrf takes half dpotrf's time (twice the SIMD width, half the memory) - at
    2500 nodes 51 against 98 ms on one core - and a factor good to ~7 digits preconditions
    the double-precision conjugate gradients (:func:`pcg`) that make the solution exact to
    the double system's own round-off in a few iterations (the landing's damped descent,
    :func:`femadh.contact.landing._lm_descent`)."""
    with np.errstate(over="ignore", invalid="ignore"):      # (checked just below)
        M = np.array(H, dtype=np.float32)   # C order: M.T is the Fortran-ordered matrix
        d = diagonal(M)
        d[...] = diag                       # the damped diagonal, formed in double
    if not np.all(np.isfinite(M)):
        raise FloatingPointError("an entry beyond single precision's range")
    u, info = _SPOTRF(M.T, lower=False, overwrite_a=True, clean=False)
    if info != 0:
        return None
    piv = np.diagonal(u)
    if not np.all(np.isfinite(piv) & (piv > 0)):
        return None
    return u


def cho_solve_single(u, r):
    """x (float64) with U^T U x = r for U from :func:`cho_factor_single`: two triangular
    solves (BLAS strsv) in single precision - a preconditioner's application, good to the
    factor's ~7 digits. r is scaled to a largest entry of 1 before it is rounded to single
    precision (a residual of ~1e-30 would otherwise fall into its subnormal range and
    vanish: the solve is linear, the scale is put back in double)."""
    r = np.asarray(r, dtype=float)
    scale = float(np.max(np.abs(r), initial=0.0))
    if not scale > 0 or not math.isfinite(scale):
        return np.zeros_like(r) if scale == 0 else np.full_like(r, np.nan)
    y = blas.strsv(u, (r / scale).astype(np.float32), trans=1)      # U^T y = r
    y = blas.strsv(u, y, trans=0, overwrite_x=1)                     # U x = y
    return y.astype(float) * scale


def pcg(apply_a, apply_m, b, rtol, maxiter):
    """Preconditioned conjugate gradients for a symmetric positive definite A x = b.

    Written here rather than taken from :func:`scipy.sparse.linalg.cg`: that one neither
    stops at nor reports a direction of non-positive curvature, which is what proves a
    damped Hessian indefinite to the landing's descent (:class:`femadh.contact.landing.
    _Damped`), nor tells a preconditioner's breakdown from it.

    Parameters
    ----------
    apply_a, apply_m : callable(ndarray) -> ndarray
        The product with A and the preconditioner's solve M^-1 (symmetric positive definite).
    b : ndarray
        Right-hand side (zero: x = 0, converged at once).
    rtol : float
        Relative residual |r| / |b| (2-norms, r the recurred residual) to reach.
    maxiter : int
        Iterations (products with A) at most: the loop's budget.

    Returns
    -------
    (x, iterations, status)
        status "converged" (rtol met), "curvature" (a direction with p.A p <= 0: A is not
        positive definite on the Krylov space - the only status that proves it), "breakdown"
        (r.M^-1 r <= 0: the preconditioner failed, not A), "nan" (a product or a
        preconditioner solve was not a number) or "budget" (maxiter products without meeting
        rtol); x is the last iterate before the status.
    """
    x = np.zeros_like(b)
    r = np.array(b, dtype=float)
    bnorm = math.sqrt(r @ r)
    if bnorm == 0.0:
        return x, 0, "converged"        # (not a direction of zero curvature)
    z = apply_m(r)
    p = z.copy()
    rz = r @ z
    for k in range(1, maxiter + 1):
        q = apply_a(p)
        pq = p @ q
        if not (math.isfinite(pq) and math.isfinite(rz)):
            return x, k, "nan"
        if not rz > 0:
            return x, k, "breakdown"
        if not pq > 0:
            return x, k, "curvature"
        alpha = rz / pq
        x += alpha * p
        r -= alpha * q
        if math.sqrt(r @ r) <= rtol * bnorm:
            return x, k, "converged"
        z = apply_m(r)
        rz_new = r @ z
        p = z + (rz_new / rz) * p
        rz = rz_new
    return x, maxiter, "budget"


def diagonal(M):
    """A writeable view of the diagonal of the square contiguous array M (C or Fortran
    order): ``diagonal(M)[...] += d`` makes the adds of ``M[np.diag_indices_from(M)] += d``,
    the same bits, without building the two index arrays and the gather/scatter (a
    non-contiguous M: its diagonal by those indices)."""
    if M.flags.c_contiguous:
        return M.reshape(-1)[::M.shape[0] + 1]
    if M.flags.f_contiguous:
        return M.T.reshape(-1)[::M.shape[0] + 1]
    return _DiagonalOf(M)


class _DiagonalOf:
    """``+=`` on the diagonal of a non-contiguous square array, by its index arrays."""

    def __init__(self, M):
        self.M = M

    def __iadd__(self, d):
        self.M[np.diag_indices_from(self.M)] += d
        return self


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
        M = np.array(K[m0:, m0:][::-1, ::-1], order="F")    # LAPACK's order: no 2nd copy
        if D.ndim == 2:     # a sub-grid law's tridiagonal Jacobian (ContactProblem.law_jacobian)
            M += D[m0:, m0:][::-1, ::-1]
        else:
            d = diagonal(M)
            d += D[m0:][::-1]
        # rows scaled by the annulus areas: diag(area) K is nearly symmetric (the energy
        # Hessian), for which partial pivoting rarely swaps rows - so one factorisation keeps
        # covering every trailing block
        self.scale = None if scale is None else np.asarray(scale, float)
        if self.scale is not None:
            M *= self.scale[m0:][::-1, None]
        self.n, self.m0 = n, m0
        self.lu, self.piv = lu_factor(M, overwrite_a=True)
        swaps = (self.piv != np.arange(n - m0)).nonzero()[0]
        self.k_valid = int(swaps[0]) if swaps.size else n - m0
        self._block = (None, None)

    def covers(self, m):
        return m >= self.m0 and self.n - m <= self.k_valid

    def _lu_block(self, m):
        k = self.n - m
        if self._block[0] != k:
            # (in LAPACK's order, as getrf left it: a C-ordered block was copied once more
            # by the wrapper on every solve)
            lu = self.lu if k == self.lu.shape[0] else np.asfortranarray(self.lu[:k, :k])
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
        return lu_solve(self._lu_block(m), rhs[::-1])[::-1]


def disk_size(A):
    """m if the active set is exactly the nodes 0..m-1, else None."""
    m = int(A.sum())
    return m if A[:m].all() else None


#: precision of :class:`TrailingCholesky`'s kept factor: single halves the memory the two
#: triangular solves of each preconditioner application read (the solve is bound by memory),
#: and a preconditioner of GMRES with its directions kept (``x = Z y``, the residual of the
#: exact product) needs no more than its ~7 digits: the Krylov steps still reach
#: GMRES_RTOL = 1e-6 of the exact Jacobian
PRECONDITIONER_DTYPE = np.float32


class TrailingCholesky:
    """One Cholesky factorisation that preconditions every trailing block from m >= m0.

    The matrix is the symmetric energy Hessian sym(S) + diag(area D) (N/m, S = diag(area) K;
    :meth:`ContactProblem.energy_hessian`) in reversed node order, so that every trailing
    block is a leading block, and the Cholesky factor U of a leading block is the leading part
    of the full factor - there is no pivoting to spoil it (unlike :class:`TrailingLU`). It is
    positive definite near a stable state; where it is not, ``k_valid`` is the largest leading
    block that is (LAPACK potrf's info), and blocks beyond it are not covered. The factor is
    kept in PRECONDITIONER_DTYPE (single precision); a solve is two triangular solves (BLAS
    trsv) with the leading block of the block size asked for, copied contiguous once per
    size (the contact edge moves by a node or a few per state, and each size serves the
    corrector's iterations and its GMRES products). (It used to keep the inverse of U,
    whose leading blocks are views: the inversion, LAPACK trtri, cost as much as the
    factorisation itself - 2.3 against 2.8 ms at 600 nodes - for every refresh, and its
    two matrix-vector products 42 us against the two triangular solves' 25 us at 450
    nodes.)

    It differs from the area-scaled collocation Jacobian diag(area)(K + D) by the
    antisymmetric part of S (measured 1.4 % of its norm on the Fig 4 scene's 285-node grid)
    and by the change of D since it was built: a preconditioner for :func:`gmres`, not a solver.
    """

    def __init__(self, S_sym, areas, D, m0, not_pd=None, refutes=None):
        self.n, self.m0 = S_sym.shape[0], m0
        self._kept = None
        self._block = (None, None)
        self._deferred = None
        if not_pd is not None:
            # the leading block of size not_pd (the free nodes of the iterate that asked for
            # this refresh) is known not to be positive definite (the edge-block test of
            # :meth:`femadh.contact.stability.ElasticCertificate.refutes`): no block that
            # contains it is covered, and the factorisation is made only when a smaller block
            # is asked for - from the same arrays, so the same factor, bit for bit. Near a
            # fold half the refreshes are such (a whole Fig 4 run at accuracy 1e-3: 147 of
            # 270); 53 of those are never asked for a smaller block, 94 are factorised
            # later (counted by the solve that asks: complementarity._krylov_step).
            # ``refutes(k)``, if given, tells the same of a smaller leading block k (True:
            # proven not positive definite)
            self._deferred = (S_sym, areas, D, not_pd, refutes)
            return
        self._factorise(S_sym, areas, D)

    def _factorise(self, S_sym, areas, D):
        from scipy.linalg import lapack

        n, m0 = self.n, self.m0
        self._deferred = None
        M = np.array(S_sym[m0:, m0:][::-1, ::-1], order="F")
        if D.ndim == 2:     # a sub-grid law: area x its Jacobian is the symmetric df/dh
            M += (areas[m0:, None] * D[m0:, m0:])[::-1, ::-1]
        else:
            d = diagonal(M)
            d += (areas[m0:] * D[m0:])[::-1]
        u, info = lapack.dpotrf(M, lower=False, clean=True, overwrite_a=True)
        self._k_valid = n - m0 if info == 0 else int(info) - 1
        # the factor in the kept precision is taken when a block is first asked for
        # (:meth:`covers`): a factor that covers no block the corrector needs - the Hessian
        # of an iterate off the stable branch, not positive definite at the contact edge,
        # which near a fold is most of the refreshes (91 of 97 on the Fig 4 scene's 631-node
        # sweep) - costs its Cholesky alone
        self._u = u[:self._k_valid, :self._k_valid] if self._k_valid > 0 else None

    @property
    def deferred(self):
        """True while the factorisation has not been made (see ``not_pd``)."""
        return self._deferred is not None

    @property
    def k_valid(self):
        """The largest leading block (reversed node order) that is positive definite."""
        if self._deferred is not None:
            self._factorise(*self._deferred[:3])
        return self._k_valid

    @k_valid.setter
    def k_valid(self, value):
        self._k_valid = value

    def _keep(self):
        """U (reversed node order, upper) in PRECONDITIONER_DTYPE; k_valid drops to 0 where
        a diagonal entry is not a finite positive number in that precision."""
        if self._deferred is not None:
            self._factorise(*self._deferred[:3])
        u, self._u = self._u, None
        self._kept = np.zeros((0, 0), PRECONDITIONER_DTYPE, order="F")
        if u is None or self.k_valid <= 0:
            return
        kept = np.asfortranarray(u, dtype=PRECONDITIONER_DTYPE)
        diag = np.diagonal(kept)
        if not np.all(np.isfinite(diag) & (diag > 0)):
            # a pivot beyond single precision (under- or overflow): nothing is covered
            self.k_valid = 0
            return
        self._kept = kept

    @property
    def kept(self):
        """U in reversed node order (upper triangular, PRECONDITIONER_DTYPE): what a
        checkpoint stores (:meth:`from_kept`)."""
        if self._kept is None:
            self._keep()
        return self._kept

    @classmethod
    def from_kept(cls, kept, n, m0, k_valid):
        """The preconditioner from its kept factor (a checkpoint's arrays)."""
        out = cls.__new__(cls)
        out.n, out.m0, out._k_valid = n, m0, k_valid
        out._deferred = None
        out._u = None
        out._kept = np.asfortranarray(kept, dtype=PRECONDITIONER_DTYPE)
        out._block = (None, None)
        return out

    def covers(self, m):
        if self._deferred is not None and m >= self.m0:
            S_sym, areas, D, not_pd, refutes = self._deferred
            if self.n - m >= not_pd:
                return False        # contains the block known not positive definite
            if refutes is not None and refutes(self.n - m):
                self._deferred = (S_sym, areas, D, self.n - m, refutes)
                return False
        if not (m >= self.m0 and self.n - m <= self.k_valid):
            return False
        if self._kept is None:
            self._keep()            # (may find a pivot out of range: then nothing is covered)
        return self.n - m <= self.k_valid

    def _factor_block(self, k):
        """The leading k x k block of U, contiguous (one copy per block size)."""
        if self._block[0] != k:
            kept = self.kept
            blk = kept if k == kept.shape[0] else np.asfortranarray(kept[:k, :k])
            # (the routine's name, not the f2py routine: a factor stays picklable)
            self._block = (k, blk, "strsv" if blk.dtype == np.float32 else "dtrsv")
        return self._block[1]

    def solve(self, m, rhs):
        """x with H[m:, m:] x = rhs (natural node order m..n-1): U^T U x' = rhs' in reversed
        order (x' = x reversed), two triangular solves."""
        k = self.n - m
        blk = self._block
        if blk[0] != k or k <= 0:
            # a new block size: checked once (a block is cut only from a factor that covers
            # it, and what a factor covers never changes once its block is cut: the
            # corrector's iterations and GMRES products then skip the checks)
            if k <= 0:
                return np.zeros(0)
            if not self.covers(m):
                raise ValueError(f"trailing block from node {m} is not covered (m0 = "
                                 f"{self.m0}, positive definite leading size {self.k_valid})")
            self._factor_block(k)
            blk = self._block
        from scipy.linalg import blas

        u, trsv = blk[1], getattr(blas, blk[2])
        # (a double vector would be converted by the wrapper anyway; reversed, contiguous)
        r = np.array(rhs[::-1], dtype=u.dtype)
        y = trsv(u, r, trans=1, overwrite_x=1)          # U^T y = r
        x = trsv(u, y, trans=0, overwrite_x=1)          # U x = y
        return np.asarray(x[::-1], dtype=float)


#: Krylov dimension of one preconditioned solve before it counts as failed
GMRES_MAX = 12


def gmres(apply_a, apply_m, b, rtol, maxiter=GMRES_MAX):
    """Right-preconditioned GMRES for a small dense system A x = b (Givens rotations).

    Parameters
    ----------
    apply_a, apply_m : callable(ndarray) -> ndarray
        The product with A and the preconditioner's solve M^-1.
    b : ndarray
    rtol : float
        Relative residual |b - A x| / |b| to reach.
    maxiter : int
        Krylov dimension (the cap of the loop).

    Returns
    -------
    (x, iterations, converged)
        x = M^-1 V y minimises |b - A x| over the Krylov space; converged: rtol met.
    """
    # np.linalg.norm's own sqrt(b . b) without its checks - for a contiguous b (norm ravels
    # a strided or reversed b first, which changes the sum's order): both callers pass one
    b = np.ascontiguousarray(b)
    beta = math.sqrt(b @ b)
    n = b.size
    if beta == 0.0 or n == 0:
        return np.zeros(n), 0, True
    V = np.empty((maxiter + 1, n))
    Z = np.empty((maxiter, n))
    R = np.zeros((maxiter + 1, maxiter))
    # the rotations and the rotated right-hand side as Python floats: the same IEEE double
    # arithmetic as numpy scalars, bit for bit, without their per-operation overhead (the
    # loop's own Python was a third of a Krylov iteration at ~400 free nodes)
    cs, sn = [0.0] * maxiter, [0.0] * maxiter
    g = [0.0] * (maxiter + 1)
    g[0] = beta
    V[0] = b / beta
    j = 0
    for j in range(maxiter):
        Z[j] = apply_m(V[j])
        w = apply_a(Z[j])
        # classical Gram-Schmidt, twice (as stable as modified, in two BLAS calls each)
        Vj = V[:j + 1]
        h = Vj @ w
        w = w - h @ Vj
        h2 = Vj @ w
        w = w - h2 @ Vj
        col = (h + h2).tolist()
        col.append(math.sqrt(w @ w))        # np.linalg.norm's own sqrt(w . w)
        for i in range(j):      # the earlier rotations on the new column
            a, c = col[i], col[i + 1]
            col[i], col[i + 1] = cs[i] * a + sn[i] * c, -sn[i] * a + cs[i] * c
        r = math.hypot(col[j], col[j + 1])
        cs[j], sn[j] = (1.0, 0.0) if r == 0 else (col[j] / r, col[j + 1] / r)
        breakdown = col[j + 1] <= 1e-14 * beta
        V[j + 1] = w / col[j + 1] if not breakdown else 0.0
        col[j] = r
        R[:j + 1, j] = col[:j + 1]
        g[j + 1] = -sn[j] * g[j]
        g[j] = cs[j] * g[j]
        if abs(g[j + 1]) <= rtol * beta or breakdown:
            break
    k = j + 1
    y = _back_substitute(R[:k, :k], np.array(g[:k]))
    return y @ Z[:k], k, bool(abs(g[k]) <= rtol * beta)


def _back_substitute(R, g):
    """y with the upper triangular R y = g (small: GMRES's Hessenberg after rotation).

    scipy.linalg.solve_triangular(R, g, check_finite=False) for R a block of a C-ordered
    array, as it calls LAPACK trtrs (on the transpose: the lower triangle of R^T, transposed
    system), without its wrappers."""
    if R.dtype != _F8 or g.dtype != _F8 or R.flags.f_contiguous or g.size == 0:
        return linalg.solve_triangular(R, g, lower=False, check_finite=False)
    x, info = _TRTRS(R.T, g, overwrite_b=False, lower=True, trans=True, unitdiag=False)
    if info > 0:
        raise linalg.LinAlgError(f"singular matrix: resolution failed at diagonal {info-1}")
    if info < 0:
        raise ValueError(f"illegal value in {-info}-th argument of internal trtrs")
    return x
