"""Finite-element surface operator: gmsh mesh + scikit-fem axisymmetric elasticity, condensed
onto the surface nodes of a RadialGrid (same nodes, same annulus pressures as the Green
operator, so the two are comparable like-for-like).

The body (:class:`~femadh.elastic.fe.body.FEBody`) is a homogeneous half-space
(:meth:`FEOperator.homogeneous`) or a stack of bonded layers on a substrate half-space
(:meth:`FEOperator.layered`). It is truncated at rho = L, L = outer_factor x max(a, D) (a the
analysis radius, D the stack depth). On the far boundary the displacement is prescribed as the
substrate's Boussinesq point-load field scaled by the total load of each load case: far from
the load and from the stack the layered body responds like the substrate half-space to a point
force (in Hankel space the stack changes k G(k) = 2/E*_sub + O(k D), and an O(k) term is local
to the load), which removes most of the O(F / (pi E* L)) offset of a fixed boundary. Measured
(validation/results/layered_fe.md): 10-15x below the fixed boundary's error while L is
comparable to a stiff plate's bending length (error still ~ 1/L there), at the mesh floor from
L = 1e3 max(a, D); the default is 1e4.

The operator is built in steps, each a method: :meth:`~FEOperator._read_mesh` (the mesh with
its named boundaries ``surface``, ``axis``, ``far`` and its regions), :meth:`~FEOperator._assemble`
(stiffness per region; the surface load through a FacetBasis on the loaded ``surface`` facets),
:meth:`~FEOperator._constrain` (Dirichlet DOFs by boundary name: the far field, u_r = 0 on the
axis), :meth:`~FEOperator._factorise` (sparse LU of the free block, fill-reducing
symmetric-mode ordering), :meth:`~FEOperator._locate_surface` (the grid nodes' rows) and
:meth:`~FEOperator._condense` (the dense surface compliance C_ij = w(r_i) per unit pressure on
annulus j, one batched solve).

With layers the pair is no longer one E*: the sphere's own compliance (its homogeneous
half-space Green function on the same nodes and annuli) is added to the FE body's, so the
contact solvers see one compliance C = C_body + C_sphere (C_body alone for a rigid sphere).
"""
import time

import numpy as np
from scipy.sparse.linalg import splu

from ..green import GreenOperator
from ..grid import RadialGrid
from ..operator import SurfaceOperator
from .body import FEBody
from .farfield import boussinesq
from .mesh import cached_mesh, load_mesh
from .settings import (NU_DISPLACEMENT_MAX, NU_LIMIT, SOFT_RATIO, FESettings,
                       layered_surface_size, layers_needing_radial_resolution, mesh_spec)
from .weakform import (annulus_load_matrix, axisymmetric_elasticity, lame,
                       projected_volumetric, surface_facet_basis)

# the settings' names stay importable from here (their home is .settings)
__all__ = ["FEOperator", "FESettings", "mesh_spec", "NU_DISPLACEMENT_MAX", "NU_LIMIT",
           "SOFT_RATIO", "layered_surface_size", "layers_needing_radial_resolution"]


class FEOperator(SurfaceOperator):
    """Condensed FE compliance of an axisymmetric (layered) half-space on a RadialGrid.

    Build it with :meth:`homogeneous` (the composite modulus of the pair, paper 1 eq 2) or
    :meth:`layered` (a layer stack on a substrate, the sphere's own compliance added); both
    take ``cache=True`` to read the condensed compliance from the on-disk operator cache
    (:mod:`~femadh.elastic.fe.cache`).

    Parameters
    ----------
    grid : RadialGrid
    body : FEBody
    settings : FESettings, optional
    mesh_path : path, optional
        Use this mesh instead of building/caching one.
    progress : callable, optional
        Receives a message when a mesh is built.

    Attributes
    ----------
    compliance, stiffness : ndarray (N, N)
        As for :class:`~femadh.elastic.green.GreenOperator` (m/Pa, Pa/m).
    compliance_body, compliance_sphere : ndarray (N, N)
        The FE body's part and the sphere's (zeros for a rigid or homogeneous-E* sphere).
    body : FEBody
    e_star : float
        Homogeneous body only: its composite modulus (Pa).
    youngs, nu : float
        The substrate's Young's modulus (Pa) and Poisson ratio.
    materials : list of (E Pa, nu)
        Per region: layers top first, then the substrate (region id = index).
    region : ndarray of int
        Region id of every mesh triangle.
    formulation : str
        "displacement" or "mixed" (the one used).
    timings : dict
        Seconds spent in mesh, assembly, factorisation and condensation (an operator read
        from the cache: ``cache_read``, and the body's parts once it is built).
    n_dofs : int
    """

    name = "fe"

    def __init__(self, grid: RadialGrid, body: FEBody, settings=None, *, mesh_path=None,
                 progress=None):
        self._prepare(grid, body, settings, mesh_path, progress)
        self._build()
        self._set_compliance(self._condense())

    @classmethod
    def homogeneous(cls, grid, e_star, nu=0.3, settings=None, *, mesh_path=None,
                    progress=None, cache=False, cache_dir=None):
        """The half-space of composite modulus ``e_star`` (Pa): Young's modulus
        E* (1 - nu^2), Poisson ratio ``nu`` (which shapes the interior field, not w).
        ``cache``: through the on-disk operator cache (``cache_dir``, else its default)."""
        body = FEBody.homogeneous(e_star, nu)
        return cls._make(grid, body, settings, mesh_path, progress, cache, cache_dir)

    @classmethod
    def layered(cls, grid, substrate, layers=(), sphere=None, settings=None, *,
                mesh_path=None, progress=None, cache=False, cache_dir=None):
        """The layer stack ``layers`` (Layer or (t m, E Pa, nu), top first) on the
        ``substrate`` half-space; ``sphere`` (a material, or None: rigid) adds its half-space
        Green compliance on the same nodes. ``layers=()``: the bare substrate."""
        body = FEBody.layered(substrate, layers, sphere)
        return cls._make(grid, body, settings, mesh_path, progress, cache, cache_dir)

    @classmethod
    def _make(cls, grid, body, settings, mesh_path, progress, cache, cache_dir):
        if cache:
            from .cache import cached_operator

            op = cls.__new__(cls)
            op._prepare(grid, body, settings, mesh_path, progress)
            return cached_operator(op, progress, cache_dir=cache_dir)
        return cls(grid, body, settings, mesh_path=mesh_path, progress=progress)

    def _prepare(self, grid, body, settings, mesh_path, progress):
        """Everything but the numerics: the body, its formulation, the mesh file."""
        if not isinstance(body, FEBody):
            raise TypeError(f"FEOperator(grid, body): body must be an FEBody, got "
                            f"{type(body).__name__}; use FEOperator.homogeneous(grid, e_star, "
                            f"nu) or FEOperator.layered(grid, substrate, layers, sphere)")
        self.grid = grid
        self.settings = settings or FESettings()
        self.body = body
        self.substrate, self.layers, self.sphere = body.substrate, body.layers, body.sphere
        if body.e_star is not None:
            self.e_star = body.e_star
        self.youngs, self.nu = body.substrate.youngs_modulus, body.substrate.poisson_ratio
        self.materials = body.materials
        self.formulation = body.formulation(self.settings.formulation)
        self.spec = mesh_spec(grid, self.settings, self.layers, self.substrate)
        self._mesh_path = mesh_path or cached_mesh(self.spec, progress=progress)
        self.timings = {}

    #: attributes of the assembled, factorised body: an operator read from the cache
    #: (``cache=True``, :mod:`.cache`) builds them on first use (full fields, VTK, render)
    _BODY = frozenset(("mesh", "region", "basis", "free", "fixed", "uD", "K_full", "B", "_lu",
                       "_Kfd", "surface_vertices", "_pressure", "_pbasis", "_rows",
                       "far_dofs", "axis_dofs"))

    def __getattr__(self, name):
        # only reached when normal lookup fails: a cached operator's body is built lazily
        if name in FEOperator._BODY and not self.__dict__.get("_built", False):
            self._build()
            return getattr(self, name)
        raise AttributeError(f"{type(self).__name__!s} has no attribute {name!r}")

    # ------------------------------------------------------------------ the steps
    def _build(self):
        """The body: mesh, assembly, constraints, factorisation, the surface rows."""
        self._built = True
        self._read_mesh()
        self._assemble()
        self._constrain()
        self._factorise()
        self._locate_surface()

    def _read_mesh(self):
        """The scikit-fem mesh in SI units, its named boundaries and triangle regions."""
        t0 = time.perf_counter()
        path = self._mesh_path
        self.mesh, self.region = load_mesh(path, scale=self.grid.radius)
        if self.region.max() != len(self.layers):
            raise ValueError(f"mesh {path} has {self.region.max()} layers, the body "
                             f"{len(self.layers)}")
        self.timings["mesh"] = time.perf_counter() - t0

    def _assemble(self):
        """Stiffness K (per region) and the load matrix B (N per Pa: column j the nodal
        forces of unit pressure on annulus j)."""
        from skfem import Basis, ElementTriP2, ElementTriP2B, ElementVector

        t0 = time.perf_counter()
        # the mixed formulation needs the cubic bubble for a stable discontinuous P1 pressure
        element = ElementTriP2B() if self.formulation == "mixed" else ElementTriP2()
        self.basis = Basis(self.mesh, ElementVector(element))
        self.K_full = self._stiffness_matrix().tocsc()
        self.B = self._load_matrix()
        self.timings["assembly"] = time.perf_counter() - t0

    def _load_matrix(self):
        """B through a FacetBasis on the loaded part of the named ``surface`` (r < a): each
        facet lies inside one annulus (the mesh has vertices at every node and annulus edge),
        so column j sums the facets of annulus j (:func:`~.weakform.annulus_load_matrix`,
        quadrature exact for the element's trace times r)."""
        m, g = self.mesh, self.grid
        surface = m.boundaries["surface"]
        loaded = surface[m.p[0, m.facets[:, surface]].mean(axis=0) < g.radius]
        fb = surface_facet_basis(m, self.basis.elem, loaded)
        if fb.N != self.basis.N:
            raise RuntimeError("the surface FacetBasis numbers the DOFs unlike the body's")
        # the annulus of each facet in the basis' own order (its midpoint's)
        annulus = np.searchsorted(g.edges, m.p[0, m.facets[:, fb.find]].mean(axis=0)) - 1
        return annulus_load_matrix(fb, annulus, g.n)

    def _constrain(self):
        """Dirichlet DOFs by boundary name: the ``far`` boundary carries the substrate's
        Boussinesq field per unit total upward force (or 0, ``far_field="fixed"``), the
        ``axis`` has u_r = 0."""
        b = self.basis
        self.far_dofs = b.get_dofs("far").flatten()
        axis = b.get_dofs("axis")
        self.axis_dofs = np.concatenate([axis.nodal["u^1"], axis.facet["u^1"]])
        far = self.far_dofs
        self.fixed = np.union1d(far, self.axis_dofs)
        self.free = np.setdiff1d(np.arange(b.N), self.fixed)
        uD = np.zeros(b.N)
        if self.settings.far_field == "boussinesq":
            loc = b.doflocs
            e_sub, nu_sub = self.materials[-1]
            ur, uz = boussinesq(loc[0, far], loc[1, far], e_sub, nu_sub)
            is_r = np.isin(far, b.nodal_dofs[0]) | np.isin(far, b.facet_dofs[0])
            uD[far] = np.where(is_r, ur, uz)
        self.uD = uD

    def _factorise(self):
        """Sparse LU of the free block; the free-fixed coupling for the lift."""
        t0 = time.perf_counter()
        K, free, fixed = self.K_full, self.free, self.fixed
        self._lu = splu(K[free][:, free].tocsc(), permc_spec="MMD_AT_PLUS_A",
                        diag_pivot_thresh=0.0, options={"SymmetricMode": True})
        self._Kfd = K[free][:, fixed]
        self.timings["factorisation"] = time.perf_counter() - t0

    def _locate_surface(self):
        """Row of each grid node's vertical displacement in the free-DOF solution.

        Sets ``surface_vertices``: the mesh vertex of each grid node (the nearest vertex of
        the named ``surface``: coordinates come back through the mesh file in units of a, so
        equality is only to round-off; the mesh was built with a vertex at every node).
        """
        p = self.mesh.p
        surf = np.unique(self.mesh.facets[:, self.mesh.boundaries["surface"]])
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
        self._rows = np.searchsorted(self.free, self.basis.nodal_dofs[1, self.surface_vertices])

    def _condense(self):
        """The body's surface compliance: one batched solve for every annulus' unit
        pressure (the far-field lift scaled by the annulus' total force)."""
        t0 = time.perf_counter()
        totals = self.grid.areas  # total force of a unit pressure on each annulus
        rhs = self.B[self.free] - self._Kfd @ (self.uD[self.fixed][:, None] * totals[None, :])
        U = self._lu.solve(np.asarray(rhs))
        body = U[self._rows, :]
        self.timings["condensation"] = time.perf_counter() - t0
        return body

    def _set_compliance(self, body):
        """C = C_body (+ the sphere's Green compliance on the same nodes)."""
        self.compliance_body = body
        if self.sphere is not None:
            self.compliance_sphere = GreenOperator(self.grid,
                                                   self.sphere.plane_strain_modulus).compliance
            self.compliance = self.compliance_body + self.compliance_sphere
        else:
            self.compliance_sphere = np.zeros_like(self.compliance_body)
            self.compliance = self.compliance_body

    def _stiffness_matrix(self):
        """Global stiffness: each region's material on its own elements.

        Displacement formulation: lambda int div u div v + 2 mu int eps:eps. Mixed: the same
        with div replaced by its element-wise projection on discontinuous P1 (pressure
        eliminated per element, :func:`~.weakform.projected_volumetric`)."""
        from skfem import Basis, ElementTriP1DG

        if len(self.materials) == 1 and self.formulation == "displacement":
            lam, mu = lame(*self.materials[0])
            return axisymmetric_elasticity(lam, mu).assemble(self.basis)
        self._pressure = []   # per region: (elements, lambda, projection M^-1 B) for fields
        pbasis = Basis(self.mesh, ElementTriP1DG()) if self.formulation == "mixed" else None
        K = None
        for rid, (E, nu_r) in enumerate(self.materials):
            elements = np.flatnonzero(self.region == rid)
            lam, mu = lame(E, nu_r)
            ub = Basis(self.mesh, self.basis.elem, elements=elements)
            if self.formulation == "mixed":
                Kr = axisymmetric_elasticity(0.0, mu).assemble(ub)
                Bdiv, M_inv = projected_volumetric(ub, pbasis, elements)
                proj = (M_inv @ Bdiv).tocsr()
                Kr = Kr + lam * (Bdiv.T @ proj)
                self._pressure.append((elements, lam, proj))
            else:
                Kr = axisymmetric_elasticity(lam, mu).assemble(ub)
            K = Kr if K is None else K + Kr
        self._pbasis = pbasis
        return K

    # ------------------------------------------------------------------ interface
    def full_field(self, pressure):
        """Displacement DOF vector (m) of the whole mesh under annulus pressures (Pa)."""
        total = float(self.grid.areas @ pressure)
        u = self.uD * total
        rhs = self.B[self.free] @ pressure - self._Kfd @ u[self.fixed]
        u[self.free] = self._lu.solve(np.asarray(rhs).ravel())
        return u

    @property
    def field_projector(self):
        """Stress recovery and VTK output nodes (:class:`~.fields.FieldProjector`), built on
        first use and kept: every further state costs sparse products and one solve."""
        if getattr(self, "_field_projector", None) is None:
            from .fields import FieldProjector

            self._field_projector = FieldProjector(self)
        return self._field_projector

    @property
    def n_dofs(self):
        return self.basis.N
