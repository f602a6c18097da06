"""Greenwood-Williamson statistics and asperity effects (paper 1 sec 5.2-6), regime map."""
import math

import numpy as np
import pytest
from scipy import integrate

from femadh.laws import AsperityAdhesion, GWAdhesion, GWElastic
from conftest import check_curve_against_fields
from femadh.laws import gw_integral
from femadh.reference.gw import (height_density, mean_plane_dominance_bound,
                                 paper1_table2_roughness)


@pytest.mark.parametrize("n", [0.0, 0.5, 1.0, 1.5, 2.5])
def test_gw_integrals_match_quadrature(n):
    for t in (-2.5, -0.3, 0.7, 3.0):
        q = integrate.quad(lambda s: (s - t) ** n * math.exp(-s * s / 2) / math.sqrt(2 * math.pi),
                           t, np.inf, epsabs=1e-14, epsrel=1e-12)[0]
        assert gw_integral(n, t) == pytest.approx(q, rel=1e-9, abs=0)


def test_corrected_eq26_is_normalised():
    r = paper1_table2_roughness(100e12)
    q = integrate.quad(lambda z: height_density(z, r.z_m, r.sigma_a), r.z_m - 20 * r.sigma_a,
                       r.z_m + 20 * r.sigma_a)[0]
    assert q == pytest.approx(1.0, rel=1e-10)


def test_paper1_table2_and_fig7_numbers():
    """Sec 6: composite sigma_a = 0.344 nm, z_m = 1.08 nm, R_a = 0.94 um; at p = 0.5 the real
    area ratios 0.013/0.04/0.073 and P_LJa 5.56/17.7/31.8 MPa; eq 22 bounds 1.05/0.49 nm."""
    r = paper1_table2_roughness(1.0)
    assert (r.sigma_a, r.z_m, r.radius) == pytest.approx((0.344e-9, 1.08e-9, 0.94e-6),
                                                         rel=2e-3, abs=0)
    for rho, ar, plj in ((31.3, 0.013, 5.56), (100, 0.04, 17.7), (179, 0.073, 31.8)):
        r = paper1_table2_roughness(rho * 1e12)
        assert r.contact_probability(r.z_m) == pytest.approx(0.5, rel=1e-14, abs=0)
        assert r.real_area_ratio(r.z_m) == pytest.approx(ar, rel=0.05)   # paper's 2 digits
        assert r.lj_pressure(r.z_m, 0.06) / 1e6 == pytest.approx(plj, rel=5e-3)
    assert mean_plane_dominance_bound(0.165e-9, 1e-6, 10e12) == pytest.approx(1.05e-9, rel=5e-3, abs=0)
    assert mean_plane_dominance_bound(0.165e-9, 1e-6, 100e12) == pytest.approx(0.49e-9, rel=1e-2, abs=0)


def test_asperity_laws_derivatives_by_finite_differences():
    r = paper1_table2_roughness(100e12)
    h = np.linspace(0.3e-9, 3e-9, 60)
    for law in (GWElastic(r, 58.48e9), GWAdhesion(r, 0.06),
                AsperityAdhesion.from_asperities(0.94e-6, 0.06, 100e12, 0.5, 1.08e-9)):
        eps = 1e-15
        fd = (law.pressure(h + eps) - law.pressure(h - eps)) / (2 * eps)
        assert np.max(np.abs(fd - law.dpressure(h))) <= 1e-7 * np.max(np.abs(fd))
        fe = (law.energy(h + eps) - law.energy(h - eps)) / (2 * eps)
        assert np.max(np.abs(fe - law.pressure(h))) <= 1e-7 * np.max(np.abs(law.pressure(h)))


def test_paper1_section6_scenes_run_and_report_asperity_forces(tmp_path):
    """The sec 6 scenes run and write their asperity forces, each integrated from fields.csv
    (without the error estimate, which reruns each scene on two coarser grids and is judged
    elsewhere: it cost half of this test)."""
    import csv

    import femadh

    for name, col in (("paper1_fig8_rho179", "F_LJa_N"), ("paper1_slider_gw", "F_ela_N")):
        sc = femadh.load_scene(f"validation/scenes/{name}.toml")
        res = femadh.run(sc, str(tmp_path / name), figures=False, progress=False,
                         estimate=False)
        assert res.status == "converged"
        rows = list(csv.DictReader(open(tmp_path / name / "curve.csv")))
        assert col in rows[0]
        # F_ex = F_LJ + F_LJa - F_ela - F_el, each integrated from fields.csv
        assert check_curve_against_fields(tmp_path / name) == len(rows)


def test_regime_map_limits_and_hysteresis():
    """Smooth LJ sphere: small mu approaches the Derjaguin/DMT 2 pi R dg with no hysteresis;
    at larger mu the curve folds (jump-in on approach, jump-out later on retract), the loop
    widens and the pull-off falls towards JKR's 1.5, ever closer to Maugis-Dugdale at
    lambda = 1.16 mu; no traced state lets a node snap on its own."""
    from femadh.studies.regime import lj_sphere

    lo = lj_sphere(0.1)
    assert lo.jump_in is None and lo.jump_out is None and lo.n_folds == 0
    # rigid-LJ limit AR/8z0^2 = 2 pi R dg; at mu = 0.1 measured 1.969 (Maugis-Dugdale: 1.940)
    assert lo.pull_off == pytest.approx(2.0, abs=0.05)
    mid, hi = lj_sphere(2.0), lj_sphere(4.0)
    for p in (mid, hi):
        assert p.jump_in is not None and p.jump_out > p.jump_in
        assert p.trapping_ratio < 0.45   # mesh-wiggle onset measured at ~0.4-0.6 (mu = 3)
    assert 1.5 < hi.pull_off < mid.pull_off < lo.pull_off
    assert hi.hysteresis > mid.hysteresis > 0.5
    # LJ vs Dugdale law differ in shape (not a numerical error): measured 3.7 % at mu = 2,
    # 1.85 % at mu = 4
    assert mid.pull_off == pytest.approx(mid.maugis, rel=0.042)
    assert hi.pull_off == pytest.approx(hi.maugis, rel=0.021)
    assert abs(hi.pull_off / hi.maugis - 1) < abs(mid.pull_off / mid.maugis - 1)


def test_regime_cli_writes_table_and_figures(regime_run, capsys):
    """`femadh regime`: csv with one row per mu, the two figures; units are checked.
    (conftest's regime_run: the run whose printed table test_output reads.)"""
    import csv

    from femadh.cli import main

    code, _, out = regime_run
    assert code == 0
    rows = list(csv.DictReader(open(out / "regime.csv")))
    assert [float(r["mu"]) for r in rows] == [0.5, 1.0]
    assert rows[0]["jump_in_d_over_z0"] == "" and float(rows[1]["jump_in_d_over_z0"]) > 2
    assert (out / "regime_map.png").stat().st_size > 0
    assert (out / "regime_curves.png").stat().st_size > 0
    assert main(["regime", "--radius", "1 kg", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "--radius" in err and "1 kg" in err and "length" in err


def test_regime_force_of_the_undeformed_surface_is_eq14_untruncated():
    """w = 0: the map's force (grid + tail beyond the analysis radius) is the rigid sphere's
    eq 14 on the whole plane; the grid's midpoint rule costs at most 1.5e-4 here (measured),
    while the tail alone is 0.3-11 % of it at d = z0 ... 10 z0."""
    from femadh.reference.rigid_lj import rigid_sphere_lj_force
    from femadh.studies.smooth_sphere import lj_force, lj_sphere_problem

    R, A, z0 = 1e-6, 1e-19, 0.165e-9
    problem, lj, *_ = lj_sphere_problem(1.0, R, A, z0, 0.4, 120)
    for d in np.array([1.0, 1.5, 3.0, 10.0]) * z0:
        F = lj_force(problem, lj, d, np.zeros(problem.grid.n))
        assert F == pytest.approx(rigid_sphere_lj_force(d, A, z0, R), rel=5e-4, abs=0)


def test_a_narrow_loop_near_the_cusp_is_not_stepped_over():
    """Just above the onset of bistability (mu ~ 0.70) the S-loop is narrower than the
    continuation's steps (jump-in/out 2.2657/2.2684 z0 at mu = 0.72): the trace must resolve
    its two folds (it halves a step whose tangent turns by more than 30 degrees), as finer
    steps do."""
    from femadh.studies.regime import lj_sphere

    # on the legacy fixed grid (the banded default steps over this loop at ds_max = 0.5:
    # a known limit near the cusp, validation/README.md)
    p = lj_sphere(0.72, ds_max=0.5, stiffness_target=0.4, min_nodes=120)
    fine = lj_sphere(0.72, ds_max=0.1, stiffness_target=0.4, min_nodes=120)
    assert p.n_folds == fine.n_folds == 2
    assert p.jump_in == pytest.approx(fine.jump_in, rel=1e-9, abs=0)
    assert p.jump_out > p.jump_in


def test_eq20_law_amplitude_is_the_papers_P_LJa():
    """The [effects.asperity_adhesion] law carries eq 20's P_LJa = 2 pi R_a dg rho p: at
    p = 0.5 the paper's 5.56 / 17.7 / 31.8 MPa for rho = 31.3 / 100 / 179 um^-2 (3 digits)."""
    for rho, plj in ((31.3, 5.56), (100, 17.7), (179, 31.8)):
        law = AsperityAdhesion.from_asperities(0.94e-6, 0.06, rho * 1e12, 0.5, 1.08e-9)
        assert law.pressure_value / 1e6 == pytest.approx(plj, rel=5e-3)
        # deep in contact (h = sigma) the smoothed step has fully switched on: 1 - S(5)
        assert law.pressure(1.08e-9) / law.pressure_value == pytest.approx(
            1 / (1 + math.exp(-5)), rel=1e-12)


@pytest.mark.parametrize("rho", [31.3, 100.0, 179.0])
def test_gw_laws_equal_eqs_23_24_by_quadrature(rho):
    """The laws the solver uses (closed-form parabolic-cylinder integrals) against eqs 23-24
    integrated over the corrected eq 26 density by adaptive quadrature (measured <= 2e-12)."""
    r = paper1_table2_roughness(rho * 1e12)
    E = 58.48e9
    el, ad = GWElastic(r, E), GWAdhesion(r, 0.06)
    for h in (0.4e-9, 0.9e-9, 1.08e-9, 1.6e-9, 2.5e-9):
        phi = lambda z: height_density(z, r.z_m, r.sigma_a)  # noqa: E731
        top = r.z_m + 12 * r.sigma_a
        p_el = 4 / 3 * E * r.density * math.sqrt(r.radius) * integrate.quad(
            lambda z: (z - h) ** 1.5 * phi(z), h, top, epsabs=0, epsrel=1e-13, limit=200)[0]
        prob = integrate.quad(phi, h, top, epsabs=0, epsrel=1e-13, limit=200)[0]
        p_ad = 2 * math.pi * r.radius * 0.06 * r.density * prob
        assert -el.pressure(h) == pytest.approx(p_el, rel=1e-10, abs=0)
        assert ad.pressure(h) == pytest.approx(p_ad, rel=1e-10, abs=0)


def test_eq20_on_the_contact_set_is_the_smoothed_laws_limit_and_vanishes_with_the_mesh():
    """Eq 20 in the complementarity model (sec 6 slider, rho = 179 um^-2): (a) the smoothed
    step converges to the exact contact-set limit as its width -> 0 (measured excess 2.2e-5,
    8.1e-6, 2.5e-6 N at widths 2, 1, 0.5 % of sigma, N = 100: order 1.6); (b) the limit's own
    excess over the pull-off without eq 20 falls like the node spacing (7.7e-6, 4.3e-6,
    1.8e-6 N at N = 100, 200, 400: order 1.0-1.3): a range-less pressure does no work.
    The sweeps go 2 -> 0.6 nm (the scene's -5 nm adds deep states only): the pull-offs, read
    on the retract at d = 1.2-1.4 nm, are those of sweeps to 0 nm to 2e-13 relative (and
    those to 0 and -5 nm agree to 1e-15; measured; 2.6 instead of 3.5 CPU-s for the nine
    runs); the narrowest step's run is the one that fails when an unstable state is
    accepted."""
    import warnings

    from femadh.runner.run import run
    from validation.roughness import slider_scene

    from conftest import observed_order

    seen = {}

    def pull_off(rho, nodes, smoothing=None):
        key = (rho, nodes, smoothing)       # the limit and rho = 0 at N = 100 serve twice
        if key not in seen:
            kw = {} if smoothing is None else {"smoothing": smoothing}
            sc = slider_scene(rho=rho, **kw).replace({"solver.nodes": nodes,
                                                      "sweep.start": "2 nm",
                                                      "sweep.stop": "0.6 nm"})
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")      # narrow steps are stiffer than a node
                seen[key] = run(sc, progress=False, estimate=False).headline["max_adhesion_N"]
        return seen[key]

    lim = pull_off(179, 100)
    widths = np.array([0.02, 0.01, 0.005])
    excess = np.array([pull_off(179, 100, w) - lim for w in widths])
    assert np.all(excess > 0) and np.all(np.diff(excess) < 0)
    assert observed_order(widths, excess) == pytest.approx(1.6, abs=0.3)
    ns = np.array([100, 200, 400])
    extra = np.array([pull_off(179, n) - pull_off(0, n) for n in ns])
    assert np.all(extra > 0)
    assert observed_order(1.0 / ns, extra) > 0.8
    assert extra[-1] < 0.1 * pull_off(0, 100)   # 7 % at N = 400
