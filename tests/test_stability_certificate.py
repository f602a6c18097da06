"""The stability certificate (femadh.contact.stability.ElasticCertificate) says "stable" only
where the energy Hessian is positive definite with the stated margin, and the decision of
``is_stable`` is the Cholesky's on every state of a Fig 4 sweep, folds included.

The judge is independent of the certificate: the generalised eigenvalues of (H_II, S_II) by
LAPACK's dense symmetric eigensolver. Certified means H_II >= (1 - CERT_LIMIT) S_II, i.e. the
smallest generalised eigenvalue >= 1 - CERT_LIMIT = 0.1.
"""
import numpy as np
import pytest
from scipy import linalg

from femadh.contact import stability
from femadh.contact.stability import CERT_LIMIT, ElasticCertificate, is_positive_definite

from conftest import FIG4_TOL, fig4_problem, fig4_sweeps


def _generalised_min(problem, h, m):
    """Smallest eigenvalue mu of H_II x = mu S_II x on the trailing block m..n-1."""
    H = problem.energy_hessian(h, np.arange(problem.grid.n) >= m)
    S = problem.S_sym[m:, m:]
    return float(linalg.eigh(H, S, eigvals_only=True, subset_by_index=[0, 0])[0])


@pytest.fixture(scope="module")
def fig4():
    """The Fig 4 problem on 220 uniform nodes, its certificate, and every state of its
    approach and retract through both folds with the free-node count of each."""
    p = fig4_problem(220)
    ap, re = fig4_sweeps(p)
    states = ap.states + re.states + [j.before for j in ap.jumps + re.jumps]
    return p, ElasticCertificate(p.S_sym), states


def _softening(problem, h, m):
    """The certificate's input: max(-area P', 0) on nodes m..n-1, reversed."""
    D = problem.areas[m:] * problem.dpressure(h[m:])
    return np.maximum(-D[::-1], 0.0)


def test_certificate_is_an_upper_bound_on_the_softening_eigenvalue(fig4):
    """Scale each state's softening e by s: the exact lambda_max(E^1/2 S^-1 E^1/2) is s times
    the state's. For every s where the certificate answers yes, s lambda_max < CERT_LIMIT
    (it is a bound, never an estimate); it answers yes for the weak softenings (s small: it is
    not vacuous) and no at s lambda_max >= CERT_LIMIT."""
    p, cert, states = fig4
    yes = 0
    for st in states[::3]:
        m = int(st.active.sum())
        e = _softening(p, st.h, m)
        k = e.size
        Sk = p.S_sym[m:, m:][::-1, ::-1]
        lam = float(linalg.eigh(np.diag(e), Sk, eigvals_only=True,
                                subset_by_index=[k - 1, k - 1])[0])
        assert lam > 0
        for s in np.array([0.01, 0.3, 0.7, 0.95, 1.0, 1.05]) * (CERT_LIMIT / lam):
            ok = cert.certifies(s * e)
            assert not ok or s * lam < CERT_LIMIT, (m, s * lam)
            yes += ok
        assert cert.certifies(0.01 * CERT_LIMIT / lam * e)
    assert yes >= len(states[::3])


def test_the_trace_part_is_the_diagonal_of_the_inverse_elastic_block(fig4):
    """trace(M_RR) = sum_i e_i (S_II^-1)_ii, with S_II^-1 from a dense inverse of the trailing
    block itself (not from the full factor's cumulated squares): equal to round-off
    (measured relative difference 1.8e-15 at most; tolerance 2e-14, about ten times that)
    for every free-set size and block."""
    p, cert, states = fig4
    rng = np.random.default_rng(7)
    n = p.grid.n
    for m in (0, 17, 60, 150):
        k = n - m
        Sk = p.S_sym[m:, m:][::-1, ::-1]
        dinv = np.diag(np.linalg.inv(Sk))
        e = rng.uniform(0, 1, k) * np.diag(Sk)
        for b in (1, 8, 64):
            exact = float(e[:k - b] @ dinv[:k - b])
            assert cert.tail(e, b) == pytest.approx(exact, rel=2e-14, abs=0)


def test_certificate_with_a_small_edge_block_stays_a_bound(fig4, monkeypatch):
    """With an edge block of 8 nodes most of the softening enters by the trace of the rest:
    still a bound (it certifies less, never more)."""
    p, cert, states = fig4
    monkeypatch.setattr(stability, "EDGE_BLOCKS", (8,))
    for st in states[::4]:
        m = int(st.active.sum())
        mu = _generalised_min(p, st.h, m)
        for s in (0.2, 0.5, 1.0, 2.0, 4.0):
            e = s * _softening(p, st.h, m)
            if cert.certifies(e):
                H = p.S_sym[m:, m:] - np.diag(e[::-1])
                mu_s = float(linalg.eigh(H, p.S_sym[m:, m:], eigvals_only=True,
                                         subset_by_index=[0, 0])[0])
                assert mu_s >= 1 - CERT_LIMIT - 1e-12, (m, s, mu, mu_s)


def test_is_stable_is_the_cholesky_decision_on_every_state_of_a_fold_sweep(fig4, monkeypatch):
    """Every state of the approach and retract (the last states before both folds included):
    is_stable with the certificate equals the Cholesky of the Hessian; where it certifies, the
    smallest generalised eigenvalue is >= 0.1; it certifies most states (measured 12 of 14 on
    this sweep), and the marginal ones before the folds go to the Cholesky."""
    p, cert, states = fig4
    monkeypatch.setattr(stability, "CERT_BUILD_AFTER", 0)
    certified, mus = 0, []
    for st in states:
        free = ~st.active
        m = int(st.active.sum())
        mu = _generalised_min(p, st.h, m)
        mus.append(mu)
        c = stability.certified_stable(p, st.h, free)
        assert stability.is_stable(p, st.h, free) == is_positive_definite(
            p.energy_hessian(st.h, free))
        if c:
            certified += 1
            assert mu >= 1 - CERT_LIMIT
    assert certified >= 0.7 * len(states)
    # the nearly marginal state before the jump-in was not certified (mu < 0.1)
    assert min(mus) < 1 - CERT_LIMIT


def test_saddles_are_never_certified(monkeypatch):
    """The Tabor mu = 2 smooth sphere (120 nodes, no contact: every node free) traced by
    arclength through its S: the points between the two folds are saddles (the trace's own
    flag), none is certified, and is_stable says unstable; everywhere is_stable equals the
    Cholesky. (Its stable states are not certified either: the LJ softening of a smooth
    sphere at Tabor mu = 2 reaches the elastic stiffness, lambda_max >= CERT_LIMIT.)"""
    from femadh.contact.arclength import trace_curve
    from femadh.studies.smooth_sphere import lj_sphere_problem

    from conftest import HAMAKER, Z0

    monkeypatch.setattr(stability, "CERT_BUILD_AFTER", 0)
    problem, *_ = lj_sphere_problem(2.0, 1e-6, HAMAKER, Z0, 0.4, 120)
    curve = trace_curve(problem, 12 * Z0, -6 * Z0, tol=1e-19, scale=Z0, ds=0.2, ds_max=2.0)
    assert len(curve.folds) == 2
    i1, i2 = (f.index for f in curve.folds)
    free = np.ones(problem.grid.n, bool)
    saddles = 0
    for i, pt in enumerate(curve.points):
        h = problem.contour(pt.d) - pt.w
        c = stability.certified_stable(problem, h, free)
        decision = stability.is_stable(problem, h, free)
        assert decision == is_positive_definite(problem.energy_hessian(h, free))
        if i1 < i <= i2 and not pt.stable:
            saddles += 1
            assert not c and not decision
    assert saddles >= 3


def test_a_certified_state_has_the_margin_on_random_softenings():
    """Random softenings on a 150-node disk (free sets of every size), concentrated at the
    first free node and decaying inward, each scaled so that the exact lambda_max of
    E^1/2 S_II^-1 E^1/2 is x, uniform in [0.5, 1.5] (x > 1: a saddle). A certified state has
    x < 0.9 - the margin H_II >= 0.1 S_II the module states (the literal here, not its
    constant) - so no saddle is ever certified; both answers occur, and the bound is tight
    where the softening sits at the edge (measured: certified up to x = 0.8997, the
    smallest x turned down 0.905)."""
    p = fig4_problem(150)
    cert = ElasticCertificate(p.S_sym)
    rng = np.random.default_rng(3)
    kdiag = np.diag(p.S_sym)
    yes, no = [], []
    for _ in range(80):
        m = int(rng.integers(0, 40))
        k = p.grid.n - m
        decay = np.exp(-np.arange(k) / rng.uniform(1, 20))
        e0 = (kdiag[m:] * decay)[::-1]
        Sk = p.S_sym[m:, m:][::-1, ::-1]
        lam = float(linalg.eigh(np.diag(e0), Sk, eigvals_only=True,
                                subset_by_index=[k - 1, k - 1])[0])
        x = rng.uniform(0.5, 1.5)
        (yes if cert.certifies(x / lam * e0) else no).append(x)
    assert 0.85 < max(yes) < 0.9 and no


def test_refuted_edge_blocks_are_saddles_of_the_elastic_energy():
    """The same random edge softenings, scaled to lambda_max = x in [0.5, 1.5]: where the
    edge-block test refutes positive definiteness, x > 1 (the exact generalised eigenvalue:
    S_II - E has a negative direction) and the Cholesky of S_II - E fails; it refutes some
    (measured: 32 of 80, down to x = 1.0017; the edge block of 128 of up to 150 free nodes
    holds nearly all the softening)."""
    p = fig4_problem(150)
    cert = ElasticCertificate(p.S_sym)
    rng = np.random.default_rng(5)
    kdiag = np.diag(p.S_sym)
    refuted = []
    for _ in range(80):
        m = int(rng.integers(0, 40))
        k = p.grid.n - m
        e0 = (kdiag[m:] * np.exp(-np.arange(k) / rng.uniform(1, 20)))[::-1]
        Sk = p.S_sym[m:, m:][::-1, ::-1]
        lam = float(linalg.eigh(np.diag(e0), Sk, eigvals_only=True,
                                subset_by_index=[k - 1, k - 1])[0])
        x = rng.uniform(0.5, 1.5)
        if cert.refutes(x / lam * e0):
            refuted.append(x)
            assert x > 1
            assert not is_positive_definite(Sk - np.diag(x / lam * e0))
    assert refuted and min(refuted) < 1.1


def test_a_deferred_refresh_covers_what_the_factor_covers(monkeypatch):
    """A Krylov refresh deferred because the Hessian on the free nodes m.. is refuted answers
    covers(m') for every m' as the factorised one does, and where it covers, its kept factor
    is the factorised one's bit for bit (the same arrays, factorised later). Measured: 27 of
    the 30 random softenings refuted, each factor covering a smaller block (k_valid 149-209
    of 161-214 free nodes), so both answers of covers() are compared. A Jacobian that
    stiffens every free node (a positive definite Hessian) is never refuted."""
    from femadh.contact.complementarity import deferred_refresh
    from femadh.contact.linalg import TrailingCholesky

    monkeypatch.setattr(stability, "CERT_BUILD_AFTER", 0)
    p = fig4_problem(220)
    n = p.grid.n
    kdiag = np.diag(p.K)
    rng = np.random.default_rng(11)
    deferred = 0
    for _ in range(30):
        m = int(rng.integers(5, 60))
        A = np.arange(n) < m
        # a law Jacobian softening the free nodes next to the edge by up to 3 x their own
        # stiffness, decaying inward: refuted for the stronger ones
        D = np.zeros(n)
        D[m:] = -rng.uniform(0.2, 3.0) * kdiag[m:] * np.exp(-np.arange(n - m)
                                                            / rng.uniform(1, 8))
        D[:m] = -rng.uniform(0, 3) * kdiag[:m]       # the contact nodes' (held: not used)
        assert not stability.refuted_positive_definite(p, -D, m)
        m0 = max(0, m - 11)
        if not stability.refuted_positive_definite(p, D, m):
            continue
        deferred += 1
        lazy = deferred_refresh(p, D, A, m0, m)
        full = TrailingCholesky(p.S_sym, p.areas, np.where(A, 0.0, D), m0)
        assert not full.covers(m)
        for mm in range(m0, n):
            assert lazy.covers(mm) == full.covers(mm), (m, mm)
        if full.k_valid > 0:
            assert np.array_equal(lazy.kept, full.kept)
    assert deferred >= 20


def test_sweeps_are_bit_identical_with_and_without_the_certificate(monkeypatch):
    """The Fig 4 approach and retract on 220 nodes (folds included), once as femadh runs it
    and once with every stability test a Cholesky and every Krylov refresh factorised: the
    same states to the bit (displacements, contact sets, stability), and the certificate and
    the deferral both acted (measured: 41 of 52 stability tests certified, 30 refreshes
    deferred)."""
    import femadh.contact.linalg as la

    made = {"deferred": 0}
    real_init = la.TrailingCholesky.__init__

    def spy(self, *a, **k):
        made["deferred"] += k.get("not_pd") is not None
        real_init(self, *a, **k)
    monkeypatch.setattr(la.TrailingCholesky, "__init__", spy)
    certified = []
    real_cert = stability.certified_stable

    def cert_spy(*a):
        certified.append(real_cert(*a))
        return certified[-1]
    monkeypatch.setattr(stability, "certified_stable", cert_spy)
    fast = fig4_sweeps(fig4_problem(220))
    monkeypatch.setattr(stability, "certified_stable", lambda *a: False)
    monkeypatch.setattr(stability, "refuted_positive_definite", lambda *a: False)
    import femadh.contact.complementarity as cm
    monkeypatch.setattr(cm, "refuted_positive_definite", lambda *a: False)
    plain = fig4_sweeps(fig4_problem(220))
    for sf, sp in zip(fast, plain):
        assert len(sf.states) == len(sp.states) and len(sf.jumps) == len(sp.jumps)
        for a, b in zip(sf.states, sp.states):
            assert np.array_equal(a.w, b.w) and np.array_equal(a.active, b.active)
            assert a.stable == b.stable and a.d == b.d
    assert sum(certified) >= 30 and made["deferred"] >= 10


def test_a_stiffening_node_is_never_read_as_softening(monkeypatch):
    """Random law Jacobians that soften the edge and stiffen a random half of the free nodes
    (up to 30 x their stiffness): none is refuted (refuted_positive_definite answers only
    where every free node softens). The positive control, the same Jacobians with the
    stiffening dropped (those nodes at D = 0): the refutation fires, and only on Hessians
    the Cholesky rejects - and on many whose true Hessian (with the stiffening) is positive
    definite, which is why the stiffening cannot be dropped. Measured: 0 of 200 refuted; the
    softening alone refuted 180, none positive definite, 44 of them with a positive definite
    true Hessian (64 of the 200 are)."""
    monkeypatch.setattr(stability, "CERT_BUILD_AFTER", 0)
    p = fig4_problem(220)
    n = p.grid.n
    kdiag = np.diag(p.K)
    rng = np.random.default_rng(2)
    definite = control = misread = 0
    for _ in range(200):
        m = int(rng.integers(5, 60))
        k = n - m
        D = np.zeros(n)
        D[m:] = -rng.uniform(0.2, 3.0) * kdiag[m:] * np.exp(-np.arange(k) / rng.uniform(1, 8))
        stiff = rng.random(k) < 0.5
        D[m:][stiff] = rng.uniform(1, 30) * kdiag[m:][stiff]
        pd = is_positive_definite(p.S_sym[m:, m:] + np.diag(p.areas[m:] * D[m:]))
        definite += pd
        assert not stability.refuted_positive_definite(p, D, m)
        soft = np.minimum(D, 0.0)
        if stability.refuted_positive_definite(p, soft, m):
            assert not is_positive_definite(p.S_sym[m:, m:] + np.diag(p.areas[m:] * soft[m:]))
            control += 1
            misread += pd
    assert definite >= 30 and control >= 100 and misread >= 20


def test_no_mask_means_every_node_free(fig4, monkeypatch):
    """free = None (every node free, as energy_hessian reads it): the same decision and the
    same certificate as the all-True mask, on the states without contact."""
    monkeypatch.setattr(stability, "CERT_BUILD_AFTER", 0)
    p, cert, states = fig4
    open_states = [st for st in states if not st.active.any()]
    assert open_states
    for st in open_states:
        every = np.ones(p.grid.n, bool)
        assert stability.certified_stable(p, st.h, None) == \
            stability.certified_stable(p, st.h, every)
        assert stability.is_stable(p, st.h, None) == stability.is_stable(p, st.h, every)


def test_a_deferred_refresh_factorised_later_is_counted(fig4, monkeypatch):
    """A Krylov refresh deferred at one iterate (its free block refuted) and factorised when
    a later solve asks covers() for a smaller free block is that solve's factorisation:
    stats["factorisations"] counts every Cholesky and LU the solve makes. The case: each
    stable disk state of the Fig 4 sweep on 220 nodes with more than KRYLOV_MIN_FREE free
    nodes, solved again from itself with a refresh deferred as if the block one node larger
    were refuted (the same arrays as its own refresh): the first Krylov step factorises it;
    and with the refresh refuted at its own free block: never factorised, the step makes a
    fresh one. Measured: 7 such states, each solve 1 Cholesky and no LU, counted 1 (the
    first: 0 before the count was added)."""
    import femadh.contact.complementarity as cm
    import femadh.contact.linalg as la

    p, _, states = fig4
    n = p.grid.n
    made = {"cholesky": 0, "lu": 0}
    real_fact, real_lu = la.TrailingCholesky._factorise, cm.linalg.lu_factor

    def fact(self, *a):
        made["cholesky"] += 1
        return real_fact(self, *a)

    def lu(*a, **k):
        made["lu"] += 1
        return real_lu(*a, **k)

    # (femadh.contact.linalg.lu_factor: the corrector's own LU and TrailingLU's both call it)
    monkeypatch.setattr(la.TrailingCholesky, "_factorise", fact)
    monkeypatch.setattr(cm.linalg, "lu_factor", lu)
    cases = 0
    for st in states:
        m = la.disk_size(st.active)
        if not (st.stable and m and n - m > cm.KRYLOV_MIN_FREE):
            continue
        D = p.law_jacobian(st.h)
        m0 = max(0, m - max(4, int(cm.DISK_MARGIN_FRACTION * n)))
        # refuted one node out (factorised by the first step's covers(m)), and refuted
        # at m itself (never factorised: the step makes a fresh refresh)
        for refuted_at, factorised in ((m - 1, True), (m, False)):
            lazy = cm.deferred_refresh(p, D, st.active, m0, refuted_at)
            assert lazy.deferred
            made.update(cholesky=0, lu=0)
            stats = {}
            got = cm.solve_complementarity(p, st.d, st.w, tol=FIG4_TOL, max_iter=50,
                                           active0=st.active, factor=lazy, stats=stats)
            assert got.converged
            assert lazy.deferred != factorised and made["cholesky"] >= 1
            assert stats["factorisations"] == made["cholesky"] + made["lu"], (stats, made)
        cases += 1
    assert cases >= 5


def test_the_certificate_build_holds_two_dense_arrays():
    """The certificate keeps R^-1 and its cumulated squares (2 n^2 doubles) and its build
    needs no more at its peak (femadh.scene.resources.GREEN_ARRAYS counts them): peak traced
    memory of ElasticCertificate(sym(S)) on the Fig 4 problem's 600 nodes, in units of
    8 n^2 bytes. Measured 2.000 (3.000 with a squared temporary and its cumulated copy);
    the cumulated squares are np.cumsum(R^-1 * R^-1, axis=1) to the bit."""
    import tracemalloc

    p = fig4_problem(600)
    n = p.grid.n
    S = np.array(p.S_sym)
    tracemalloc.start()
    try:
        cert = ElasticCertificate(S)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert cert.ok
    assert peak / (8.0 * n * n) <= 2.01, peak / (8.0 * n * n)
    assert np.array_equal(cert.q, np.cumsum(cert.rinv * cert.rinv, axis=1))
    assert cert.q.flags.f_contiguous
