"""Finite-element surface operator: gmsh mesh + scikit-fem axisymmetric elasticity, condensed
onto the surface nodes of a RadialGrid (same nodes, same annulus pressures as the Green
operator, so the two are comparable like-for-like).

The body is a homogeneous half-space or a stack of bonded layers on a substrate half-space
(:class:`~femadh.elastic.fe.layers.Layer`). It is truncated at rho = L, L = outer_factor x
max(a, D) (a the analysis radius, D the stack depth). On the far boundary the displacement is
prescribed as the substrate's Boussinesq point-load field scaled by the total load of each load
case: far from the load and from the stack the layered body responds like the substrate
half-space to a point force (in Hankel space the stack changes k G(k) = 2/E*_sub + O(k D), and
an O(k) term is local to the load), which removes most of the O(F / (pi E* L)) offset of a
fixed boundary. Measured (validation/results/layered_fe.md): 10-15x below the fixed boundary's
error while L is comparable to a stiff plate's bending length (error still ~ 1/L there), at the
mesh floor from L = 1e3 max(a, D); the default is 1e4. The stiffness is factorised once (sparse LU,
fill-reducing symmetric-mode ordering) and the dense surface compliance C_ij = w(r_i) per unit
pressure on annulus j comes from one batched solve.

With layers the pair is no longer one E*: the sphere's own compliance (its homogeneous
half-space Green function on the same nodes and annuli) is added to the FE body's, so the
contact solvers see one compliance C = C_body + C_sphere (C_body alone for a rigid sphere).
"""
from dataclasses import dataclass
import math
import time

import numpy as np
from scipy.sparse.linalg import splu

from ...materials import IsotropicMaterial
from ..green import GreenOperator
from ..grid import RadialGrid
from ..operator import SurfaceOperator
from .farfield import boussinesq
from .layers import Layer, as_layer
from .mesh import MeshSpec, cached_mesh, read_mesh, surface_points_of
from .weakform import axisymmetric_elasticity, lame, projected_volumetric

#: above this Poisson ratio of any region, formulation "auto" uses the mixed one (plain P2
#: displacement elements lock in confined nearly incompressible layers)
NU_DISPLACEMENT_MAX = 0.45
#: largest Poisson ratio the FE body accepts (mixed formulation; its pressure is eliminated
#: element by element with a finite lambda, so nu = 0.5 itself is excluded)
NU_LIMIT = 0.49999


@dataclass
class FESettings:
    """Mesh parameters of the FE operator (dimensionless, relative to the grid).

    Attributes
    ----------
    outer_factor : float
        L / max(a, D): far-boundary radius over the larger of the analysis radius a and the
        layer stack depth D (D = 0 for the homogeneous half-space).
    growth : float
        Element size growth with distance from the loaded segment.
    surface_fraction : float
        Surface element size as a fraction of the node spacing (1/2: one element per
        node-to-edge interval).
    far_field : str
        ``"boussinesq"``: the far boundary carries the (substrate's) point-load field scaled by
        the total load (truncation error O(a^2/L^2) homogeneous); ``"fixed"``: u = 0 there
        (error O(a/L), for studies).
    layer_min_elements : int
        Least number of elements through the thickness of any layer.
    layer_radial_elements : float
        Radial surface elements per thickness of the thinnest layer on the loaded segment: the
        surface size is min(surface_fraction x node spacing, t_min / layer_radial_elements) ...
    max_layer_refinement : float
        ... but at most this many times finer than surface_fraction x node spacing (a layer
        much thinner than the node spacing changes the nodal response only through its
        thickness, not through the narrow boundary layers at the annulus edges).
    formulation : str
        ``"displacement"``: P2 displacement elements; ``"mixed"``: P2 + cubic bubble
        displacements with a discontinuous P1 pressure eliminated per element (locking-free
        for nu -> 0.5); ``"auto"``: mixed when a region has nu > NU_DISPLACEMENT_MAX.
    """

    outer_factor: float = 1e4
    growth: float = 0.25
    surface_fraction: float = 0.5
    far_field: str = "boussinesq"
    layer_min_elements: int = 2
    formulation: str = "auto"
    layer_radial_elements: float = 8.0
    max_layer_refinement: float = 8.0

    def __post_init__(self):
        if not self.outer_factor > 1:
            raise ValueError(f"outer_factor must be > 1, got {self.outer_factor}")
        if not 0 < self.growth <= 2:
            raise ValueError(f"growth must be in (0, 2], got {self.growth}")
        if not 0 < self.surface_fraction <= 1:
            raise ValueError(f"surface_fraction must be in (0, 1], got {self.surface_fraction}")
        if self.far_field not in ("boussinesq", "fixed"):
            raise ValueError(f"far_field must be 'boussinesq' or 'fixed', got {self.far_field!r}")
        if not int(self.layer_min_elements) >= 1:
            raise ValueError(f"layer_min_elements must be >= 1, got {self.layer_min_elements}")
        if not (self.layer_radial_elements > 0 and self.max_layer_refinement >= 1):
            raise ValueError("need layer_radial_elements > 0 and max_layer_refinement >= 1")
        if self.formulation not in ("auto", "displacement", "mixed"):
            raise ValueError(f"formulation must be 'auto', 'displacement' or 'mixed', got "
                             f"{self.formulation!r}")


#: a layer whose E/(1 - nu^2) is below this fraction of the material directly beneath it is
#: "soft": it carries the deformation of a pressure step in a boundary layer ~ its thickness
SOFT_RATIO = 0.25


def layers_needing_radial_resolution(layers, substrate=None):
    """Thicknesses (m) of the layers the radial grading rule applies to: soft layers (plane-
    strain modulus < SOFT_RATIO x that of the material directly below) and nearly
    incompressible ones (nu > NU_DISPLACEMENT_MAX). A thickness given without a material, or
    the last layer when the substrate is not given, counts (the conservative choice).

    Stiff or matched layers transmit a pressure step like the homogeneous body, which the
    grid's own surface size resolves (measured: a 10x or 100x stiffer layer, and one 2x softer,
    0.1-0.4 node spacings thick, stay within 3e-4 of the reference unrefined; 100x softer:
    4.3e-3, 0.45 < nu, 100x softer: 1.9e-2).
    """
    out = []
    for i, ly in enumerate(layers):
        if not isinstance(ly, Layer):
            out.append(float(ly))
            continue
        below = layers[i + 1] if i + 1 < len(layers) else substrate
        if below is None or not isinstance(below, (Layer, IsotropicMaterial)):
            out.append(ly.thickness)
            continue
        e_below = below.youngs_modulus / (1 - below.poisson_ratio**2)
        e_here = ly.youngs_modulus / (1 - ly.poisson_ratio**2)
        if e_here < SOFT_RATIO * e_below or ly.poisson_ratio > NU_DISPLACEMENT_MAX:
            out.append(ly.thickness)
    return out


def layered_surface_size(node_size, thicknesses, settings):
    """Element size (m) on the loaded surface inside the layers: the radial grading rule.

    h = clip(t_min / layer_radial_elements, node_size / max_layer_refinement, node_size),
    node_size = surface_fraction x node spacing, t_min the thinnest of ``thicknesses`` (the
    layers :func:`layers_needing_radial_resolution` selects): that layer gets
    ``layer_radial_elements`` elements per thickness along the loaded surface (the response to
    a pressure step in a soft or nearly incompressible layer changes over ~t), but the grid's
    own surface size is refined by at most ``max_layer_refinement``.
    """
    if not len(thicknesses):
        return node_size
    fine = min(thicknesses) / settings.layer_radial_elements
    return float(np.clip(fine, node_size / settings.max_layer_refinement, node_size))


def mesh_spec(grid, settings, layers=(), substrate=None):
    """The body's mesh for a grid: vertices at its nodes and annulus edges, far boundary at
    outer_factor x max(analysis radius, stack depth), surface elements surface_fraction x the
    node spacing (in the layers finer for thin soft ones, :func:`layered_surface_size`);
    ``layers`` (Layer, top first, on ``substrate``; or bare thicknesses in m) become
    interfaces."""
    thick = tuple(float(getattr(x, "thickness", x)) for x in layers)
    node_size = settings.surface_fraction * float(np.min(np.diff(grid.nodes)))
    fine = layered_surface_size(node_size, layers_needing_radial_resolution(layers, substrate),
                                settings)
    return MeshSpec(surface_points_of(grid),
                    settings.outer_factor * max(grid.radius, sum(thick)),
                    settings.growth, node_size, thick, int(settings.layer_min_elements),
                    fine if thick else None)


def _check_nu(nu, what):
    if not nu <= NU_LIMIT:
        raise ValueError(
            f"{what}: Poisson ratio {nu} is above the FE body's limit {NU_LIMIT}: the mixed "
            f"formulation eliminates the pressure with a finite lambda = E nu/((1+nu)(1-2nu)); "
            f"use nu <= {NU_LIMIT} (the incompressible limit is reached to ~(0.5 - nu))")


class FEOperator(SurfaceOperator):
    """Condensed FE compliance of an axisymmetric (layered) half-space on a RadialGrid.

    Two ways to call it:

    * ``FEOperator(grid, e_star, nu=0.3, settings)`` - homogeneous half-space with the
      composite modulus of the pair (paper 1 eq 2): the body has Young's modulus
      E* (1 - nu^2) and Poisson ratio nu (the surface normal compliance of a half-space
      depends on E/(1 - nu^2) only).
    * ``FEOperator(grid, substrate=IsotropicMaterial, layers=[Layer, ...], sphere=...,
      settings=...)`` - the body is the layer stack (top first) on the substrate half-space;
      the sphere's own compliance is its half-space Green function on the same nodes
      (``sphere=None``: rigid sphere). ``layers=[]`` gives a homogeneous substrate body.

    Parameters
    ----------
    grid : RadialGrid
    e_star : float, optional
        Composite modulus E* (Pa) of the homogeneous call.
    nu : float
        Poisson ratio of the homogeneous FE body (affects the interior field, not w).
    settings : FESettings, optional
    mesh_path : path, optional
        Use this mesh instead of building/caching one.
    progress : callable, optional
        Receives a message when a mesh is built.
    substrate : IsotropicMaterial, optional
        The half-space below the layers (layered call).
    layers : sequence of Layer or (thickness m, E Pa, nu)
        Top layer first.
    sphere : IsotropicMaterial or None
        Elastic sphere (its Green compliance is added) or None (rigid).

    Attributes
    ----------
    compliance, stiffness : ndarray (N, N)
        As for :class:`~femadh.elastic.green.GreenOperator` (m/Pa, Pa/m).
    compliance_body, compliance_sphere : ndarray (N, N)
        The FE body's part and the sphere's (zeros for a rigid or homogeneous-E* sphere).
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

    def __init__(self, grid: RadialGrid, e_star=None, nu=0.3, settings=None, mesh_path=None,
                 progress=None, *, substrate=None, layers=(), sphere=None):
        self.grid = grid
        self.settings = settings or FESettings()
        self._set_body(e_star, nu, substrate, layers, sphere)
        self.spec = mesh_spec(grid, self.settings, self.layers, self.substrate)
        self._mesh_path = mesh_path or cached_mesh(self.spec, progress=progress)
        self.timings = {}
        self._build()
        self._set_compliance(self._condense())

    #: attributes of the assembled, factorised body: an operator read from the cache
    #: (:meth:`cached`) builds them on first use (full fields, VTK, render)
    _BODY = frozenset(("mesh", "region", "basis", "free", "fixed", "uD", "K_full", "B", "_lu",
                       "_Kfd", "surface_vertices", "_pressure", "_pbasis"))

    def __getattr__(self, name):
        # only reached when normal lookup fails: a cached operator's body is built lazily
        if name in FEOperator._BODY and not self.__dict__.get("_built", False):
            self._build()
            return getattr(self, name)
        raise AttributeError(f"{type(self).__name__!s} has no attribute {name!r}")

    @classmethod
    def cached(cls, grid, e_star=None, nu=0.3, settings=None, progress=None, *, substrate=None,
               layers=(), sphere=None, cache_dir=None):
        """The operator of these arguments (as the constructor), its condensed compliance read
        from the on-disk operator cache when an identical body was condensed before, else
        built and stored there (:mod:`~femadh.elastic.fe.cache`, keyed by content: the mesh
        file's bytes, the grid, the materials, the settings). A cached operator builds its
        mesh, stiffness and factorisation only when full fields are asked for."""
        from .cache import load_or_build

        return load_or_build(cls, grid, e_star, nu, settings, progress, substrate=substrate,
                             layers=layers, sphere=sphere, cache_dir=cache_dir)

    def _build(self):
        """Read the mesh, assemble the stiffness and load matrices, factorise (the body)."""
        from skfem import Basis, ElementTriP2, ElementTriP2B, ElementVector, MeshTri

        grid, t = self.grid, self.timings
        self._built = True
        a = grid.radius
        t0 = time.perf_counter()
        path = self._mesh_path
        p, tri, region = read_mesh(path, scale=a, regions=True)
        if region.max() != len(self.layers):
            raise ValueError(f"mesh {path} has {region.max()} layers, the body "
                             f"{len(self.layers)}")
        self.mesh = MeshTri(np.ascontiguousarray(p.T), np.ascontiguousarray(tri.T))
        self.region = region
        t["mesh"] = time.perf_counter() - t0

        t0 = time.perf_counter()
        # the mixed formulation needs the cubic bubble for a stable discontinuous P1 pressure
        element = ElementTriP2B() if self.formulation == "mixed" else ElementTriP2()
        self.basis = Basis(self.mesh, ElementVector(element))
        K = self._stiffness_matrix().tocsc()
        B = self._load_matrix()
        t["assembly"] = time.perf_counter() - t0

        L = self.spec.outer_radius
        far = self._far_dofs(L)
        axis_r = self._axis_radial_dofs()
        fixed = np.union1d(far, axis_r)
        free = np.setdiff1d(np.arange(self.basis.N), fixed)
        # Dirichlet data per unit total upward force: the substrate's Boussinesq field on the
        # far boundary, u_r = 0 on the axis
        uD = np.zeros(self.basis.N)
        loc = self.basis.doflocs
        e_sub, nu_sub = self.materials[-1]
        ur, uz = boussinesq(loc[0, far], loc[1, far], e_sub, nu_sub)
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
        self._rows = self._surface_rows()

    def _condense(self):
        """The body's surface compliance: one batched solve for every annulus' unit
        pressure."""
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

    # ------------------------------------------------------------------ the body
    def _set_body(self, e_star, nu, substrate, layers, sphere):
        """Materials per region and the formulation, from either call form."""
        if substrate is None:
            if e_star is None:
                raise ValueError("give e_star (homogeneous half-space) or substrate= "
                                 "(layered body)")
            if layers or sphere is not None:
                raise ValueError("layers and sphere need substrate=: with e_star the pair is "
                                 "one homogeneous composite modulus")
            self.e_star, self.nu = float(e_star), float(nu)
            self.youngs = self.e_star * (1 - self.nu**2)
            self.substrate = IsotropicMaterial(self.youngs, self.nu)
            self.layers, self.sphere = (), None
        else:
            if e_star is not None:
                raise ValueError("give either e_star or substrate=, not both")
            if not isinstance(substrate, IsotropicMaterial):
                substrate = IsotropicMaterial(*substrate)
            self.substrate = substrate
            self.layers = tuple(as_layer(x) for x in layers)
            if sphere is not None and not isinstance(sphere, IsotropicMaterial):
                sphere = IsotropicMaterial(*sphere)
            self.sphere = sphere
            # the homogeneous call's attributes, here for the substrate
            self.youngs, self.nu = substrate.youngs_modulus, substrate.poisson_ratio
        self.materials = ([(ly.youngs_modulus, ly.poisson_ratio) for ly in self.layers]
                          + [(self.substrate.youngs_modulus, self.substrate.poisson_ratio)])
        for i, (_, nu_i) in enumerate(self.materials):
            _check_nu(nu_i, "substrate" if i == len(self.layers) else f"layer {i}")
        choice = self.settings.formulation
        if choice == "auto":
            nu_max = max(nu_i for _, nu_i in self.materials)
            choice = "mixed" if nu_max > NU_DISPLACEMENT_MAX else "displacement"
        self.formulation = choice

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
        """DOFs of the far boundary: the arc rho = L (homogeneous) or, layered, the bands'
        outer edge r = L and the substrate's arc below them."""
        m = self.mesh
        fac = m.boundary_facets()
        x = m.p[:, m.facets[:, fac]]
        if not self.layers:
            rho = np.hypot(x[0], x[1])  # (2, nf)
            on = np.all(rho > 0.999 * L, axis=0)
        else:
            # the substrate's arc is centred on the axis at the bottom of the structured zone,
            # z_c = -(lowest z) - L
            z_c = -float(m.p[1].min()) - L
            edge = x[0] >= L * (1 - 1e-9)
            arc = np.hypot(x[0], x[1] + z_c) >= L * (1 - 1e-6)
            on = np.all(edge | arc, axis=0)
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
