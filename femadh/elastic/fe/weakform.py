"""Axisymmetric linear elasticity in (r, z) for scikit-fem: material constants, strains, the
r-weighted bilinear form, and the stresses of a displacement field."""
import math

import numpy as np


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


def axisymmetric_divergence():
    """Bilinear form b(u, q) = int q div(u) 2 pi r dr dz, div u = e_rr + e_zz + e_tt
    (u: displacement trial field, q: scalar pressure test field)."""
    from skfem import BilinearForm

    @BilinearForm
    def form(u, q, w):
        r = w.x[0]
        e = _strains(u, r)
        return 2 * math.pi * r * q * (e[0] + e[1] + e[2])

    return form


def axisymmetric_mass():
    """Bilinear form m(p, q) = int p q 2 pi r dr dz of a scalar field."""
    from skfem import BilinearForm

    @BilinearForm
    def form(p, q, w):
        return 2 * math.pi * w.x[0] * p * q

    return form


def projected_volumetric(ubasis, pbasis, elements):
    """The volumetric part of the mixed (displacement, discontinuous pressure) formulation with
    the pressure eliminated element by element.

    The pressure-like field p = lambda P(div u), P the r-weighted L2 projection onto the
    discontinuous space of ``pbasis`` on each element, makes the volumetric energy
    lambda int P(div u) P(div v) 2 pi r = lambda (B u)^T M^-1 (B v), with B the divergence
    coupling and M the (element-block-diagonal) pressure mass matrix. With a stable pair (P2 +
    cubic bubble displacements, P1 discontinuous pressure) this does not lock as lambda/mu
    grows, unlike lambda int div u div v on plain P2.

    Parameters
    ----------
    ubasis : skfem Basis
        Vector displacement basis restricted to ``elements``.
    pbasis : skfem Basis
        Discontinuous scalar basis (e.g. ElementTriP1DG) on the whole mesh.
    elements : ndarray of int
        The elements of the region.

    Returns
    -------
    B : sparse (n_p, n_u)
        int q div(u) 2 pi r on the region (rows of other elements are zero).
    M_inv : sparse (n_p, n_p)
        Inverse of the region's pressure mass matrix, block by block (zero elsewhere).
    """
    from scipy.sparse import coo_matrix
    from skfem import Basis

    pb = Basis(pbasis.mesh, pbasis.elem, elements=elements, quadrature=ubasis.quadrature)
    B = axisymmetric_divergence().assemble(ubasis, pb).tocsr()
    M = axisymmetric_mass().assemble(pb).tocsr()
    dofs = pbasis.element_dofs[:, elements].T                 # (n_el, n_loc)
    n_loc = dofs.shape[1]
    blocks = np.empty((dofs.shape[0], n_loc, n_loc))
    for i in range(n_loc):
        for j in range(n_loc):
            blocks[:, i, j] = np.asarray(M[dofs[:, i], dofs[:, j]]).ravel()
    inv = np.linalg.inv(blocks)
    rows = np.repeat(dofs, n_loc, axis=1).ravel()
    cols = np.tile(dofs, (1, n_loc)).ravel()
    M_inv = coo_matrix((inv.ravel(), (rows, cols)), shape=M.shape).tocsr()
    return B, M_inv


def surface_pressure_form(pressure=None):
    """Linear form of a normal pressure on the surface z = 0: int p(r) v_z 2 pi r dr over the
    facets of a FacetBasis (v the vector test field; p > 0 pulls the surface up, +z).

    ``pressure``: a callable p(r) (Pa, r in m) or None for p = 1 (per Pa)."""
    from skfem import LinearForm

    @LinearForm
    def form(v, w):
        r = w.x[0]
        p = 1.0 if pressure is None else pressure(r)
        return 2 * math.pi * r * p * v[1]

    return form


def surface_facet_basis(mesh, element, facets, degree=0):
    """FacetBasis of ``element`` on ``facets`` whose quadrature integrates the surface load
    exactly: the trace of the element (degree maxdeg) times r times a pressure polynomial of
    ``degree``."""
    from skfem import FacetBasis

    return FacetBasis(mesh, element, facets=facets, intorder=element.maxdeg + 1 + degree)


def annulus_load_matrix(basis, columns, n_columns):
    """Consistent nodal forces (N per Pa) of a unit pressure on groups of surface facets.

    Parameters
    ----------
    basis : skfem FacetBasis
        On the loaded surface facets (:func:`surface_facet_basis`).
    columns : ndarray of int
        Per facet of ``basis``: its column (the pressure annulus it lies in).
    n_columns : int

    Returns
    -------
    scipy.sparse.csr_matrix (basis.N, n_columns)
        Column j: int N_i v_z 2 pi r over the facets of column j, i.e. the load vector of
        unit pressure there; built from the facet-by-facet contributions of
        :func:`surface_pressure_form` (the element's own trace, so a changed element changes
        the load with it).
    """
    from scipy.sparse import coo_matrix

    local = surface_pressure_form().elemental(basis)
    rows = local.indices[0]
    nf = basis.nelems
    # skfem lays the contributions out shape function by shape function, facets inside
    cols = np.tile(np.asarray(columns), rows.size // nf)
    B = coo_matrix((local.data, (rows, cols)), shape=(basis.N, n_columns)).tocsr()
    B.eliminate_zeros()
    return B
