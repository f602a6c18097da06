"""Independent campaign (2026-11-25): FE stress recovery against exact linear fields.

A P2 (or P2 + bubble) body reproduces a linear displacement field exactly, so the recovered
stresses of such a field are Hooke's law of its constant strain, to round-off.
"""
import numpy as np
import pytest

from femadh.elastic import RadialGrid
from femadh.elastic.fe import FEOperator, FESettings
from femadh.elastic.fe.weakform import lame

from conftest import E_STAR


@pytest.fixture(scope="module")
def fe():
    g = RadialGrid.uniform(1e-6, 10)
    return FEOperator.homogeneous(g, E_STAR, 0.3, FESettings(1e3, 0.5, 1.0))


def _field(fe, ur, uz):
    """Full DOF vector of the displacement (ur(r, z), uz(r, z)) at the P2 nodes."""
    b = fe.basis
    mesh = b.mesh
    mid = mesh.p[:, mesh.facets].mean(axis=1)
    u = np.zeros(b.N)
    for comp, f in ((0, ur), (1, uz)):
        u[b.nodal_dofs[comp]] = f(*mesh.p)
        u[b.facet_dofs[comp]] = f(*mid)
    return u


def test_recovered_shear_stress_is_mu_times_engineering_strain(fe):
    """u_z = gamma r (u_r = 0): e_rz = gamma/2, the only strain, so sigma_rz = mu gamma and
    every normal stress vanishes. A shear strain counted without its 1/2 doubles sigma_rz."""
    E, nu = fe.materials[0]
    lam, mu = lame(E, nu)
    gamma = 1e-4
    out = fe.field_projector.fields(_field(fe, lambda r, z: 0 * r, lambda r, z: gamma * r))
    scale = mu * gamma
    # measured: relative deviations 2.5e-14 (sigma_rz, von Mises), 9e-14 (normal stresses):
    # round-off of an L2 projection of a constant; tolerance ~100x that
    assert np.max(np.abs(out["sigma_rz"] / scale - 1.0)) < 1e-11
    for k in ("sigma_rr", "sigma_zz", "sigma_tt"):
        assert np.max(np.abs(out[k])) < 1e-11 * scale
    assert np.max(np.abs(out["von_mises"] / (np.sqrt(3) * scale) - 1.0)) < 1e-11


def test_recovered_normal_stresses_of_uniaxial_strain(fe):
    """u_z = eps z: sigma_zz = (lambda + 2 mu) eps, sigma_rr = sigma_tt = lambda eps, no shear."""
    E, nu = fe.materials[0]
    lam, mu = lame(E, nu)
    eps = 1e-4
    out = fe.field_projector.fields(_field(fe, lambda r, z: 0 * r, lambda r, z: eps * z))
    scale = (lam + 2 * mu) * eps
    # measured: relative deviations 6e-15 (sigma_zz), 1e-14 (sigma_rr, sigma_tt), 2e-15
    # (sigma_rz / sigma_zz); tolerance ~100x-1000x that (round-off)
    assert np.max(np.abs(out["sigma_zz"] / scale - 1.0)) < 1e-11
    assert np.max(np.abs(out["sigma_rr"] / (lam * eps) - 1.0)) < 1e-11
    assert np.max(np.abs(out["sigma_tt"] / (lam * eps) - 1.0)) < 1e-11
    assert np.max(np.abs(out["sigma_rz"])) < 1e-11 * scale

