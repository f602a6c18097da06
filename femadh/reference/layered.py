"""Surface compliance of an axisymmetric layered elastic half-space (Burmister problem).

An independent judge for a layered surface operator: a stack of perfectly bonded isotropic
layers on an isotropic half-space, loaded by a frictionless normal pressure p(r) on z = 0.
Conventions are those of :mod:`femadh.elastic.green`: SI units, body in z <= 0, p > 0 pushes
into the body and the returned displacement w is then positive.

Hankel space
------------
With p(r) = int p̄(k) J0(kr) k dk, p̄(k) = int p(r) J0(kr) r dr, the surface displacement is

    w(r) = int_0^inf G(k) p̄(k) J0(kr) k dk,       homogeneous: G(k) = 2 / (E* k),

E* = E/(1 - nu^2). G (m/Pa) is what :meth:`LayeredHalfSpace.compliance_k` returns.

Layer stiffness (derived here; the static limit of the stiffness-matrix method of Kausel &
Roësset 1981, "Stiffness matrices for layered soils", BSSA 71:1743)
------------------------------------------------------------------------------------------
Write u_r = U(z) J1(kr), u_z = W(z) J0(kr), sigma_rz = T(z) J1(kr), sigma_zz = N(z) J0(kr).
Navier's equations become  mu U'' - (lam+2mu) k^2 U - (lam+mu) k W' = 0  and
(lam+2mu) W'' - mu k^2 W + (lam+mu) k U' = 0, whose solutions, with zeta = kz, s = +-1 and
kappa = 3 - 4 nu, are

    (U, W) = (1, -s) e^{s zeta}   and   (U, W) = (zeta, kappa - s zeta) e^{s zeta}.

Their tractions are (T, N)/(2 mu k) = (s, -1) e^{s zeta} and
(s zeta - (1 - 2nu), 2(1 - nu) s - zeta) e^{s zeta}. A layer of thickness h (x = kh), with zeta
measured from its mid-plane, splits into a mode with U even / W odd ("s") and one with U odd /
W even ("a"); eliminating the two amplitudes of each gives the 2x2 stiffness of the top face
(traction per displacement), in units of 2 k:

    S_s = mu / (kappa sinh x - x) [[n2 (cosh x - 1), x - n1 sinh x], [., n2 (cosh x + 1)]]
    S_a = mu / (kappa sinh x + x) [[n2 (cosh x + 1), -x - n1 sinh x], [., n2 (cosh x - 1)]]

with n1 = 1 - 2nu, n2 = 2(1 - nu). The 4x4 layer stiffness (top dofs, bottom dofs) is
[[S_s + S_a, (S_s - S_a) P], [P (S_s - S_a), P (S_s + S_a) P]] / 2 with P = diag(1, -1) (the
mirror z -> -z). The substrate half-space (decaying solutions only) has the top-face stiffness
S_sub = mu/kappa [[n2, -n1], [-n1, n2]]; for this S the frictionless surface compliance is
(S^-1)_zz / (2k) = (1 - nu)/(mu k) = 2/(E* k).

Numerical form. Two condensations of a layer onto what lies below (stiffness S_below):

* k h >= 1: S_top = S_tt - S_tb (S_bb + S_below)^-1 S_bt (static condensation) with every
  hyperbolic function multiplied by 2 e^{-x}, so only e^{-x}, e^{-2x} appear and nothing
  overflows for any kh; the small-x cancellations are removed analytically
  (kappa sinh x - x = 2 n1 sinh x + (sinh x - x), x - n1 sinh x = 2 nu x - n1 (sinh x - x),
  sinh x - x from its series), so nu = 0.5 (n1 = 0) is evaluated like any other nu.
* k h < 1: the propagator exp(A x) of the first-order system d/dzeta (U, W, T/2k, N/2k) =
  A (U, W, T/2k, N/2k); since (A^2 - I)^2 = 0 it is the cubic c0 I + c1 A + c2 A^2 + c3 A^3
  in A with hyperbolic coefficients, close to I here, and
  S_top = (P_21 + P_22 S_below)(P_11 + P_12 S_below)^-1. The stiffness route would lose
  log10(1/kh) digits here (3 log10(1/kh) at nu = 0.5): a thin layer's stiffness ~ mu/h is
  condensed onto one ~ mu k.

The two routes are independent derivations and agree to ~1e-13 where both are accurate. The
stack is condensed from the substrate upwards, one 2x2 operation per layer and wavenumber.

Quadrature of the Hankel integrals
----------------------------------
G is split into the top layer's half-space and a remainder, G = 2/(E*_top k) + dG(k);
the first part is integrated in closed form (:func:`femadh.elastic.green.disk_displacement`,
:func:`femadh.reference.hertz.hertz_displacement`), and dG decays like (k t)^2 e^{-2 k t_top}
(the top layer shields the surface from what lies below). k dG is finite at k = 0
(-> 2/E*_sub - 2/E*_top), so the remainder integrand is smooth and is integrated with
Gauss-Legendre panels on [0, k_max]. k_max is where |k dG| has fallen below
``cutoff_tol`` x 2/E*_top (scanned once per stack on k t_top <= 80; ~20/t_top for the
default 1e-14). Panels are ``panel_width`` x pi/(a + r_max) wide (one period of the fastest
oscillation of J1(ka) J0(kr) for the default 2), and the first one is graded dyadically
towards k = 0, where dG changes on the stack's longest lengths (e.g. the bending length of a
stiff layer on a soft one). Number of k nodes ~ 16 (20/t_top)(a + r_max)/(2 pi) + 16 x 24.
"""
from dataclasses import dataclass
from functools import cached_property
import math

import numpy as np
from scipy import special

from .disk import uniform_disk_displacement as _half_space_disk
from .hertz import hertz_displacement as _half_space_hertz

# Below this x = kh the sinh(x) - x series is used (its 12 terms are exact to round-off there).
_SERIES_LIMIT = 1.0
# Layers with k h below this are condensed with the propagator exp(A kh), above with the
# stiffness matrix (growth of the propagator stays below e there; both agree to round-off).
_PROPAGATOR_LIMIT = 1.0
# Memory cap for one block of a J0(k r) table (entries).
_BLOCK_ENTRIES = 2_000_000


def plane_strain_modulus(e, nu):
    """E* = E / (1 - nu^2) (Pa) of one material."""
    return e / (1.0 - nu * nu)


def _scaled_sinh_excess(x):
    """2 e^{-x} (sinh x - x) without cancellation or overflow (x >= 0, dimensionless)."""
    x = np.asarray(x, float)
    small = x < _SERIES_LIMIT
    out = np.empty_like(x)
    xs = x[small]
    # sinh x - x = sum_{n>=1} x^(2n+1)/(2n+1)!: 12 terms leave < 1e-30 relative at x = 1
    term, series = xs**3 / 6.0, np.zeros_like(xs)
    for n in range(1, 13):
        series += term
        term = term * xs * xs / ((2 * n + 2) * (2 * n + 3))
    out[small] = 2.0 * np.exp(-xs) * series
    xl = x[~small]
    # for x >= 1 the direct form loses at most one digit (1 - e^{-2} vs 2 e^{-1})
    out[~small] = -np.expm1(-2.0 * xl) - 2.0 * xl * np.exp(-xl)
    return out


def _sym(a, b, c):
    """Stack the symmetric 2x2 matrices [[a, b], [b, c]] into shape (..., 2, 2)."""
    a, b, c = np.broadcast_arrays(a, b, c)
    return np.stack([np.stack([a, b], -1), np.stack([b, c], -1)], -2)


def _inv2(m):
    """Inverse of a stack of 2x2 matrices (..., 2, 2) by the adjugate (no pivoting needed:
    every matrix inverted here is symmetric positive definite)."""
    a, b, c, d = m[..., 0, 0], m[..., 0, 1], m[..., 1, 0], m[..., 1, 1]
    det = a * d - b * c
    return np.stack([np.stack([d, -b], -1), np.stack([-c, a], -1)], -2) / det[..., None, None]


def layer_mode_stiffness(x, mu, nu):
    """Top-face stiffnesses S_s, S_a (Pa, i.e. traction per displacement / (2k)) of one layer.

    Parameters
    ----------
    x : ndarray
        k h (dimensionless), > 0.
    mu, nu : float
        Shear modulus (Pa) and Poisson ratio of the layer.

    Returns
    -------
    s_sym, s_anti : ndarray (..., 2, 2)
        The mode with U even/W odd about the mid-plane, and the one with U odd/W even; dofs
        ordered (U, W). See the module docstring; both are written with 2 e^{-x} scaling.
    """
    n1, n2, kappa = 1.0 - 2.0 * nu, 2.0 * (1.0 - nu), 3.0 - 4.0 * nu
    e1 = np.exp(-x)
    one_minus_e1 = -np.expm1(-x)          # 1 - e^{-x}, exact for small x
    one_minus_e2 = -np.expm1(-2.0 * x)    # 2 e^{-x} sinh x
    excess = _scaled_sinh_excess(x)       # 2 e^{-x} (sinh x - x)
    d_sym = 2.0 * n1 * one_minus_e2 + excess          # 2 e^{-x} (kappa sinh x - x)
    d_anti = kappa * one_minus_e2 + 2.0 * x * e1      # 2 e^{-x} (kappa sinh x + x)
    s_sym = _sym(n2 * one_minus_e1**2,                 # 2 e^{-x} n2 (cosh x - 1)
                 4.0 * nu * x * e1 - n1 * excess,      # 2 e^{-x} (x - n1 sinh x)
                 n2 * (1.0 + e1) ** 2) * (mu / d_sym)[..., None, None]
    s_anti = _sym(n2 * (1.0 + e1) ** 2,
                  -(2.0 * x * e1 + n1 * one_minus_e2),
                  n2 * one_minus_e1**2) * (mu / d_anti)[..., None, None]
    return s_sym, s_anti


def half_space_stiffness(mu, nu):
    """Top-face stiffness of a half-space below z = 0 (Pa, traction per displacement / (2k)).

    Returns the 2x2 matrix mu/kappa [[2(1-nu), -(1-2nu)], [-(1-2nu), 2(1-nu)]], dofs (U, W).
    """
    kappa = 3.0 - 4.0 * nu
    return mu / kappa * _sym(2.0 * (1.0 - nu), -(1.0 - 2.0 * nu), 2.0 * (1.0 - nu))


def _mirror(m, rows=False, cols=False):
    """m with the W row and/or W column negated: P m, m P or P m P with P = diag(1, -1)."""
    m = m.copy()
    if rows:
        m[..., 1, :] *= -1.0
    if cols:
        m[..., :, 1] *= -1.0
    return m


def _condense_by_stiffness(s_below, x, mu, nu):
    """S_top = S_tt - S_tb (S_bb + S_below)^-1 S_bt: exact to round-off for x >= 1."""
    s_sym, s_anti = layer_mode_stiffness(x, mu, nu)
    s_tt = 0.5 * (s_sym + s_anti)
    s_tb = _mirror(0.5 * (s_sym - s_anti), cols=True)
    s_bb = _mirror(s_tt, rows=True, cols=True)
    s_bt = np.swapaxes(s_tb, -1, -2)
    return s_tt - s_tb @ _inv2(s_bb + s_below) @ s_bt


def state_matrix(mu, nu):
    """A (4x4) of d/d(kz) (U, W, tau, eta) = A (U, W, tau, eta), (tau, eta) = (T, N)/(2k).

    From sigma_rz = mu (u_r,z + u_z,r), sigma_zz = lam div u + 2 mu u_z,z and the two
    equilibrium equations. Its minimal polynomial is (A^2 - I)^2 (solutions e^{+-kz},
    kz e^{+-kz}).
    """
    c = 1.0 / (1.0 - nu)
    return np.array([[0.0, 1.0, 2.0 / mu, 0.0],
                     [-nu * c, 0.0, 0.0, (1.0 - 2.0 * nu) * c / mu],
                     [mu * c, 0.0, 0.0, nu * c],
                     [0.0, 0.0, -1.0, 0.0]])


def layer_propagator(x, mu, nu):
    """exp(A x) (..., 4, 4): the layer's state at its top from the state at its bottom.

    Because (A^2 - I)^2 = 0, exp(A x) = c0 I + c1 A + c2 A^2 + c3 A^3 with the Hermite
    interpolant of e^{lambda x} at lambda = +-1: c0 = cosh x - x sinh x / 2,
    c1 = (3 sinh x - x cosh x)/2, c2 = x sinh x / 2, c3 = (x cosh x - sinh x)/2. Used for
    x < 1 only, where it is near the identity and free of cancellation.
    """
    x = np.asarray(x, float)[..., None, None]
    ch, sh = np.cosh(x), np.sinh(x)
    a1 = state_matrix(mu, nu)
    a2 = a1 @ a1
    return ((ch - 0.5 * x * sh) * np.eye(4) + 0.5 * (3.0 * sh - x * ch) * a1
            + 0.5 * x * sh * a2 + 0.5 * (x * ch - sh) * (a2 @ a1))


def _condense_by_propagator(s_below, x, mu, nu):
    """S_top = (P21 + P22 S_below)(P11 + P12 S_below)^-1 with P = exp(A x) (x < 1)."""
    prop = layer_propagator(x, mu, nu)
    u_top = prop[..., :2, :2] + prop[..., :2, 2:] @ s_below
    t_top = prop[..., 2:, :2] + prop[..., 2:, 2:] @ s_below
    return t_top @ _inv2(u_top)


def condense_layer(s_below, x, mu, nu):
    """Top-face stiffness (Pa, per 2k) of a layer bonded onto a body of stiffness ``s_below``.

    Thick (x = kh >= 1): static condensation of the layer's stiffness matrix, written with
    decaying exponentials only. Thin (x < 1): the propagator exp(A x), which is near the
    identity there, whereas condensing a stiffness ~ mu/(kh) would lose log10(1/kh) digits
    (and ~ 3 log10(1/kh) for nu = 0.5).

    Parameters
    ----------
    s_below : ndarray (..., 2, 2)
        Stiffness (Pa, per 2k) of what lies below the layer, dofs (U, W).
    x : ndarray
        k h of the layer (dimensionless), > 0.
    mu, nu : float
        Layer shear modulus (Pa) and Poisson ratio.
    """
    x = np.asarray(x, float)
    s_below = np.broadcast_to(s_below, x.shape + (2, 2))
    out = np.empty(x.shape + (2, 2))
    thin = x < _PROPAGATOR_LIMIT
    out[thin] = _condense_by_propagator(s_below[thin], x[thin], mu, nu)
    out[~thin] = _condense_by_stiffness(s_below[~thin], x[~thin], mu, nu)
    return out


def _as_material(e, nu, what):
    e, nu = float(e), float(nu)
    if not e > 0:
        raise ValueError(f"{what}: Young's modulus must be > 0 Pa, got {e}")
    if not -1.0 < nu <= 0.5:
        raise ValueError(f"{what}: Poisson ratio must be in (-1, 0.5], got {nu}")
    return e, nu


@dataclass(frozen=True)
class LayeredHalfSpace:
    """Bonded elastic layers on an elastic half-space under frictionless normal pressure.

    Parameters
    ----------
    layers : sequence of (thickness, E, nu)
        Top layer first; thickness (m) > 0, Young's modulus E (Pa) > 0, -1 < nu <= 0.5.
        May be empty (homogeneous half-space).
    substrate : (E, nu)
        The half-space below the last layer.
    panel_points : int
        Gauss-Legendre points per k panel.
    panel_width : float
        Width of the uniform k panels as a fraction of pi / (a + r_max).
    grading_levels : int
        Number of dyadic panels that grade the first uniform panel towards k = 0.
    cutoff_tol : float
        The remainder k dG(k) is integrated up to where it has decayed below
        cutoff_tol * 2/E*_top (relative to the top layer's own k G).
    """

    layers: tuple
    substrate: tuple
    panel_points: int = 16
    panel_width: float = 2.0
    grading_levels: int = 24
    cutoff_tol: float = 1e-14

    def __post_init__(self):
        layers = tuple((float(t),) + _as_material(e, nu, f"layer {i}")
                       for i, (t, e, nu) in enumerate(self.layers))
        if any(not t > 0 for t, _, _ in layers):
            raise ValueError("layer thicknesses must be > 0 m")
        object.__setattr__(self, "layers", layers)
        object.__setattr__(self, "substrate", _as_material(*self.substrate, "substrate"))
        if (self.panel_points < 2 or not self.panel_width > 0 or not self.cutoff_tol > 0
                or self.grading_levels < 0):
            raise ValueError("need panel_points >= 2, panel_width > 0, cutoff_tol > 0 and "
                             "grading_levels >= 0")

    # ---- moduli -----------------------------------------------------------------------
    @property
    def e_star_top(self):
        """E* (Pa) of the surface material (top layer, or the substrate if there is none)."""
        e, nu = (self.layers[0][1:] if self.layers else self.substrate)
        return plane_strain_modulus(e, nu)

    @property
    def e_star_substrate(self):
        """E* (Pa) of the substrate half-space."""
        return plane_strain_modulus(*self.substrate)

    @property
    def depth(self):
        """Total thickness D of the layers (m)."""
        return sum(t for t, _, _ in self.layers)

    # ---- Hankel-space compliance ------------------------------------------------------
    def reduced_compliance(self, k):
        """k G(k) (1/Pa): 2/E* for a homogeneous half-space; finite at k = 0 (2/E*_sub).

        Parameters
        ----------
        k : array_like
            Wavenumbers (1/m), >= 0.
        """
        k = np.asarray(k, float)
        if np.any(k < 0):
            raise ValueError("wavenumbers must be >= 0")
        kp = np.where(k > 0, k, 1.0)  # placeholder at k = 0, replaced by the limit below
        e_sub, nu_sub = self.substrate
        s = np.broadcast_to(half_space_stiffness(e_sub / (2 * (1 + nu_sub)), nu_sub),
                            kp.shape + (2, 2))
        for t, e, nu in reversed(self.layers):
            s = condense_layer(s, kp * t, e / (2.0 * (1.0 + nu)), nu)
        # frictionless surface: w̄ = (S^-1)_zz p̄ / (2k), so k G = (S^-1)_zz / 2
        kg = 0.5 * s[..., 0, 0] / (s[..., 0, 0] * s[..., 1, 1] - s[..., 0, 1] * s[..., 1, 0])
        return np.where(k > 0, kg, 2.0 / self.e_star_substrate)

    def compliance_k(self, k):
        """Surface normal compliance G(k) (m/Pa) in Hankel space: w̄(k) = G(k) p̄(k).

        Parameters
        ----------
        k : array_like
            Wavenumbers (1/m), >= 0 (G = inf at k = 0).
        """
        k = np.asarray(k, float)
        with np.errstate(divide="ignore"):
            return self.reduced_compliance(k) / k

    def excess_reduced_compliance(self, k):
        """k dG(k) = k G(k) - 2/E*_top (1/Pa): what the stack adds to the top layer's own
        half-space; -> 2/E*_sub - 2/E*_top at k = 0, ~ e^{-2 k t_top} for k t_top >> 1."""
        return self.reduced_compliance(k) - 2.0 / self.e_star_top

    # ---- quadrature -------------------------------------------------------------------
    @cached_property
    def k_cutoff(self):
        """Wavenumber (1/m) beyond which |k dG| < cutoff_tol * 2/E*_top (0 if dG == 0)."""
        if not self.layers:
            return 0.0
        t_top = self.layers[0][0]
        x = np.linspace(0.0, 80.0, 1601)[1:]  # dG ~ (k t)^m e^{-2 k t}: 80 is far beyond need
        excess = np.abs(self.excess_reduced_compliance(x / t_top))
        above = np.nonzero(excess > self.cutoff_tol * 2.0 / self.e_star_top)[0]
        if above.size == 0:
            return 0.0
        # one scan step past the last node above tolerance
        return float(x[min(above[-1] + 1, x.size - 1)] / t_top)

    def k_nodes(self, length):
        """Gauss-Legendre nodes and weights (1/m) on [0, k_cutoff] for the remainder integral.

        Panels of width w = panel_width * pi / length above w (J1(ka) J0(kr) oscillates with
        period 2 pi / (a + r) at most); below w, dyadic panels [w 2^-(j+1), w 2^-j],
        j < grading_levels, and [0, w 2^-grading_levels]: dG changes on the scale of every
        length of the stack, including bending lengths t (E_layer/E_below)^(1/3) >> t of stiff
        layers on soft ones, and a feature at k0 has width ~ k0, so a panel [k0/2, k0] resolves it.

        Parameters
        ----------
        length : float
            a + r_max (m).

        Returns
        -------
        k, weights : ndarray
            Empty when the stack has no remainder.
        """
        k_max = self.k_cutoff
        if k_max == 0.0:
            return np.zeros(0), np.zeros(0)
        width = min(self.panel_width * math.pi / length, k_max)
        n_uniform = math.ceil(k_max / width - 1e-9)
        uniform = np.linspace(width, k_max, n_uniform)
        dyadic = width * 0.5 ** np.arange(self.grading_levels, 0, -1)
        edges = np.concatenate([[0.0], dyadic, uniform])
        xg, wg = np.polynomial.legendre.leggauss(self.panel_points)
        half = 0.5 * np.diff(edges)
        mid = 0.5 * (edges[1:] + edges[:-1])
        k = (mid[:, None] + half[:, None] * xg[None, :]).ravel()
        weights = (half[:, None] * wg[None, :]).ravel()
        return k, weights

    def _remainder(self, r, load_k, length):
        """int_0^inf dG(k) p̄(k) J0(k r) k dk = int k dG(k) p̄(k) J0(k r) dk at radii r (m).

        ``load_k(k)`` returns p̄(k) per unit pressure with shape (n_k, n_loads); the result
        has shape (r.size, n_loads). Blocks over k keep the J0 table below _BLOCK_ENTRIES.
        """
        k, wts = self.k_nodes(length)
        out = 0.0
        step = max(1, _BLOCK_ENTRIES // max(r.size, 1))
        # with no remainder (k empty) the single empty block gives zeros of the right shape
        for i in range(0, max(k.size, 1), step):
            kb, wb = k[i:i + step], wts[i:i + step]
            weighted = (wb * self.excess_reduced_compliance(kb))[:, None] * load_k(kb)
            out = out + special.j0(r[:, None] * kb[None, :]) @ weighted
        return out

    # ---- physical-space displacements -------------------------------------------------
    def disk_displacement(self, r, a, p=1.0):
        """Surface displacement w(r) (m) under a uniform pressure p (Pa) on the disk r <= a.

        Parameters
        ----------
        r : array_like
            Observation radii (m).
        a : float
            Disk radius (m), >= 0.
        p : float
            Pressure (Pa), positive into the body (w > 0).
        """
        r = np.asarray(r, float)
        a = float(a)
        w = _half_space_disk(r, a, self.e_star_top, p)
        if a == 0.0:
            return w
        rem = self._remainder(r.ravel(), lambda k: disk_transform(k, a)[:, None],
                              a + float(np.max(r, initial=0.0)))
        return w + p * rem[:, 0].reshape(r.shape)

    def annulus_compliance(self, nodes, edges):
        """C_ij = w at node i (m) per unit pressure (Pa) on annulus [e_j, e_j+1].

        Directly comparable with ``GreenOperator(grid, e_star).compliance`` for a RadialGrid.

        Parameters
        ----------
        nodes : array_like, shape (N,)
            Collocation radii (m).
        edges : array_like, shape (N+1,)
            Annulus edges (m), increasing.
        """
        nodes, edges = np.asarray(nodes, float), np.asarray(edges, float)
        disks = _half_space_disk(nodes[:, None], edges[None, :], self.e_star_top)
        length = float(edges.max() + nodes.max())
        # one disk per edge (p̄ = 0 for the edge at r = 0)
        rem = self._remainder(nodes, lambda k: disk_transform(k[:, None], edges[None, :]),
                              length)
        return np.diff(disks + rem, axis=1)

    def hertz_displacement(self, r, a, p0):
        """Surface displacement w(r) (m) under the Hertz pressure p0 sqrt(1 - r^2/a^2), r <= a.

        Parameters
        ----------
        r : array_like
            Observation radii (m).
        a : float
            Contact radius (m), > 0.
        p0 : float
            Peak pressure (Pa).
        """
        r = np.asarray(r, float)
        a = float(a)
        w = _half_space_hertz(r.ravel(), a, p0, self.e_star_top)
        rem = self._remainder(r.ravel(), lambda k: hertz_transform(k, a, 1.0)[:, None],
                              a + float(np.max(r, initial=0.0)))
        return (w + p0 * rem[:, 0]).reshape(r.shape)


def disk_transform(k, a, p=1.0):
    """Hankel transform p̄(k) = p a J1(ka)/k (Pa m^2) of a uniform pressure p on r <= a."""
    k = np.asarray(k, float)
    b = k * a
    # J1(b)/b -> 1/2 at b = 0
    ratio = np.where(b > 0, special.j1(b) / np.where(b > 0, b, 1.0), 0.5)
    return p * a * a * ratio


def hertz_transform(k, a, p0):
    """Hankel transform (Pa m^2) of the Hertz pressure p0 sqrt(1 - r^2/a^2) on r <= a.

    Sonine's integral gives p̄(k) = p0 a^2 (sin b - b cos b)/b^3 with b = ka, i.e.
    p0 a^2 j1(b)/b; at b = 0 it is p0 a^2/3 (total force 2 pi p0 a^2/3 = 2 pi p̄(0)).

    Parameters
    ----------
    k : array_like
        Wavenumbers (1/m), >= 0.
    a : float
        Contact radius (m).
    p0 : float
        Peak pressure (Pa).
    """
    b = np.asarray(k, float) * a
    out = np.empty_like(b)
    small = b < 0.5
    bs = b[small]
    # (sin b - b cos b)/b^3 = sum_{n>=1} (-1)^(n+1) 2n b^(2n-2)/(2n+1)!: the closed form
    # cancels like b^3 for small b; 10 terms are exact to round-off for b < 0.5
    term, series = np.full_like(bs, 1.0 / 3.0), np.zeros_like(bs)
    for n in range(1, 11):
        series += term
        term = -term * bs * bs * (n + 1) / (n * (2 * n + 2) * (2 * n + 3))
    out[small] = series
    bl = b[~small]
    out[~small] = (np.sin(bl) - bl * np.cos(bl)) / bl**3
    return p0 * a * a * out
