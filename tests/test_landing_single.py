"""The landing's damped descent steps solved by conjugate gradients in double precision
preconditioned by a single-precision Cholesky factor kept across trials and steps
(femadh.contact.landing._Damped): every step it takes is the double system's solution, every
trial it refuses is one the double factorisation refuses, and the descent settles on the
double path's minimum, polished to the same landing."""
import numpy as np
import pytest
from scipy import linalg as sla

from femadh.contact import landing
from femadh.contact.forces import state_forces
from femadh.contact.linalg import cho_factor_single, cho_solve_single, pcg

from conftest import FIG4_TOL as TOL


def _single_on(monkeypatch):
    """The single path on the 150-node disk (SINGLE_MIN_NODES is 300 by default: below it the
    factorisation is as cheap as the iterations' overhead, not a question of correctness)."""
    monkeypatch.setattr(landing, "SINGLE_MIN_NODES", 100)


@pytest.fixture(scope="module")
def trials(fig4_jump150):
    """Every trial of the single path's descent of the 150-node jump-in: (H, s, lam, rhs,
    outcome) with the outcome a step, NOT_PD or None, and the descent's result."""
    p, j = fig4_jump150
    seen = []
    real = landing._Damped.solve

    def spy(self, lam, rhs):
        out = real(self, lam, rhs)
        seen.append((self.H.copy(), self.s.copy(), lam, rhs.copy(), out))
        return out
    mp = pytest.MonkeyPatch()
    try:
        _single_on(mp)
        mp.setattr(landing._Damped, "solve", spy)
        w, settled = landing._lm_descent(p, j.d_land, j.before.w, p.sigma)
    finally:
        mp.undo()
    return seen, (w, settled)


def test_every_step_is_the_double_systems_solution(trials):
    """Each step the iterations return solves (H + lam diag(s)) dw = -grad as the double
    factorisation does: measured at most 7.0e-14 apart relative (max norm) over the descent's
    31 steps (OPENBLAS_CORETYPE=SkylakeX; Haswell 1.0e-13, Sandybridge 2.3e-13), where
    SINGLE_RTOL is 1e-13 (tolerance 1e-10: 400x the largest); and it is a descent
    direction."""
    seen, _ = trials
    steps = [t for t in seen if isinstance(t[4], np.ndarray)]
    assert len(steps) >= 10
    for H, s, lam, rhs, x in steps:
        M = H + np.diag(lam * s)
        ref = sla.cho_solve(sla.cho_factor(M), rhs)
        assert np.max(np.abs(x - ref)) <= 1e-10 * np.max(np.abs(ref))
        assert rhs @ x > 0                  # grad . dw < 0


def test_a_refused_trial_is_not_positive_definite(trials):
    """Each trial refused (NOT_PD: a kept factor met non-positive curvature, the only proof
    the single path takes) is one the double factorisation refuses too: the 12 refused damped
    Hessians' least eigenvalues (of diag(s)^-1/2 M diag(s)^-1/2) measured -1.4e-2 ... -6.0e-5,
    far from zero against the ~1e-7 at which single and double precision could disagree; the
    accepted trials' measured >= 9.2e-5 (the same on the three OPENBLAS_CORETYPEs)."""
    seen, _ = trials
    refused = [t for t in seen if t[4] is landing._Damped.NOT_PD]
    assert refused                          # the jump-in slides through indefinite Hessians
    for H, s, lam, rhs, _ in refused:
        M = H + np.diag(lam * s)
        with pytest.raises(sla.LinAlgError):
            sla.cho_factor(M)
    assert not [t for t in seen if t[4] is None]    # no fallback to the double path here


def test_the_descent_settles_on_the_double_paths_minimum(fig4_jump150, trials, monkeypatch,
                                                         cholesky_count):
    """The single path's descent settles where the double path's does, to the energy's
    round-off (measured 1.3e-29 - 5.0e-29 J apart, 1-4 % of its 1.2e-27 J), without a double
    factorisation and with fewer single ones than the double path's factorisations (measured
    28-29 against 43: the kept factor serves the rest). The whole descent (no round-off stop)
    factorises in double, as before."""
    p, j = fig4_jump150
    seen, (w1, s1) = trials
    w0, s0 = landing._lm_descent(p, j.d_land, j.before.w, p.sigma)
    n_double = cholesky_count[0]
    assert s0 and s1
    e0, e1 = p.energy(w0, j.d_land), p.energy(w1, j.d_land)
    assert abs(e1 - e0) <= landing._roundoff(p, w0, e0), (e0, e1)
    count = [0]
    real = landing.cho_factor_single

    def counted(*a):
        count[0] += 1
        return real(*a)
    monkeypatch.setattr(landing, "cho_factor_single", counted)
    _single_on(monkeypatch)
    cholesky_count[0] = 0
    landing._lm_descent(p, j.d_land, j.before.w, p.sigma)
    assert cholesky_count[0] == 0
    assert 0 < count[0] < n_double, (count[0], n_double)
    # the whole descent (roundoff off: a lattice-trapped grid, the retry after a failed
    # polish) keeps the double factorisation
    count[0] = 0
    landing._lm_descent(p, j.d_land, j.before.w, p.sigma, roundoff=False, max_iter=10)
    assert count[0] == 0 and cholesky_count[0] > 0


def test_the_polished_landing_is_the_same_state(fig4_jump150, monkeypatch):
    """The landing (descent and Newton polish) with the single path is the double path's:
    the same contact set, the surfaces within 1e-3 of the tolerance (measured 1.2e-24 -
    1.9e-24 m apart: 1.9e-5 of it), F_LJ within 1e-14 relative (measured <= 1.1e-15)."""
    p, j = fig4_jump150
    ref = landing.land(p, j.d_land, j.before.w, tol=TOL, max_iter=40)
    _single_on(monkeypatch)
    st = landing.land(p, j.d_land, j.before.w, tol=TOL, max_iter=40)
    assert ref.converged and ref.stable and st.converged and st.stable
    assert np.array_equal(st.active, ref.active)
    assert np.max(np.abs(st.w - ref.w)) <= 1e-3 * TOL
    assert state_forces(p, st)[2] == pytest.approx(state_forces(p, ref)[2], rel=1e-14, abs=0)


def _spd(n, seed, shift=1.0):
    rng = np.random.default_rng(seed)
    B = rng.standard_normal((n, n))
    return B @ B.T / n + shift * np.eye(n)


def test_the_single_factor_is_the_matrix_to_single_precision():
    """U^T U = H + the damped diagonal to single precision's round-off (measured 1.26e-7 of
    its largest entry on 60 nodes; tolerance 4 ulps of float32: 4.8e-7); its solve to the
    single factor's accuracy (measured 4.8e-7 - 6.0e-7, cond 3.5: tolerance 1e-5); None where
    the matrix is not positive definite; FloatingPointError where it is beyond float32."""
    H = _spd(60, 1)
    d = np.diagonal(H) + 0.5
    u = cho_factor_single(H, d)
    U = np.triu(u).astype(float)
    M = H + 0.5 * np.eye(60)
    assert np.max(np.abs(U.T @ U - M)) <= 4 * np.finfo(np.float32).eps * np.max(np.abs(M))
    x = cho_solve_single(u, M @ np.ones(60))
    assert np.max(np.abs(x - 1)) <= 1e-5
    assert cho_factor_single(H, np.diagonal(H) - 5.0) is None
    with pytest.raises(FloatingPointError):     # beyond float32: the double path decides
        cho_factor_single(H * 1e39, np.diagonal(H) * 1e39)


def test_pcg_solves_and_refuses_what_it_must():
    """Preconditioned CG reaches its relative residual on a positive definite system
    (preconditioned by the single factor of a matrix 30 % off its diagonal: 11 iterations;
    the solution measured 6.2e-15 - 6.5e-15 off relative, cond(A) 4.9 with rtol 1e-13:
    tolerance 1e-12); meets non-positive curvature on an indefinite one (first direction: the
    right-hand side along the negative eigenvector); stops at its budget; and takes a zero
    right-hand side as solved (not as a direction of zero curvature)."""
    A, P = _spd(80, 2), _spd(80, 2, shift=1.3)
    u = cho_factor_single(P, np.diagonal(P))
    b = np.arange(1.0, 81.0)
    x, k, status = pcg(lambda v: A @ v, lambda r: cho_solve_single(u, r), b, 1e-13, 60)
    assert status == "converged" and k < 60
    ref = np.linalg.solve(A, b)
    assert np.max(np.abs(x - ref)) <= 1e-12 * np.max(np.abs(ref))
    lam, V = np.linalg.eigh(A)
    indefinite = A - (lam[0] + 0.5) * np.outer(V[:, 0], V[:, 0])      # eigenvalue -0.5
    _, _, status = pcg(lambda v: indefinite @ v, lambda r: r, V[:, 0], 1e-13, 60)
    assert status == "curvature"
    _, k, status = pcg(lambda v: A @ v, lambda r: r, b, 1e-13, 3)
    assert (k, status) == (3, "budget")
    x, k, status = pcg(lambda v: A @ v, lambda r: r, 0 * b, 1e-13, 3)
    assert (k, status) == (0, "converged") and not x.any()


def test_what_the_single_path_cannot_prove_goes_to_the_double_factorisation():
    """Only a direction of non-positive curvature proves a damped Hessian indefinite. A matrix
    positive definite in double whose condition (1e9) is beyond single precision fails spotrf:
    the trial goes to the double factorisation (None), not "not positive definite" (which
    would raise the damping where the double path takes the step; review of landfast). pcg
    tells a preconditioner's breakdown and a NaN from curvature, and the preconditioner's
    solve is linear down to residuals far below single precision's range (r x 1e-30: a
    float32 cast alone made it 0)."""
    from femadh.contact.linalg import cho_factor_single, cho_solve_single, pcg

    rng = np.random.default_rng(0)
    n = 120
    q, _ = np.linalg.qr(rng.standard_normal((n, n)))
    h = (q * np.geomspace(1e-9, 1.0, n)) @ q.T
    h = (h + h.T) / 2
    sla.cho_factor(h)                                  # positive definite in double
    assert cho_factor_single(h, np.diagonal(h).copy()) is None
    d = landing._Damped(np.ones(n))
    d.step(h, np.ones(n, bool))
    assert d.solve(1e-12, rng.standard_normal(n)) is None
    a = np.diag(np.linspace(1.0, 2.0, n))
    u = cho_factor_single(a, np.diagonal(a).copy())
    r = rng.standard_normal(n)
    assert np.allclose(cho_solve_single(u, r * 1e-30), cho_solve_single(u, r) * 1e-30,
                       rtol=1e-12, atol=0)
    b = rng.standard_normal(n)
    indefinite = np.diag(np.linspace(-1.0, 2.0, n))
    assert pcg(lambda v: indefinite @ v, lambda v: v, b, 1e-13, n)[2] == "curvature"
    assert pcg(lambda v: a @ v, lambda v: -v, b, 1e-13, n)[2] == "breakdown"
    assert pcg(lambda v: a @ v * np.nan, lambda v: v, b, 1e-13, n)[2] == "nan"
    assert pcg(lambda v: a @ v, lambda v: v, b, 1e-13, n)[2] == "converged"
