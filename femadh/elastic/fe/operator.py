"""Finite-element surface operator: gmsh mesh + scikit-fem axisymmetric elasticity, condensed
onto the surface nodes of a RadialGrid (same nodes, same annulus pressures as the Green
operator, so the two are comparable like-for-like).

The half-space z <= 0 is truncated at rho = L. On the far arc the displacement is prescribed as
the Boussinesq point-load field scaled by the total load of each load case, which removes the
O(F / (pi E* L)) offset of a fixed boundary down to O(a^2 / L^2). The stiffness is factorised
once (sparse LU, fill-reducing symmetric-mode ordering) and the dense surface compliance
C_ij = w(r_i) per unit pressure on annulus j comes from one batched solve.
"""
from dataclasses import dataclass
import math
import time

import numpy as np
from scipy.sparse.linalg import splu

from ..grid import RadialGrid
from ..operator import SurfaceOperator
from .farfield import boussinesq
from .mesh import MeshSpec, cached_mesh, read_mesh, surface_points_of
from .weakform import axisymmetric_elasticity, lame


@dataclass
class FESettings:
    """Mesh parameters of the FE operator (dimensionless, relative to the grid).

    Attributes
    ----------
    outer_factor : float
        L / a, far-boundary radius over analysis radius.
    growth : float
        Element size growth with distance from the loaded segment.
    surface_fraction : float
        Surface element size as a fraction of the node spacing (1/2: one element per
        node-to-edge interval).
    far_field : str
        ``"boussinesq"``: the arc carries the point-load field scaled by the total load
        (truncation error O(a^2/L^2)); ``"fixed"``: u = 0 there (error O(a/L), for studies).
    """

    outer_factor: float = 1e4
    growth: float = 0.25
    surface_fraction: float = 0.5
    far_field: str = "boussinesq"

    def __post_init__(self):
        if not self.outer_factor > 1:
            raise ValueError(f"outer_factor must be > 1, got {self.outer_factor}")
        if not 0 < self.growth <= 2:
            raise ValueError(f"growth must be in (0, 2], got {self.growth}")
        if not 0 < self.surface_fraction <= 1:
            raise ValueError(f"surface_fraction must be in (0, 1], got {self.surface_fraction}")
        if self.far_field not in ("boussinesq", "fixed"):
            raise ValueError(f"far_field must be 'boussinesq' or 'fixed', got {self.far_field!r}")


def mesh_spec(grid, settings):
    """The half-space mesh of a grid: vertices at its nodes and annulus edges, far boundary at
    outer_factor x the analysis radius, surface elements surface_fraction x the node spacing."""
    return MeshSpec(surface_points_of(grid), settings.outer_factor * grid.radius,
                    settings.growth,
                    settings.surface_fraction * float(np.min(np.diff(grid.nodes))))


class FEOperator(SurfaceOperator):
    """Condensed FE compliance of the axisymmetric half-space on a RadialGrid.

    Parameters
    ----------
    grid : RadialGrid
    e_star : float
        Composite modulus E* (Pa). The FE body has Young's modulus E* (1 - nu^2) and Poisson
        ratio ``nu``: the surface normal compliance of a half-space depends on E/(1-nu^2) only.
    nu : float
        Poisson ratio of the FE body (affects the interior field, not w).
    settings : FESettings, optional
    mesh_path : path, optional
        Use this mesh instead of building/caching one.

    Attributes
    ----------
    compliance, stiffness : ndarray (N, N)
        As for :class:`~femadh.elastic.green.GreenOperator`.
    timings : dict
        Seconds spent in mesh, assembly, factorisation and condensation.
    n_dofs : int
    """

    name = "fe"

    def __init__(self, grid: RadialGrid, e_star, nu=0.3, settings=None, mesh_path=None,
                 progress=None):
        from skfem import Basis, ElementTriP2, ElementVector, MeshTri

        self.grid, self.e_star, self.nu = grid, float(e_star), float(nu)
        self.settings = settings or FESettings()
        self.youngs = self.e_star * (1 - self.nu**2)
        lam, mu = lame(self.youngs, self.nu)
        a = grid.radius
        t = {}
        t0 = time.perf_counter()
        self.spec = mesh_spec(grid, self.settings)
        path = mesh_path or cached_mesh(self.spec, progress=progress)
        p, tri = read_mesh(path, scale=a)
        self.mesh = MeshTri(np.ascontiguousarray(p.T), np.ascontiguousarray(tri.T))
        t["mesh"] = time.perf_counter() - t0

        t0 = time.perf_counter()
        self.basis = Basis(self.mesh, ElementVector(ElementTriP2()))
        K = axisymmetric_elasticity(lam, mu).assemble(self.basis).tocsc()
        B = self._load_matrix()
        t["assembly"] = time.perf_counter() - t0

        L = self.settings.outer_factor * a
        far = self._far_dofs(L)
        axis_r = self._axis_radial_dofs()
        fixed = np.union1d(far, axis_r)
        free = np.setdiff1d(np.arange(self.basis.N), fixed)
        # Dirichlet data per unit total upward force: Boussinesq on the arc, u_r = 0 on the axis
        uD = np.zeros(self.basis.N)
        loc = self.basis.doflocs
        ur, uz = boussinesq(loc[0, far], loc[1, far], self.youngs, self.nu)
        is_r = np.isin(far, self.basis.nodal_dofs[0]) | np.isin(far, self.basis.facet_dofs[0])
        if self.settings.far_field == "boussinesq":
            uD[far] = np.where(is_r, ur, uz)
        self.free, self.fixed, self.uD = free, fixed, uD
        self.K_full, self.B = K, B

        t0 = time.perf_counter()
        Kff = K[free][:, free].tocsc()
        self._lu = splu(Kff, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                        options={"SymmetricMode": True})
        self._Kfd = K[free][:, fixed]
        t["factorisation"] = time.perf_counter() - t0

        t0 = time.perf_counter()
        totals = grid.areas  # total force of a unit pressure on each annulus
        rhs = B[free] - self._Kfd @ (uD[fixed][:, None] * totals[None, :])
        U = self._lu.solve(np.asarray(rhs))
        self.compliance = U[self._surface_rows(), :]
        t["condensation"] = time.perf_counter() - t0
        self.timings = t

    # ------------------------------------------------------------------ set-up helpers
    def _load_matrix(self):
        """Consistent nodal forces (z components) of unit pressure on each annulus (N per Pa).

        Each loaded surface facet lies inside one annulus (the mesh has vertices at every node
        and edge); the P2 trace shape functions times 2 pi r are integrated by 3-point Gauss.
        """
        from scipy.sparse import coo_matrix

        m, b, g = self.mesh, self.basis, self.grid
        fac = m.boundary_facets()
        x = m.p[:, m.facets[:, fac]]  # (2, 2, nf)
        on = (np.abs(x[1, 0]) == 0) & (np.abs(x[1, 1]) == 0)
        ra, rb = x[0, 0, on], x[0, 1, on]
        f_on = fac[on]
        mid = 0.5 * (ra + rb)
        inside = mid < g.radius
        ra, rb, f_on, mid = ra[inside], rb[inside], f_on[inside], mid[inside]
        j = np.searchsorted(g.edges, mid) - 1
        gp, gw = np.polynomial.legendre.leggauss(3)
        s = 0.5 * (gp + 1)
        wq = 0.5 * gw
        shapes = np.stack([(1 - s) * (1 - 2 * s), s * (2 * s - 1), 4 * s * (1 - s)])  # a, b, mid
        length = np.abs(rb - ra)
        rq = ra[:, None] + (rb - ra)[:, None] * s[None, :]
        vals = (shapes[None, :, :] * (2 * math.pi * rq)[:, None, :] * wq).sum(-1) \
            * length[:, None]  # (nf, 3)
        va, vb = m.facets[0, f_on], m.facets[1, f_on]
        dofs = np.stack([b.nodal_dofs[1, va], b.nodal_dofs[1, vb], b.facet_dofs[1, f_on]], 1)
        cols = np.repeat(j[:, None], 3, 1)
        return coo_matrix((vals.ravel(), (dofs.ravel(), cols.ravel())),
                          shape=(b.N, g.n)).tocsr()

    def _far_dofs(self, L):
        m = self.mesh
        fac = m.boundary_facets()
        x = m.p[:, m.facets[:, fac]]
        rho = np.hypot(x[0], x[1])  # (2, nf)
        on = np.all(rho > 0.999 * L, axis=0)
        return self.basis.get_dofs(fac[on]).flatten()

    def _axis_radial_dofs(self):
        m, b = self.mesh, self.basis
        fac = m.boundary_facets()
        x = m.p[:, m.facets[:, fac]]
        on = np.all(x[0] == 0.0, axis=0)
        dofs = b.get_dofs(fac[on])
        return np.concatenate([dofs.nodal["u^1"], dofs.facet["u^1"]])

    def _surface_rows(self):
        """Row of each grid node's vertical displacement in the free-DOF solution.

        Also sets ``surface_vertices``: the mesh vertex of each grid node (nearest surface
        vertex: coordinates come back through the mesh file in units of a, so equality is
        only to round-off; the mesh was built with a vertex at every node).
        """
        p = self.mesh.p
        surf = np.flatnonzero(p[1] == 0.0)
        order = np.argsort(p[0, surf])
        rs = p[0, surf][order]
        k = np.clip(np.searchsorted(rs, self.grid.nodes), 1, rs.size - 1)
        pick = np.where(np.abs(rs[k - 1] - self.grid.nodes) <= np.abs(rs[k] - self.grid.nodes),
                        k - 1, k)
        self.surface_vertices = surf[order][pick]
        gap = np.max(np.abs(p[0, self.surface_vertices] - self.grid.nodes))
        if gap > 1e-9 * self.grid.radius:
            raise ValueError(f"mesh has no vertex at a grid node (off by {gap:.3g} m): the mesh "
                             f"does not belong to this grid")
        where = np.searchsorted(self.free, self.basis.nodal_dofs[1, self.surface_vertices])
        return where

    # ------------------------------------------------------------------ interface
    def full_field(self, pressure):
        """Displacement DOF vector (m) of the whole mesh under annulus pressures (Pa)."""
        total = float(self.grid.areas @ pressure)
        u = self.uD * total
        rhs = self.B[self.free] @ pressure - self._Kfd @ u[self.fixed]
        u[self.free] = self._lu.solve(np.asarray(rhs).ravel())
        return u

    @property
    def n_dofs(self):
        return self.basis.N
