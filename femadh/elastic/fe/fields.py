"""Full fields of an FE state for inspection: displacement and stresses at the P2 nodes.

:class:`FieldProjector` is built once per operator (``operator.field_projector``). It holds
sparse matrices from the displacement DOF vector to each stress component at the quadrature
points (material of every region, and the projected volumetric stress of the mixed
formulation, included), and the factorised mass matrices of an L2 projection onto continuous
quadratic fields *per region*: a stress state then costs a few sparse products and one
triangular solve instead of assembling and factorising a mass matrix per component.

Output nodes are the P2 nodes (vertices and edge midpoints, i.e. VTK quadratic triangles), one
copy per region: stresses jump across an interface (only the traction is continuous), so each
region is projected on its own and the interfaces stay sharp in the pictures.
"""
import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.linalg import splu

from .weakform import lame

STRESS_NAMES = ("sigma_rr", "sigma_zz", "sigma_tt", "sigma_rz")


def _strain_operators(basis):
    """Sparse (n_el * n_q, N) matrices of e_rr, e_zz, e_tt, e_rz at the quadrature points."""
    n_el, n_q = basis.dx.shape
    r = basis.mapping.F(basis.X)[0]          # (n_el, n_q) radii of the quadrature points
    rows = np.arange(n_el * n_q).reshape(n_el, n_q)
    data = {k: [] for k in range(4)}
    row_idx, col_idx = [], []
    for j in range(basis.Nbfun):
        phi = basis.basis[j][0]
        g = phi.grad                           # (2 comps, 2 dirs, n_el, n_q)
        comps = (g[0, 0], g[1, 1], np.asarray(phi)[0] / r, 0.5 * (g[0, 1] + g[1, 0]))
        for k, v in enumerate(comps):
            data[k].append(v.ravel())
        row_idx.append(rows.ravel())
        col_idx.append(np.repeat(basis.element_dofs[j], n_q))
    rows_all, cols_all = np.concatenate(row_idx), np.concatenate(col_idx)
    shape = (n_el * n_q, basis.N)
    return [coo_matrix((np.concatenate(data[k]), (rows_all, cols_all)), shape=shape).tocsr()
            for k in range(4)]


class FieldProjector:
    """Stress recovery and output nodes of an FEOperator, built once and reused per state.

    Parameters
    ----------
    operator : FEOperator

    Attributes
    ----------
    points : ndarray (n_out, 2)
        (r, z) of the output nodes (m): each region's P2 nodes (interface nodes repeated).
    cells : ndarray (n_el, 6)
        Quadratic triangles (VTK/meshio "triangle6" order: corners, then the midpoints of
        edges 01, 12, 20) into ``points``.
    cell_region : ndarray (n_el,)
        Region id of each cell (0 = top layer, ..., len(layers) = substrate).
    """

    def __init__(self, operator):
        from skfem import Basis, ElementTriP2

        b = operator.basis
        mesh = b.mesh
        n_el, n_q = b.dx.shape
        strains = _strain_operators(b)
        # per-element Lame constants; their volumetric stress lambda tr(eps), or in mixed
        # regions lambda P(div u) (what the stiffness used, free of the locking noise)
        region = operator.region
        lam_el = np.empty(n_el)
        mu_el = np.empty(n_el)
        for rid, (E, nu) in enumerate(operator.materials):
            lam_el[region == rid], mu_el[region == rid] = lame(E, nu)
        lam_q = np.repeat(lam_el, n_q)
        mu_q = np.repeat(mu_el, n_q)
        trace = strains[0] + strains[1] + strains[2]
        if operator.formulation == "mixed":
            volumetric = self._mixed_volumetric(operator, n_el * n_q, n_q)
        else:
            volumetric = _diag(lam_q) @ trace
        self._stress = [(volumetric + _diag(2 * mu_q) @ strains[k]).tocsr() for k in range(3)]
        self._stress.append((_diag(2 * mu_q) @ strains[3]).tocsr())

        # continuous P2 output space broken at the interfaces: one copy per region
        p2 = Basis(mesh, ElementTriP2(), quadrature=b.quadrature)
        elem_nodes = np.vstack([mesh.t, p2.mesh.t2f + mesh.p.shape[1]])   # (6, n_el)
        node_xy = np.hstack([mesh.p, mesh.p[:, mesh.facets].mean(axis=1)])
        key = region[None, :] * node_xy.shape[1] + elem_nodes
        uniq, local = np.unique(key.ravel(), return_inverse=True)
        self.cells = local.reshape(6, n_el).T
        self._node = uniq % node_xy.shape[1]
        self.points = node_xy[:, self._node].T
        self.cell_region = region
        n_out = uniq.size
        # element mass matrices and quadrature-to-node load operator in the broken space
        phi = np.stack([np.asarray(p2.basis[j][0]) for j in range(6)])         # (6, n_el, n_q)
        # skfem's P2 local dofs are (vertices, facets) in t / t2f order, as elem_nodes
        w = b.dx                                                          # (n_el, n_q)
        m_loc = np.einsum("iek,jek,ek->eij", phi, phi, w)
        rows = np.repeat(self.cells[:, :, None], 6, axis=2)
        cols = np.repeat(self.cells[:, None, :], 6, axis=1)
        mass = coo_matrix((m_loc.ravel(), (rows.ravel(), cols.ravel())),
                          shape=(n_out, n_out)).tocsc()
        q_rows = np.repeat(self.cells.T[:, :, None], n_q, axis=2)        # (6, n_el, n_q)
        q_cols = np.broadcast_to(np.arange(n_el * n_q).reshape(n_el, n_q), q_rows.shape)
        load = coo_matrix(((phi * w[None]).ravel(), (q_rows.ravel(), q_cols.ravel())),
                          shape=(n_out, n_el * n_q)).tocsr()
        # one factorisation: the broken mass matrix is block diagonal over regions
        self._mass_lu = splu(mass, permc_spec="MMD_AT_PLUS_A")
        self._stress_rhs = [(load @ s).tocsr() for s in self._stress]
        # displacement DOFs of every output node (P2 nodes carry point values, also for the
        # bubble-enriched element whose bubble vanishes there)
        nv = mesh.p.shape[1]
        dof_r = np.concatenate([b.nodal_dofs[0], b.facet_dofs[0]])
        dof_z = np.concatenate([b.nodal_dofs[1], b.facet_dofs[1]])
        self._dof_r, self._dof_z = dof_r[self._node], dof_z[self._node]
        self.n_vertices = nv

    @staticmethod
    def _mixed_volumetric(operator, n_rows, n_q):
        """lambda P(div u) at the quadrature points: in the mixed formulation every region's
        volumetric stress is its projected divergence (the pressure the stiffness used)."""
        from skfem import Basis

        pb = operator._pbasis
        total = None
        for elements, lam, proj in operator._pressure:
            pr = Basis(pb.mesh, pb.elem, elements=elements, quadrature=operator.basis.quadrature)
            vals = np.stack([np.asarray(pr.basis[j][0]) for j in range(pr.Nbfun)])  # (3, n_e, n_q)
            dofs = pb.element_dofs[:, elements]                                 # (3, n_e)
            rows = elements[:, None] * n_q + np.arange(n_q)[None, :]            # (n_e, n_q)
            interp = coo_matrix(
                (vals.ravel(), (np.broadcast_to(rows, vals.shape).ravel(),
                                np.repeat(dofs[:, :, None], n_q, axis=2).ravel())),
                shape=(n_rows, pb.N)).tocsr()
            part = lam * (interp @ proj)
            total = part if total is None else total + part
        return total.tocsr()

    def fields(self, u):
        """Output-node fields of a displacement DOF vector u (m).

        Returns a dict: ``displacement`` (n_out, 3) = (u_r, u_z, 0) (m), the four stresses
        and ``von_mises`` (Pa), each (n_out,).
        """
        rhs = np.column_stack([op @ u for op in self._stress_rhs])
        s = self._mass_lu.solve(rhs)
        out = {name: s[:, k] for k, name in enumerate(STRESS_NAMES)}
        out["von_mises"] = np.sqrt(0.5 * ((out["sigma_rr"] - out["sigma_zz"]) ** 2
                                          + (out["sigma_zz"] - out["sigma_tt"]) ** 2
                                          + (out["sigma_tt"] - out["sigma_rr"]) ** 2)
                                   + 3 * out["sigma_rz"] ** 2)
        disp = np.zeros((self.points.shape[0], 3))
        disp[:, 0], disp[:, 1] = u[self._dof_r], u[self._dof_z]
        out["displacement"] = disp
        return out


def _diag(v):
    from scipy.sparse import diags

    return diags(v)


def fe_point_fields(operator, u):
    """Output-node fields of a full displacement DOF vector u of an FEOperator (see
    :meth:`FieldProjector.fields`); the projector is the operator's, built on first use."""
    return operator.field_projector.fields(u)


__all__ = ["FieldProjector", "fe_point_fields", "STRESS_NAMES"]
