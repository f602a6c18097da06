"""The trailing Cholesky kept as its single-precision factor (two triangular solves per
preconditioner application, no inverse), and the landing descent's damped Hessian factorised
in place.

Judged independently: the energy Hessian at a state's gaps (numpy's eigvalsh for positive
definiteness, not a Cholesky) against the factor's solves and the blocks it covers; the
collocation equations of the corrector's states re-evaluated here; a checkpoint's
preconditioner against the one it was written from, bit for bit; the matrices the descent
factorises against the Hessian rebuilt here."""
import math

import numpy as np
import pytest

from femadh.contact import complementarity as cm
from femadh.contact.complementarity import DISK_MARGIN_FRACTION
from femadh.contact import landing
from femadh.contact.linalg import TrailingCholesky, TrailingLU, disk_size

from conftest import FIG4_TOL as TOL, fig4_problem, fig4_sweeps

#: the Fig 4 disk on uniform nodes with more than KRYLOV_MIN_FREE free nodes around both folds
#: (as tests/test_newton.py): the Krylov path reaches the contact states
N = 240


@pytest.fixture(scope="module")
def fig4():
    p = fig4_problem(N)
    ap, re = fig4_sweeps(p)
    krylov = [s for s in ap.states + re.states
              if isinstance(s.lu, TrailingCholesky) and s.active.any()]
    return p, krylov


def _lambda_min(p, h, free):
    return float(np.linalg.eigvalsh(p.energy_hessian(h, free))[0])


def _factor(p, st, h=None):
    """The trailing Cholesky the corrector builds for state ``st`` (its margin, its held
    nodes at D = 0), at gaps h (default: the state's)."""
    h = st.h if h is None else h
    m = disk_size(st.active)
    m0 = max(0, m - max(4, int(DISK_MARGIN_FRACTION * p.grid.n)))
    # (the contact nodes held: their law stiffness left out, as the corrector enters them)
    return TrailingCholesky(p.S_sym, p.areas, np.where(st.active, 0.0, p.law_jacobian(h)), m0)


def test_the_kept_factor_solves_every_covered_free_block_of_a_state(fig4):
    """At each contact state the Krylov steps reached, the factor built at its gaps covers
    its free block, and its two single-precision triangular solves meet the Hessian of the
    free block from m, m + 1 and m + 5 (the contact released by 0, 1, 5 nodes) to single
    precision (measured residual <= 2.5e-6 of the right-hand side; allowed 2.5e-5, 10x:
    Hessians of condition 660-1540)."""
    p, krylov = fig4
    assert len(krylov) >= 4     # contact states on both branches (measured: 6)
    rng = np.random.default_rng(11)
    worst = 0.0
    for st in krylov:
        m = disk_size(st.active)
        pre = _factor(p, st)
        for mm in (m, m + 1, m + 5):
            free = np.zeros(p.grid.n, bool)
            free[mm:] = True
            assert _lambda_min(p, st.h, free) > 0 and pre.covers(mm)
            H = p.energy_hessian(st.h, free)
            r = rng.standard_normal(H.shape[0])
            x = pre.solve(mm, r)
            assert x.dtype == np.float64
            worst = max(worst, float(np.max(np.abs(H @ x - r)) / np.max(np.abs(r))))
    assert worst <= 2.5e-5, worst


def test_krylov_states_meet_the_collocation_equations(fig4):
    """The states re-evaluated here (K w, P, C from the problem, not the corrector's own
    products): contact nodes on the floor with a compressive contact pressure
    p_c = P - K w >= 0, free nodes above it, and max |w - C (P - p_c)| within the tolerance."""
    p, krylov = fig4
    for st in krylov:
        A = st.active
        h = p.contour(st.d) - st.w
        P = p.pressure(h)
        pc = np.where(A, P - p.K @ st.w, 0.0)
        assert np.all(np.abs(h[A] - p.sigma) <= 1e-9 * p.sigma)
        assert np.all(h[~A] >= p.sigma * (1 - 1e-12))
        assert np.all(pc[A] >= 0)
        assert float(np.max(np.abs(st.w - p.C @ (P - pc)))) <= TOL


def test_a_free_block_softer_than_its_edge_node_is_not_covered(fig4):
    """The free block of a contact state with its first free node m moved to the gap where
    the LJ law softens fastest: the node's softening area_m |P'| exceeds its own stiffness
    S_mm (measured 1.95x on this grid, at h = 0.231 nm), so the free block from m is
    indefinite (the Hessian's smallest eigenvalue), while the block from m + 1 - untouched -
    stays positive definite. The factor at those gaps covers the block from m + 1 and not
    the one from m (its positive definite extent, read off LAPACK's pivot, carried through
    the kept single-precision factor), and refuses to solve it."""
    p, krylov = fig4
    st = krylov[len(krylov) // 2]
    m, free = disk_size(st.active), ~st.active
    scan = np.linspace(0.17e-9, 1e-9, 2000)
    h_soft = float(scan[np.argmin(p.dpressure(scan))])
    h = st.h.copy()
    h[m] = h_soft
    soft = -p.areas[m] * float(p.dpressure(np.array([h_soft]))[0])
    assert soft > 1.5 * p.S_sym[m, m]
    assert _lambda_min(p, h, free) < 0
    free_after = free.copy()
    free_after[m] = False
    assert _lambda_min(p, h, free_after) > 0
    pre = _factor(p, st, h)
    assert not pre.covers(m) and pre.covers(m + 1)
    with pytest.raises(ValueError, match="not covered"):
        pre.solve(m, np.ones(N - m))


def test_a_checkpointed_preconditioner_solves_bit_for_bit(fig4, tmp_path):
    """What runner.checkpoint writes of a Krylov state's preconditioner (its kept factor) is
    read back into one whose solves equal the original's to the last bit (a resumed sweep
    continues as the uninterrupted one)."""
    from types import SimpleNamespace

    from femadh.runner.checkpoint import load_checkpoint, save_checkpoint

    p, krylov = fig4
    st = krylov[-1]
    m = disk_size(st.active)
    st.lu.solve(m, np.ones(N - m))          # the kept factor exists before it is written
    folder = SimpleNamespace(path=tmp_path)
    sink = SimpleNamespace(writer=object(), last_state=(3, "approach", st), problem=p,
                           peak=None)             # no peak bracket held yet
    save_checkpoint(folder, sink)
    back = load_checkpoint(tmp_path, 3, st.d)
    assert isinstance(back.lu, TrailingCholesky)
    rng = np.random.default_rng(2)
    for mm in (m, m + 1, N - 5):
        r = rng.standard_normal(N - mm)
        assert np.array_equal(back.lu.solve(mm, r), st.lu.solve(mm, r))


def test_the_landing_descent_factorises_the_damped_hessian_it_means(monkeypatch):
    """Each trial damping of the descent factorises H + lam diag(S) with H the energy
    Hessian at the iterate - the damping of an earlier trial not carried over, H itself
    not overwritten - checked by a spy on the factorisation against H rebuilt here, on the
    Fig 4 disk's jump-in (N = 120: measured 26 factorisations for 20 Hessians, so some steps
    took a second damping)."""
    p = fig4_problem(120)
    seen = []
    real = landing.cho_factor

    def spy(M, **kw):
        seen.append(np.array(M))
        return real(M, **kw)
    hess = []
    real_h = p.energy_hessian

    def spy_h(h, free=None):
        H = real_h(h, free)
        hess.append((H, np.array(H), free))
        return H
    monkeypatch.setattr(landing, "cho_factor", spy)
    monkeypatch.setattr(p, "energy_hessian", spy_h)
    d = 1.105e-9
    w0 = np.zeros(p.grid.n)
    landing._lm_descent(p, d, w0, p.sigma, max_iter=40)
    assert len(seen) > len(hess) >= 2       # some steps took more than one damping
    sdiag = np.diag(p.S_sym)
    k = 0
    for H, H_copy, free in hess:
        assert np.array_equal(H, H_copy)    # the Hessian itself was not damped or factorised
    # every factorised matrix is one of the Hessians plus a multiple of diag(S) on its nodes
    for M in seen:
        while k < len(hess):
            H, _, free = hess[k]
            if M.shape == H.shape:
                off = M - H
                lam = off[0, 0] / sdiag[free][0]
                # the damped diagonal to the round-off of its sum (a few ulps of H_ii)
                roundoff = 8 * np.finfo(float).eps * np.abs(np.diag(H))
                if np.all(np.abs(np.diag(off) - lam * sdiag[free]) <= roundoff) and \
                        np.array_equal(off - np.diag(np.diag(off)), np.zeros_like(off)):
                    break
            k += 1
        assert k < len(hess)


def _close(dw, ref):
    return float(np.max(np.abs(dw - ref)) / np.max(np.abs(ref)))


def test_the_lu_steps_solve_the_collocation_jacobian(fig4):
    """The corrector's LU steps against numpy's dense solve of the collocation Jacobian
    (K + diag P'(h)) restricted to the free nodes, at the contact states: a disk's (at these
    states the trailing LU's pivoting leaves the disk uncovered - measured on all 6 - and
    the general LU takes it) and a contact set that is not a disk. Each Newton step meets
    numpy's to 1e-9 of its size (measured <= 4.3e-17: LU solves of matrices of condition
    550-690)."""
    p, krylov = fig4
    n = p.grid.n
    args = (math.inf, math.inf, TOL, cm.CHORD_RATE)
    worst = 0.0
    for st in krylov:
        h = st.h
        D = p.law_jacobian(h)
        F = p.K @ st.w - p.pressure(h)
        m = disk_size(st.active)

        def newton_step(A):
            I = ~A
            return np.linalg.solve((p.K + np.diag(D))[np.ix_(I, I)], -F[I])
        A = np.zeros(n, bool)
        A[:m] = True
        dw, _, _, _, _, nf = cm._lu_step(p, h, A, ~A, m, F[~A], None, None, False, *args)
        assert nf >= 1
        worst = max(worst, _close(dw, newton_step(A)))
        # the disk and one node in the free annulus
        B = A.copy()
        B[m + 20] = True
        dwb, _, lub_I, _, _, nfb = cm._lu_step(p, h, B, ~B, None, F[~B], None, None, False,
                                               *args)
        assert nfb == 1 and np.array_equal(lub_I, ~B)
        worst = max(worst, _close(dwb, newton_step(B)))
    assert worst <= 1e-9, worst


def test_a_trailing_lu_solves_each_block_it_covers():
    """One trailing LU of K + D (the Fig 4 disk, a stiffening law D = 1e-3 K_kk on every
    node: no pivot leaves its block) solves the trailing blocks from m0, m0 + 3 and
    m0 + 100 - leading blocks of its reversed factor, kept in LAPACK's order - as numpy's
    dense solve of each block does, to 1e-9 (measured <= 3.2e-15)."""
    p = fig4_problem(N)
    D = 1e-3 * np.diag(p.K)
    m0 = 30
    lu = TrailingLU(p.K, D, m0, p.areas)
    rng = np.random.default_rng(4)
    for m in (m0, m0 + 3, m0 + 100):
        assert lu.covers(m)
        r = rng.standard_normal(N - m)
        ref = np.linalg.solve(p.K[m:, m:] + np.diag(D[m:]), r)
        assert _close(lu.solve(m, r), ref) <= 1e-9
