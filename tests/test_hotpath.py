"""The contact solve's hot path without scipy's wrappers gives scipy's bits (branch hotpath).

femadh.contact.linalg calls LAPACK getrf/getrs/trtrs directly where the corrector called
scipy.linalg.lu_factor/lu_solve/solve_triangular (which call those same routines), adds to a
matrix diagonal through a strided view, and ContactProblem sums the laws without the zeros
and checks them finite by the mask's own ``all``. Each is an identity: compared bit for bit with the
code it replaced, on the cases where the two could part (a sum of finite values that
overflows (no warning, as before), a -0.0, a law that returns a cached array, a Fortran-ordered matrix, a reversed
right-hand side)."""
import warnings

import numpy as np
import pytest
from scipy import linalg as sla

from femadh.contact import linalg as la
from femadh.contact.problem import ContactProblem
from femadh.errors import ConvergenceError


def _bits(a):
    return np.asarray(a).tobytes()


@pytest.mark.parametrize("n", [1, 7, 60])
def test_direct_lapack_lu_gives_scipys_bits(n):
    rng = np.random.default_rng(n)
    K = rng.standard_normal((n, n)) + n * np.eye(n)
    rhs = rng.standard_normal(2 * n)[::-2]          # a reversed, strided right-hand side
    for M in (K, np.asfortranarray(K)):
        ref = sla.lu_factor(M.copy(order="A"), check_finite=False, overwrite_a=True)
        got = la.lu_factor(M.copy(order="A"), overwrite_a=True)
        assert _bits(got[0]) == _bits(ref[0]) and _bits(got[1]) == _bits(ref[1])
        assert _bits(la.lu_solve(got, rhs)) == _bits(sla.lu_solve(ref, rhs, check_finite=False))


def test_direct_lapack_singular_lu_warns_as_scipy():
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        la.lu_factor(np.zeros((3, 3)))
    assert [type(w.message) for w in caught] == [sla.LinAlgWarning]


@pytest.mark.parametrize("n", [1, 7, 60])
def test_direct_lapack_cholesky_gives_scipys_bits(n):
    """The landing's damped descent: potrf/potrs called directly, scipy's cho_factor /
    cho_solve bits (a Fortran copy factorised in place, as the descent does, and a C one)."""
    rng = np.random.default_rng(n)
    A = rng.standard_normal((n, n))
    H = A @ A.T + n * np.eye(n)
    g = rng.standard_normal(2 * n)[::2].copy()
    for M in (H, np.asfortranarray(H)):
        ref = sla.cho_factor(M.copy(order="A"), check_finite=False, overwrite_a=True)
        got = la.cho_factor(M.copy(order="A"), overwrite_a=True)
        assert _bits(got[0]) == _bits(ref[0]) and got[1] == ref[1]
        assert _bits(la.cho_solve(got, g)) == _bits(sla.cho_solve(ref, g, check_finite=False))


def test_direct_lapack_cholesky_refuses_an_indefinite_matrix_as_scipy():
    M = np.diag([1.0, -1.0, 2.0])
    with pytest.raises(sla.LinAlgError, match="2-th leading minor"):
        la.cho_factor(M.copy())
    with pytest.raises(sla.LinAlgError, match="2-th leading minor"):
        sla.cho_factor(M.copy(), check_finite=False)


@pytest.mark.parametrize("k", [2, 5, 12])
def test_back_substitution_gives_solve_triangulars_bits(k):
    # GMRES's R: the leading k x k block of a C-ordered (maxiter + 1) x maxiter array
    rng = np.random.default_rng(k)
    R = np.zeros((13, 12))
    R[:12] = np.triu(rng.standard_normal((12, 12))) + 3 * np.eye(12)
    g = rng.standard_normal(k)
    ref = sla.solve_triangular(R[:k, :k], g, lower=False, check_finite=False)
    assert _bits(la._back_substitute(R[:k, :k], g)) == _bits(ref)


@pytest.mark.parametrize("order", ["C", "F", "strided"])
def test_diagonal_view_adds_as_the_index_arrays_do(order):
    rng = np.random.default_rng(3)
    base = rng.standard_normal((9, 9))
    M = base[::-1, ::-1] if order == "strided" else np.array(base, order=order)
    ref = M.copy()
    d = rng.standard_normal(9)
    ref[np.diag_indices_from(ref)] += d
    view = la.diagonal(M)
    view += d
    assert _bits(M) == _bits(ref)


class _Law:
    """A law returning fixed values (cached: the same array every call)."""

    def __init__(self, values):
        self.values = np.asarray(values, float)

    def pressure(self, h):
        return self.values


def _summed(values_list, h):
    p = ContactProblem.__new__(ContactProblem)
    p.effects = {f"law{i}": _Law(v) for i, v in enumerate(values_list)}
    return p._sum("pressure", h)


def test_law_sum_gives_the_zeros_plus_laws_bits_and_leaves_the_laws_alone():
    h = np.linspace(1e-9, 2e-9, 4)
    v1 = np.array([-0.0, 1.5, -2.0, 3e300])
    v2 = np.array([0.5, -1.5, 2.0, 1e300])
    kept = v1.copy()
    ref1 = np.zeros_like(h)
    ref1 += v1
    got1 = _summed([v1], h)
    assert _bits(got1) == _bits(ref1)           # -0.0 made +0.0, as 0.0 + (-0.0) is
    ref2 = ref1.copy()
    ref2 += v2
    assert _bits(_summed([v1, v2], h)) == _bits(ref2)
    assert _bits(v1) == _bits(kept)             # the first law's (cached) array untouched
    # a law constant in h (one value): broadcast to the nodes, as the zeros it was added to
    ref3 = np.zeros_like(h)
    ref3 += 2.5
    got3 = _summed([2.5], h)
    assert got3.shape == h.shape and _bits(got3) == _bits(ref3)
    got4 = _summed([[2.5]], h)                  # one value in a 1-element array: the same
    assert got4.shape == h.shape and _bits(got4) == _bits(ref3)


def test_finite_check_and_sum_pass_finite_values_whose_sum_overflows_silently():
    v = np.array([1e308, 1e308, 1.0])           # every entry finite, their sum inf
    with warnings.catch_warnings(), np.errstate(all="raise"):
        warnings.simplefilter("error")
        assert ContactProblem._finite("lj", "pressure", v, np.ones(3)) is v
        assert _bits(_summed([v], np.ones(3))) == _bits(v)


@pytest.mark.parametrize("bad", [np.inf, -np.inf, np.nan])
def test_finite_check_names_the_first_node_that_is_not_finite(bad):
    v = np.array([1.0, 2.0, bad, 4.0, bad])
    with pytest.raises(ConvergenceError, match=r"law 'lj': pressure is not finite at node 2"):
        ContactProblem._finite("lj", "pressure", v, np.arange(5.0))


@pytest.mark.parametrize("case", ["empty", "float32", "int", "big-endian", "1x1"])
def test_direct_lapack_routes_other_inputs_to_scipy(case):
    """Inputs the direct calls do not take (an empty system: getrf would call its size an
    illegal argument; float32, int, big-endian: scipy's own dtype handling) give scipy's
    result, dtype and bits; and a contiguous input is left as it was."""
    rng = np.random.default_rng(3)
    K = rng.standard_normal((4, 4)) + 4 * np.eye(4)
    M = {"empty": np.zeros((0, 0)), "float32": K.astype(np.float32),
         "int": np.array([[4, 1], [1, 3]]), "big-endian": K.astype(">f8"),
         "1x1": np.array([[2.5]])}[case]
    keep = M.copy()
    ref = sla.lu_factor(M, check_finite=False)
    got = la.lu_factor(M)
    assert _bits(M) == _bits(keep)
    assert got[0].dtype == ref[0].dtype and _bits(got[0]) == _bits(ref[0])
    assert _bits(got[1]) == _bits(ref[1])
    if M.size:
        b = np.arange(1.0, M.shape[0] + 1)
        b_keep = b.copy()
        x = la.lu_solve(got, b)
        assert _bits(b) == _bits(b_keep)
        assert _bits(x) == _bits(sla.lu_solve(ref, b, check_finite=False))
    # the same inputs made symmetric positive definite, through the Cholesky pair
    S = (M + M.T) if M.size else M
    keep = S.copy()
    ref = sla.cho_factor(S, check_finite=False)
    got = la.cho_factor(S)
    assert _bits(S) == _bits(keep)
    assert got[0].dtype == ref[0].dtype and _bits(got[0]) == _bits(ref[0])
    if S.size:
        b = np.arange(1.0, S.shape[0] + 1)
        assert _bits(la.cho_solve(got, b)) == _bits(sla.cho_solve(ref, b, check_finite=False))


def test_back_substitution_of_a_singular_r_raises_as_scipy():
    R = np.triu(np.ones((4, 4)))
    R[2, 2] = 0.0
    g = np.ones(3)
    with pytest.raises(sla.LinAlgError, match="singular"):
        sla.solve_triangular(R[:3, :3], g, check_finite=False)
    with pytest.raises(sla.LinAlgError, match="singular"):
        la._back_substitute(R[:3, :3], g)


def test_gmres_norm_of_a_strided_right_hand_side_is_its_contiguous_copys():
    """GMRES takes |b| as sqrt(b . b) of a contiguous b (np.linalg.norm's bits): a reversed
    view gives the same iterate as its contiguous copy, bit for bit."""
    rng = np.random.default_rng(5)
    n = 40
    A = rng.standard_normal((n, n)) + 3 * np.sqrt(n) * np.eye(n)
    # (sqrt(b . b) of a reversed view differs from the contiguous copy's in the last bit for
    # ~3 vectors in 4, measured: ten of them)
    for _ in range(10):
        raw = rng.standard_normal(n)
        outs = [la.gmres(lambda v: A @ v, lambda v: v, b, 1e-10, maxiter=n)
                for b in (raw[::-1], np.ascontiguousarray(raw[::-1]))]
        assert _bits(outs[0][0]) == _bits(outs[1][0]) and outs[0][1] == outs[1][1]
