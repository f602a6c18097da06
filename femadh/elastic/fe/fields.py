"""Full fields of an FE state for inspection: displacement and stresses at the mesh vertices."""
import numpy as np

from .weakform import lame, stresses


def fe_point_fields(operator, u):
    """Vertex fields of a full displacement DOF vector u of an FEOperator."""
    from skfem import ElementTriP1

    b = operator.basis
    lam, mu = lame(operator.youngs, operator.nu)
    uh = b.interpolate(u)
    s = stresses(uh, b.global_coordinates()[0], lam, mu)
    b1 = b.with_element(ElementTriP1())
    out = {k: b1.project(val) for k, val in s.items()}
    out["von_mises"] = np.sqrt(0.5 * ((out["sigma_rr"] - out["sigma_zz"]) ** 2
                                      + (out["sigma_zz"] - out["sigma_tt"]) ** 2
                                      + (out["sigma_tt"] - out["sigma_rr"]) ** 2)
                               + 3 * out["sigma_rz"] ** 2)
    nd = b.nodal_dofs
    disp = np.zeros((b.mesh.p.shape[1], 3))
    disp[:, 0], disp[:, 1] = u[nd[0]], u[nd[1]]
    out["displacement"] = disp
    return out
