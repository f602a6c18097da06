"""FE half-space operator: absolute displacements vs closed forms, far-field truncation,
full-system residual, FE-vs-Green convergence of the force curves, VTK output, the operator
cache, the surface load (FacetBasis) and the boundaries by name."""
import contextlib
import io
import json
import math
from pathlib import Path
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
    # the surface of the reconstructed field is the condensed w: C p_total to round-off
    # (measured 6e-15 of max |w|), and the state's w is C p_total to its Newton residual
    # (<= TOL; measured 3.8e-22 m here, 1e-4 of TOL, with the stepping predictor of the
    # branch fig4fast, whose last Newton step ends elsewhere below TOL than before) ...
    w_u = u[op.basis.nodal_dofs[1, op.surface_vertices]]
    assert np.max(np.abs(w_u - s.w)) <= s.residual + 5e-14 * np.max(np.abs(s.w))
    assert s.residual <= TOL
    # ... and the traction it implies is the one applied: LJ at the gap of that surface
    h_u = p_fe.contour(s.d) - w_u
    inactive = ~s.active
    p_lj = p_fe.effects["lj"].pressure(h_u)
    # measured 7e-14 relative, beyond what the gaps' difference (the state's residual, above)
    # moves the law: 1.05e-12 at the steepest free node with the residual of 3.8e-22 m
    slack = np.abs(p_fe.effects["lj"].dpressure(h_u)) * np.max(np.abs(w_u - s.w))
    assert np.all(np.abs(p_lj - s.p_effects["lj"])[inactive] <=
                  slack[inactive] + 1e-12 * np.abs(s.p_effects["lj"][inactive]))


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
    from femadh.runner.run import run
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
    # (the volume field is the FE solve of the state's pressure: its surface is the state's
    # w to the Newton residual, at most the scene's tolerance 1e-19 m; measured 6.4e-21 m)
    assert vol["displacement"][i0, 1] == pytest.approx(w[0], rel=0, abs=sc.tolerance)
    assert "timestep" in (tmp_path / "approach.pvd").read_text()


def test_coarse_nodes_warn_about_lj_stiffness(tmp_path):
    from femadh.errors import MeshResolutionWarning
    from femadh.runner.run import run
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


# ---- the surface load and the named boundaries ------------------------------------------

MESHES = Path(__file__).resolve().parents[1] / "meshes"
COMMITTED = json.loads((MESHES / "manifest.json").read_text())


def _p2_trace_load(mesh, basis, facets, pressure):
    """Independent judge: int N_k p(r) 2 pi r dr on each facet from the P2 trace shape
    functions written out (vertex a: (1-s)(1-2s), vertex b: s(2s-1), mid-side: 4s(1-s)) and
    8-point Gauss-Legendre (exact to degree 15), scattered to the z DOFs."""
    gp, gw = np.polynomial.legendre.leggauss(8)
    s, wq = 0.5 * (gp + 1), 0.5 * gw
    shapes = np.stack([(1 - s) * (1 - 2 * s), s * (2 * s - 1), 4 * s * (1 - s)])
    va, vb = mesh.facets[0, facets], mesh.facets[1, facets]
    ra, rb = mesh.p[0, va], mesh.p[0, vb]
    rq = ra[:, None] + (rb - ra)[:, None] * s[None, :]
    vals = (shapes[None] * (2 * math.pi * rq * pressure(rq))[:, None, :] * wq).sum(-1) \
        * np.abs(rb - ra)[:, None]
    dofs = np.stack([basis.nodal_dofs[1, va], basis.nodal_dofs[1, vb],
                     basis.facet_dofs[1, facets]], 1)
    out = np.zeros(basis.N)
    np.add.at(out, dofs.ravel(), vals.ravel())
    return out


@pytest.mark.parametrize("element", ["P2", "P2B"])
def test_facet_basis_surface_load_is_exact_for_a_polynomial_pressure(element):
    """The load vector of the FacetBasis LinearForm on the named surface equals
    int N_i p(r) 2 pi r dr for a quadratic p (its quadrature is exact for the element's
    trace x r x p), for the displacement (P2) and the mixed (P2 + bubble) element."""
    from skfem import Basis, ElementTriP2, ElementTriP2B, ElementVector

    from femadh.elastic.fe.mesh import load_mesh
    from femadh.elastic.fe.weakform import surface_facet_basis, surface_pressure_form

    a = 3e-6
    mesh, _ = load_mesh(MESHES / "halfspace-7fa390b369871df4.msh", scale=a)
    basis = Basis(mesh, ElementVector(ElementTriP2() if element == "P2" else ElementTriP2B()))
    surface = mesh.boundaries["surface"]
    loaded = surface[mesh.p[0, mesh.facets[:, surface]].mean(axis=0) < a]

    def pressure(r):
        return 1e6 * (1 + 2 * r / a - 3 * (r / a) ** 2)

    b = surface_pressure_form(pressure).assemble(
        surface_facet_basis(mesh, basis.elem, loaded, degree=2))
    ref = _p2_trace_load(mesh, basis, loaded, pressure)
    # round-off: measured 8.7e-15 (P2), 4.2e-15 (P2B) of the largest nodal force; a rule two
    # degrees short (degree=0 for this quadratic p) is off by 2.2e-4 on P2
    assert np.max(np.abs(b - ref)) <= 5e-14 * np.max(np.abs(ref))
    assert not np.any(b[basis.nodal_dofs[0]])     # a normal load: no radial force


def test_load_matrix_columns_are_the_annulus_loads():
    """The operator's load matrix: column j is the consistent load of unit pressure on
    annulus j (the judge above with a piecewise-constant p), and its z forces add up to the
    annulus area (the trace shape functions sum to one)."""
    g = RadialGrid.uniform(1e-6, 20)
    op = FEOperator.homogeneous(g, E_STAR, 0.3, FESettings(1e3))
    assert op._mesh_path.name == "halfspace-7fa390b369871df4.msh"
    p = np.linspace(2.0, 0.5, g.n) * 1e6
    surface = op.mesh.boundaries["surface"]
    loaded = surface[op.mesh.p[0, op.mesh.facets[:, surface]].mean(axis=0) < g.radius]

    def piecewise(r):
        return p[np.clip(np.searchsorted(g.edges, r) - 1, 0, g.n - 1)]

    ref = _p2_trace_load(op.mesh, op.basis, loaded, piecewise)
    # (Gauss points lie inside the facets, each facet inside one annulus: the judge is exact)
    assert np.max(np.abs(op.B @ p - ref)) <= 5e-14 * np.max(np.abs(ref))   # measured 6.5e-15
    totals = np.asarray(op.B[op.basis.nodal_dofs[1]].sum(0) + op.B[op.basis.facet_dofs[1]]
                        .sum(0)).ravel()
    assert np.max(np.abs(totals / g.areas - 1)) <= 1e-14                     # measured 2.2e-15


def _geometric_dofs(mesh, basis, outer, layered):
    """The boundary DOFs found by geometric searches (as the operator did before it read the
    mesh's named boundaries): far arc (and, layered, the bands' edge r = L), axis u_r."""
    fac = mesh.boundary_facets()
    x = mesh.p[:, mesh.facets[:, fac]]
    if not layered:
        on = np.all(np.hypot(x[0], x[1]) > 0.999 * outer, axis=0)
    else:
        z_c = -float(mesh.p[1].min()) - outer
        on = np.all((x[0] >= outer * (1 - 1e-9))
                    | (np.hypot(x[0], x[1] + z_c) >= outer * (1 - 1e-6)), axis=0)
    far = np.unique(basis.get_dofs(fac[on]).flatten())
    axis = basis.get_dofs(fac[np.all(x[0] == 0.0, axis=0)])
    surface = np.flatnonzero(mesh.p[1] == 0.0)
    return far, np.sort(np.concatenate([axis.nodal["u^1"], axis.facet["u^1"]])), surface


def _layered_mesh_path():
    from femadh.elastic.fe import Layer, mesh_spec
    from femadh.elastic.fe.mesh import cached_mesh

    g = RadialGrid.uniform(1.0, 20)
    spec = mesh_spec(g, FESettings(), [Layer(0.1, 1e13, 0.3), Layer(0.5, 1e9, 0.3)])
    return cached_mesh(spec), spec.outer_radius


@pytest.mark.parametrize("name", [e["file"] for e in COMMITTED] + ["layered"])
def test_boundary_dofs_by_name_equal_the_geometric_ones(name):
    """On every committed mesh (and a layered one): the DOFs of the named ``far`` and
    ``axis`` groups and the vertices of ``surface`` are those the geometric searches find,
    and the groups are those scikit-fem's own reader (MeshTri.load) finds."""
    from skfem import Basis, ElementTriP2, ElementVector, MeshTri

    from femadh.elastic.fe.mesh import load_mesh

    if name == "layered":
        path, outer = _layered_mesh_path()
    else:
        path = MESHES / name
        outer = next(e["outer_factor"] for e in COMMITTED if e["file"] == name)
    mesh, _ = load_mesh(path)
    basis = Basis(mesh, ElementVector(ElementTriP2()))
    far, axis, surface = _geometric_dofs(mesh, basis, outer, name == "layered")
    by_name = basis.get_dofs("axis")
    assert np.array_equal(np.unique(basis.get_dofs("far").flatten()), far)
    assert np.array_equal(np.sort(np.concatenate([by_name.nodal["u^1"],
                                                  by_name.facet["u^1"]])), axis)
    assert np.array_equal(np.unique(mesh.facets[:, mesh.boundaries["surface"]]), surface)
    with contextlib.redirect_stdout(io.StringIO()):
        theirs = MeshTri.load(str(path))
    assert np.array_equal(theirs.p, mesh.p)
    for group in ("surface", "axis", "far"):
        assert np.array_equal(np.sort(theirs.boundaries[group]), mesh.boundaries[group])


def test_a_mesh_without_a_named_boundary_is_refused_clearly(tmp_path):
    from femadh.elastic.fe.mesh import load_mesh

    src = (MESHES / "halfspace-22afcdcc6c56b7b7.msh").read_text()
    bad = tmp_path / "bad.msh"
    bad.write_text(src.replace('"far"', '"outer"'))
    with pytest.raises(ValueError, match=r"bad.msh has no boundary group 'far'"):
        load_mesh(bad)
