"""FE half-space operator: absolute displacements vs closed forms, far-field truncation,
full-system residual, FE-vs-Green convergence of the force curves, VTK output."""
import math
import warnings

import numpy as np
import pytest

from femadh.contact import ContactProblem, trace
from femadh.contact import AsperityGap
from femadh.laws import LennardJones
from femadh.elastic import GreenOperator, RadialGrid, disk_displacement
from femadh.elastic.fe import FEOperator, FESettings
from femadh.indenter import Sphere
from femadh.contact.forces import state_forces
from femadh.reference import hertz_displacement

from conftest import E_STAR, HAMAKER, Z0, hertz_annulus_averages, observed_order

TOL = 1e-19


def test_uniform_disk_absolute_displacement_converges():
    """w itself (not only differences) enters the gap: check it against the closed form."""
    g = RadialGrid.uniform(1e-6, 20)
    exact = disk_displacement(g.nodes, g.radius, E_STAR)
    sizes, errs = [], []
    for growth, frac in ((0.5, 1.0), (0.25, 0.5), (0.125, 0.25)):
        fe = FEOperator.homogeneous(g, E_STAR, 0.3, FESettings(1e3, growth, frac))
        w = fe.displacement(np.ones(g.n))
        sizes.append(frac)
        errs.append(np.max(np.abs(w - exact)) / exact.max())
    # P2 elements: order 3 in max norm, measured 3.82 (superconvergent at the vertices)
    assert observed_order(sizes, errs) > 3.4
    assert errs[1] < 4e-4   # the default level: measured 1.9e-4


def test_hertz_absolute_displacement_tracks_green_and_converges():
    a_c, R = 0.5e-6, 1e-3
    p0 = 2 * E_STAR * a_c / (math.pi * R)
    hs, errs = [], []
    for n in (20, 40, 80):
        g = RadialGrid.uniform(1e-6, n)
        p = hertz_annulus_averages(g.edges, a_c, R, E_STAR)
        w_fe = FEOperator.homogeneous(g, E_STAR, 0.3, FESettings(1e3)).displacement(p)
        w_g = GreenOperator(g, E_STAR).displacement(p)
        exact = hertz_displacement(g.nodes, a_c, p0, E_STAR)
        hs.append(g.nodes[1])
        errs.append(np.max(np.abs(w_fe - exact)) / exact.max())
        # FE and Green see the same discrete load: they differ by the FE error only
        # (measured 1.4e-4, 9.8e-5, 9.1e-5 of the peak at N = 20, 40, 80)
        assert np.max(np.abs(w_fe - w_g)) / exact.max() < 3e-4
    # the piecewise-constant load of the sqrt-edged Hertz pressure limits both to 1.5
    # (measured 1.41)
    assert observed_order(hs, errs) == pytest.approx(1.5, abs=0.15)


def test_far_field_truncation_removed_by_boussinesq_data():
    g = RadialGrid.uniform(1.0, 20)
    exact = disk_displacement(g.nodes, g.radius, E_STAR)
    err = {}
    for far in ("fixed", "boussinesq"):
        for L in (10.0, 100.0, 1000.0):
            w = FEOperator.homogeneous(g, E_STAR, 0.3, FESettings(L, 0.25, 0.5, far)
                                       ).displacement(np.ones(g.n))
            err[far, L] = np.max(np.abs(w - exact)) / exact.max()
    # a fixed boundary shifts w by ~ F/(pi E* L): error ~ a/L, slope -1 (measured -0.955)
    slope = observed_order([10, 100, 1000], [err["fixed", L] for L in (10, 100, 1000)])
    assert slope == pytest.approx(-1.0, abs=0.1)
    # the Boussinesq field on the arc leaves O(a^2/L^2), below the mesh error from L = 100 a:
    # measured 1.0e-4 at L = 10 a (fixed: 8.5e-2, 840x more) and the mesh's 2.0e-4 beyond
    assert err["boussinesq", 10.0] < err["fixed", 10.0] / 400
    assert err["boussinesq", 100.0] < 3e-4


@pytest.fixture(scope="module")
def fe_fig3():
    """Paper 1 Fig 3 problem (sigma = 1 nm) on N = 60 nodes with the FE and Green operators."""
    R = 2e-3
    g = RadialGrid.uniform(math.sqrt(2 * R * 10e-9), 60)
    eff = {"lj": LennardJones(HAMAKER, Z0)}
    fe = FEOperator.homogeneous(g, E_STAR, 0.3)
    return (ContactProblem(fe, Sphere(R), eff, AsperityGap(1e-9)),
            ContactProblem(GreenOperator(g, E_STAR), Sphere(R), eff, AsperityGap(1e-9)))


def test_condensed_solution_satisfies_full_fe_system(fe_fig3):
    """Reconstruct the interior from a converged contact state: the uncondensed equations
    K u = B p(u) hold, with the nonlinear traction p evaluated from the reconstructed surface."""
    p_fe, _ = fe_fig3
    op = p_fe.operator
    sw = trace(p_fe, np.array([2.0, 1.0, 0.0, -3.0]) * 1e-9, branch="approach", tol=TOL)
    s = sw.states[-1]
    assert s.active.any()  # a contact state, with LJ and contact pressure both acting
    u = op.full_field(s.p_total)
    free = op.free
    f = op.B @ s.p_total
    r = op.K_full[free] @ u - f[free]
    # direct sparse solve: residual at round-off of ||K|| ||u|| (measured 2.9e-13)
    assert np.max(np.abs(r)) <= 3e-12 * np.max(np.abs(f))
    # the surface of the reconstructed field is the condensed w (measured 6e-15 of max |w|) ...
    w_u = u[op.basis.nodal_dofs[1, op.surface_vertices]]
    assert np.max(np.abs(w_u - s.w)) <= 5e-14 * np.max(np.abs(s.w))
    # ... and the traction it implies is the one applied: LJ at the gap of that surface
    h_u = p_fe.contour(s.d) - w_u
    inactive = ~s.active
    p_lj = p_fe.effects["lj"].pressure(h_u)
    # measured 7e-14 relative
    assert np.max(np.abs(p_lj[inactive] / s.p_effects["lj"][inactive] - 1)) <= 1e-12


def test_fe_matches_green_and_converges_under_refinement():
    """Force-separation curves (sigma = 1 nm, both branches): FE vs Green on the same nodes."""
    R = 2e-3
    g = RadialGrid.uniform(math.sqrt(2 * R * 10e-9), 100)
    eff = {"lj": LennardJones(HAMAKER, Z0)}
    ds = np.round(np.arange(2.0, -5.0001, -0.4), 10) * 1e-9

    def curve(op):
        p = ContactProblem(op, Sphere(R), eff, AsperityGap(1e-9))
        a = trace(p, ds, branch="approach", tol=TOL)
        r = trace(p, ds[::-1], branch="retract", tol=TOL, start=a.states[-1])
        return np.array([state_forces(p, s)[2] for s in a.states + r.states])

    ref = curve(GreenOperator(g, E_STAR))
    peak = np.abs(ref).max()
    errs = [np.abs(curve(FEOperator.homogeneous(g, E_STAR, 0.3, FESettings(1e4, gr, fr)))
                   - ref).max() / peak for gr, fr in ((0.5, 1.0), (0.25, 0.5))]
    assert errs[1] <= 2e-4                 # default mesh: measured 1.0e-4 of the peak force
    assert errs[0] / errs[1] > 7           # measured 10.6x per halving of the element size


def test_vtk_output_opens_in_pyvista(tmp_path):
    import pyvista as pv

    from femadh.io.writers import read_fields_state
    from femadh.runner.contact import run
    from femadh.scene import scene_from_dict
    from validation.paper1 import scene as load

    sc = load("paper1_fig3", 40)
    data = dict(sc.raw)
    data["solver"] = dict(data["solver"], method="fe", nodes=40)
    data["sweep"] = {"start": "1 nm", "stop": "-1 nm", "step": "1 nm", "directions": ["approach"]}
    data["output"] = dict(data.get("output", {}), vtk=True)
    sc = scene_from_dict(data, "test")
    res = run(sc, str(tmp_path), figures=False, progress=False)
    assert res.status == "converged" and sc.vtk
    vol = pv.read(tmp_path / "vtk" / "approach_0002.vtu")
    surf = pv.read(tmp_path / "vtk" / "approach_surface_0002.vtu")
    assert vol["displacement"].shape == (vol.n_points, 3)
    for k in ("sigma_rr", "sigma_zz", "sigma_tt", "sigma_rz", "von_mises"):
        assert np.all(np.isfinite(vol[k]))
    d, w = read_fields_state(tmp_path, "approach")        # the last state, from fields.csv
    # written as float64 (VTK) and repr (csv): exact
    assert np.array_equal(surf["w"], w)
    # displacement at the surface vertex on the axis equals the state's w(0)
    i0 = int(np.argmin(np.hypot(vol.points[:, 0], vol.points[:, 1])))
    assert vol["displacement"][i0, 1] == pytest.approx(w[0], rel=1e-12, abs=0)  # float64 copy
    assert "timestep" in (tmp_path / "approach.pvd").read_text()


def test_coarse_nodes_warn_about_lj_stiffness(tmp_path):
    from femadh.runner.contact import MeshResolutionWarning, run
    from validation.paper1 import scene as load

    sc = load("paper1_fig3", 10, sigma="0.25 nm")
    with pytest.warns(MeshResolutionWarning, match="nodes >="):
        run(sc, progress=False)
    with warnings.catch_warnings():
        warnings.simplefilter("error", MeshResolutionWarning)
        run(load("paper1_fig3", 200), progress=False)  # the bundled default: quiet


def _cache_env(tmp_path, monkeypatch):
    monkeypatch.setenv("FEMADH_OPERATOR_CACHE", str(tmp_path / "ops"))
    return tmp_path / "ops"


def test_cached_operator_equals_a_fresh_one_and_builds_its_body_on_demand(tmp_path,
                                                                          monkeypatch):
    """The operator cache: a miss condenses and stores, a hit returns the stored compliance
    (float64 npz: the same bits as the fresh condensation, so equal to round-off is exact),
    and the hit's factorised body (full fields, VTK) is built only when asked for, giving the
    fresh operator's full field."""
    cache = _cache_env(tmp_path, monkeypatch)
    g = RadialGrid.uniform(6.32e-6, 40)
    fresh = FEOperator.homogeneous(g, E_STAR, 0.3)
    miss = FEOperator.homogeneous(g, E_STAR, 0.3, cache=True)
    assert not miss.cache_hit and len(list(cache.glob("fe-*.npz"))) == 1
    hit = FEOperator.homogeneous(g, E_STAR, 0.3, cache=True)
    assert hit.cache_hit and "assembly" not in hit.timings     # nothing assembled
    assert np.array_equal(hit.compliance, miss.compliance)
    # a separate condensation: same sparse LU, same bits here (allow round-off anyway)
    assert np.allclose(hit.compliance, fresh.compliance, rtol=1e-12, atol=0)
    p = np.linspace(1e6, 0, 40)
    u = hit.full_field(p)                                      # builds the body now
    assert "assembly" in hit.timings
    assert np.allclose(u, fresh.full_field(p), rtol=1e-12, atol=1e-30)


def test_operator_cache_is_invalidated_by_a_changed_body(tmp_path, monkeypatch):
    """Another material, Poisson ratio, mesh setting or mesh file is another key (a new
    condensation); the sphere's compliance is added on load, not cached."""
    import shutil

    from femadh.elastic.fe.cache import operator_key
    from femadh.materials import IsotropicMaterial

    cache = _cache_env(tmp_path, monkeypatch)
    g = RadialGrid.uniform(6.32e-6, 30)
    base = FEOperator.homogeneous(g, E_STAR, 0.3, cache=True)
    for other in (FEOperator.homogeneous(g, 1.01 * E_STAR, 0.3, cache=True),
                  FEOperator.homogeneous(g, E_STAR, 0.25, cache=True),
                  FEOperator.homogeneous(g, E_STAR, 0.3, FESettings(1e4, growth=0.3),
                                         cache=True)):
        assert not other.cache_hit
        assert not np.array_equal(other.compliance, base.compliance)
    assert len(list(cache.glob("fe-*.npz"))) == 4
    # the same spec but a different mesh file (rebuilt, replaced): another key
    meshes = tmp_path / "meshes"
    meshes.mkdir()
    src = base._mesh_path
    shutil.copy(src, meshes / src.name)
    with open(meshes / src.name, "a") as f:
        f.write("\n")                                         # other bytes, same mesh
    monkeypatch.setenv("FEMADH_MESH_PATH", str(meshes))
    moved = FEOperator.homogeneous(g, E_STAR, 0.3, cache=True)
    assert moved._mesh_path != src and operator_key(moved) != operator_key(base)
    assert not moved.cache_hit
    # a sphere material on a layered-call body: the sphere's Green part is added on load
    sub = IsotropicMaterial(163e9, 0.3)
    rigid = FEOperator.layered(g, sub, cache=True)
    soft = FEOperator.layered(g, sub, sphere=IsotropicMaterial(83e9, 0.21), cache=True)
    assert soft.cache_hit and np.array_equal(soft.compliance_body, rigid.compliance_body)
    assert not np.array_equal(soft.compliance, rigid.compliance)
