"""1D finite-element solution of the axisymmetric Young-Laplace meridian (scikit-fem).

Formulation (regular through the vertical neck): tangent angle psi, radius r and height z as
functions of t in [0, 1] with arc length s = S t,

    psi' = S (kappa - sin(psi) / r),   r' = S cos(psi),   z' = S sin(psi),

psi = pi, z = 0 at t = 0 (tangent to the film-covered flat) and r = sin(phi),
z = z_c - cos(phi), psi = phi at t = 1 (tangent to the film-covered sphere). The arc length S
and the filling angle phi are unknowns of the same Newton system: the contact position is found
as part of the solve.

Discretisation: continuous Galerkin cG(q) for first-order systems: continuous P_q trial
functions, discontinuous P_(q-1) test functions (scikit-fem ElementLineP2 / ElementDG(P1)),
nodally superconvergent of order 2q. scikit-fem provides the mesh, bases and quadrature; the
element integrals of the nonlinear terms are evaluated with einsum on its precomputed basis
values, so a Newton step costs well under a millisecond.
"""
from dataclasses import dataclass
import math

import numpy as np
from scipy import linalg

from ..errors import ConvergenceError, DomainError
from .geometry import Geometry, force_over_2pi


@dataclass
class FESolution:
    phi: float
    S: float
    psi: np.ndarray
    r: np.ndarray
    z: np.ndarray
    n_iter: int
    solver: "MeridianFE"

    def force_contact(self, geo):
        return force_over_2pi(math.sin(self.phi), self.phi, geo.kappa)

    def force_flat(self, geo):
        return -0.5 * geo.kappa * self.r[self.solver.i0] ** 2

    def neck(self, geo):
        """(t, r_n, F/(2 pi gamma R_e) at the neck), or None if psi never reaches pi/2.

        Exact on the P2 interpolant: the element where psi crosses pi/2 is found from the
        nodal values and the local quadratic is solved in closed form.
        """
        s = self.solver
        ts, ps, rs = s.t[s.order], self.psi[s.order], self.r[s.order]
        for k in range(s.n):
            a, m, b = ps[2 * k] - math.pi / 2, ps[2 * k + 1] - math.pi / 2, ps[2 * k + 2] - math.pi / 2
            if a > 0 >= b or (a > 0 and m <= 0) or (m > 0 >= b):
                # Lagrange quadratic on xi in [0, 1] through (0, a), (1/2, m), (1, b)
                c2, c1, c0 = 2 * a - 4 * m + 2 * b, -3 * a + 4 * m - b, a
                roots = np.roots([c2, c1, c0]) if abs(c2) > 1e-300 else np.array([-c0 / c1])
                xi = min(float(x.real) for x in roots
                         if abs(x.imag) < 1e-12 and -1e-12 <= x.real <= 1 + 1e-12)
                ra, rm, rb = rs[2 * k], rs[2 * k + 1], rs[2 * k + 2]
                rn = ra * (1 - xi) * (1 - 2 * xi) + rm * 4 * xi * (1 - xi) + rb * xi * (2 * xi - 1)
                tn = ts[2 * k] + xi * (ts[2 * k + 2] - ts[2 * k])
                return tn, float(rn), force_over_2pi(float(rn), math.pi / 2, geo.kappa)
        return None

    def profile(self):
        """(r, z, psi) at the DOF points, ordered from the flat to the sphere."""
        o = self.solver.order
        return self.r[o], self.z[o], self.psi[o]


class MeridianFE:
    """cG(2) meridian solver on n elements (reusable across solves of a sweep)."""

    def __init__(self, n=32):
        from skfem import Basis, ElementDG, ElementLineP1, ElementLineP2, MeshLine

        self.n = n
        m = MeshLine(np.linspace(0.0, 1.0, n + 1))
        self.U = Basis(m, ElementLineP2(), intorder=6)
        V = Basis(m, ElementDG(ElementLineP1()), intorder=6)
        self.nU, self.nV = self.U.N, V.N
        self.phiU = np.array([np.asarray(b[0]) for b in self.U.basis])       # (iU, e, q)
        self.dphiU = np.array([b[0].grad[0] for b in self.U.basis])
        self.vV = np.array([np.asarray(b[0]) for b in V.basis])              # (jV, e, q)
        self.dx = self.U.dx                                            # (e, q)
        self.eU, self.eV = self.U.element_dofs, V.element_dofs          # (loc, e)
        self.i0 = int(self.U.nodal_dofs[0][0])
        self.i1 = int(self.U.nodal_dofs[0][-1])
        self.t = self.U.doflocs[0]
        self.order = np.argsort(self.t)
        # constant part: int phi_i' v_j (same for all three equations)
        self.D1 = self._assemble(np.ones_like(self.dx), self.dphiU)
        self.M_cache = None

    def _assemble(self, g, trial):
        """Dense (nV, nU) matrix of int g(t) trial_i v_j dt."""
        loc = np.einsum("eq,ieq,jeq,eq->eji", g, trial, self.vV, self.dx)
        A = np.zeros((self.nV, self.nU))
        np.add.at(A, (self.eV.T[:, :, None], self.eU.T[:, None, :]), loc)
        return A

    def _vec(self, g):
        loc = np.einsum("eq,jeq,eq->ej", g, self.vV, self.dx)
        b = np.zeros(self.nV)
        np.add.at(b, self.eV.T, loc)
        return b

    def _at_q(self, c):
        return np.einsum("ieq,ie->eq", self.phiU, c[self.eU])

    def initial_from_circle(self, geo, phi, rho):
        alpha = (math.pi - phi) * self.t
        rcc = (1 + rho) * math.sin(phi)
        return (math.pi - alpha, rcc - rho * np.sin(alpha), rho * (1 - np.cos(alpha)),
                rho * (math.pi - phi), phi)

    def solve(self, geo: Geometry, init, *, tol=1e-13, max_iter=40, phi_max=math.pi / 2):
        psi, r, z, S, phi = (np.array(init[0], float), np.array(init[1], float),
                             np.array(init[2], float), float(init[3]), float(init[4]))
        nU, nV = self.nU, self.nV
        N = 3 * nU + 2
        iS, iP = 3 * nU, 3 * nU + 1
        for it in range(1, max_iter + 1):
            pq, rq = self._at_q(psi), self._at_q(r)
            if np.any(rq <= 0):
                raise ConvergenceError("meniscus FE: the meridian reached the axis (r <= 0)",
                                       n_iter=it)
            sp, cp = np.sin(pq), np.cos(pq)
            f_psi = geo.kappa - sp / rq
            F = np.zeros(N)
            J = np.zeros((N, N))
            F[:nV] = self.D1 @ psi - S * self._vec(f_psi)
            F[nV:2 * nV] = self.D1 @ r - S * self._vec(cp)
            F[2 * nV:3 * nV] = self.D1 @ z - S * self._vec(sp)
            J[:nV, :nU] = self.D1 - S * self._assemble(-cp / rq, self.phiU)
            J[:nV, nU:2 * nU] = -S * self._assemble(sp / rq**2, self.phiU)
            J[nV:2 * nV, nU:2 * nU] = self.D1
            J[nV:2 * nV, :nU] = -S * self._assemble(-sp, self.phiU)
            J[2 * nV:3 * nV, 2 * nU:3 * nU] = self.D1
            J[2 * nV:3 * nV, :nU] = -S * self._assemble(cp, self.phiU)
            J[:nV, iS] = -self._vec(f_psi)
            J[nV:2 * nV, iS] = -self._vec(cp)
            J[2 * nV:3 * nV, iS] = -self._vec(sp)
            b = 3 * nV
            F[b:b + 5] = [psi[self.i0] - math.pi, z[self.i0], r[self.i1] - math.sin(phi),
                          z[self.i1] - (geo.zc - math.cos(phi)), psi[self.i1] - phi]
            J[b, self.i0] = 1.0
            J[b + 1, 2 * nU + self.i0] = 1.0
            J[b + 2, nU + self.i1], J[b + 2, iP] = 1.0, -math.cos(phi)
            J[b + 3, 2 * nU + self.i1], J[b + 3, iP] = 1.0, -math.sin(phi)
            J[b + 4, self.i1], J[b + 4, iP] = 1.0, -1.0
            dX = -linalg.solve(J, F, check_finite=False)
            alpha = 1.0
            while alpha > 1e-4:
                r_new = r + alpha * dX[nU:2 * nU]
                if np.all(self._at_q(r_new) > 0) and S + alpha * dX[iS] > 0:
                    break
                alpha *= 0.5
            psi += alpha * dX[:nU]
            r += alpha * dX[nU:2 * nU]
            z += alpha * dX[2 * nU:3 * nU]
            S += alpha * dX[iS]
            phi += alpha * dX[iP]
            step = float(np.max(np.abs(dX))) * alpha
            if step < tol and alpha == 1.0:
                if not geo.phi_min < phi <= phi_max:
                    raise DomainError(
                        f"meniscus FE: filling angle {math.degrees(phi):.2f} deg is outside "
                        f"({math.degrees(geo.phi_min):.2f}, {math.degrees(phi_max):.0f}] deg: "
                        "the meniscus foot has passed the sphere's equator (p/psat too close "
                        "to saturation for this radius)")
                return FESolution(phi, S, psi, r, z, it, self)
        raise ConvergenceError(f"meniscus FE: Newton did not converge (last step {step:.3g})",
                               n_iter=max_iter)
