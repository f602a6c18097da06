"""Axisymmetric linear elasticity in (r, z) for scikit-fem: material constants, strains, the
r-weighted bilinear form, and the stresses of a displacement field."""
import math


def lame(youngs, nu):
    """Lame constants (lambda, mu) (Pa) of Young's modulus E (Pa) and Poisson ratio nu."""
    return youngs * nu / ((1 + nu) * (1 - 2 * nu)), youngs / (2 * (1 + nu))


def axisymmetric_elasticity(lam, mu):
    """Bilinear form of axisymmetric linear elasticity in (r, z), r-weighted (2 pi r dA).

    Strains: e_rr = du_r/dr, e_zz = du_z/dz, e_tt = u_r / r (hoop), e_rz = (du_r/dz + du_z/dr)/2.
    a(u, v) = int sigma(u) : eps(v) 2 pi r dr dz with sigma = lam tr(eps) I + 2 mu eps.
    """
    from skfem import BilinearForm

    @BilinearForm
    def form(u, v, w):
        r = w.x[0]
        eu = _strains(u, r)
        ev = _strains(v, r)
        tr = eu[0] + eu[1] + eu[2]
        s = (lam * tr + 2 * mu * eu[0], lam * tr + 2 * mu * eu[1], lam * tr + 2 * mu * eu[2],
             2 * mu * eu[3])
        return 2 * math.pi * r * (s[0] * ev[0] + s[1] * ev[1] + s[2] * ev[2] + 2 * s[3] * ev[3])

    return form


def _strains(u, r):
    """(e_rr, e_zz, e_tt, e_rz) of a displacement field u = (u_r, u_z) at radii r."""
    g = u.grad
    return g[0, 0], g[1, 1], u[0] / r, 0.5 * (g[0, 1] + g[1, 0])


def stresses(u, r, lam, mu):
    """sigma_rr, sigma_zz, sigma_tt, sigma_rz (Pa) of a displacement field at radii r."""
    e = _strains(u, r)
    tr = e[0] + e[1] + e[2]
    return {"sigma_rr": lam * tr + 2 * mu * e[0], "sigma_zz": lam * tr + 2 * mu * e[1],
            "sigma_tt": lam * tr + 2 * mu * e[2], "sigma_rz": 2 * mu * e[3]}
