"""One Cholesky per converged state: the stability test of a state the Krylov steps reached is
the preconditioner it carries (complementarity._stable_preconditioner), and the trailing
Cholesky keeps its single-precision factor (two triangular solves, no inverse).

Judged independently: the smallest eigenvalue of the energy Hessian on the free nodes (numpy's
eigvalsh, not a Cholesky) for the stability; the preconditioner's solve against the Hessian
at the state's own gaps; the collocation equations of the state re-evaluated here; a
checkpoint's preconditioner against the one it was written from, bit for bit."""
import numpy as np
import pytest

from femadh.contact import complementarity as cm
from femadh.contact import landing
from femadh.contact.linalg import TrailingCholesky, disk_size
from femadh.contact.stability import is_stable

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


def test_krylov_states_carry_a_preconditioner_built_at_their_own_gaps(fig4):
    """Every contact state the Krylov steps reached is stable by the Hessian's smallest
    eigenvalue, and its preconditioner covers its free block and solves the Hessian at the
    state's gaps to single precision (measured residual <= 1.1e-6 of the right-hand side
    over these states; allowed 1e-5, ~10x: a float32 factor of Hessians with condition
    1.0e3-1.5e3)."""
    p, krylov = fig4
    assert len(krylov) >= 4     # contact states on both branches (measured: 6)
    rng = np.random.default_rng(11)
    worst = 0.0
    for st in krylov:
        m, free = disk_size(st.active), ~st.active
        assert st.stable and _lambda_min(p, st.h, free) > 0
        assert st.lu.covers(m)
        H = p.energy_hessian(st.h, free)
        r = rng.standard_normal(H.shape[0])
        x = st.lu.solve(m, r)
        worst = max(worst, float(np.max(np.abs(H @ x - r)) / np.max(np.abs(r))))
    assert worst <= 1e-5, worst


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


def test_a_state_softer_than_its_edge_node_is_unstable_by_the_same_factorisation(fig4):
    """The free block of a contact state with its first free node m moved to the gap where
    the LJ law softens fastest: the node's softening area_m |P'| exceeds its own stiffness
    S_mm (measured 1.95x on this grid, at h = 0.231 nm), so the free block from m is
    indefinite (the Hessian's smallest eigenvalue), while the block from m + 1 - untouched -
    stays positive definite. The state's one Cholesky reads it unstable and hands on no
    preconditioner, as the separate test does; one node fewer (the block from m + 1) would
    read it stable."""
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
    stable, pre = cm._stable_preconditioner(p, h, st.active)
    assert stable is False and pre is None
    assert is_stable(p, h, free) is False
    # and the state itself, unmodified: stable by both, with a preconditioner that covers it
    stable, pre = cm._stable_preconditioner(p, st.h, st.active)
    assert stable is True and pre.covers(m) and is_stable(p, st.h, free)


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
    sink = SimpleNamespace(writer=object(), last_state=(3, "approach", st), problem=p)
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
    real = landing.sla.cho_factor

    def spy(M, **kw):
        seen.append(np.array(M))
        return real(M, **kw)
    hess = []
    real_h = p.energy_hessian

    def spy_h(h, free=None):
        H = real_h(h, free)
        hess.append((H, np.array(H), free))
        return H
    monkeypatch.setattr(landing.sla, "cho_factor", spy)
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
