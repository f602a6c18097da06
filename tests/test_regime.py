"""Smooth-sphere regime map (femadh.studies.regime): Tabor range, accuracy on demand, guards,
and the peer benchmark's Lj82 law."""
import functools
import math

import numpy as np
import pytest

from femadh.laws import LennardJones, Lj82, check_law

Z0, R, HAMAKER = 0.165e-9, 1e-6, 1e-19


def test_lj82_derivatives_by_finite_differences_and_its_minimum():
    """Lj82(w, z0): energy minimum -w at z0, pressure = dV/dh, P' = dP/dh by central
    differences (measured 2e-10 relative), accepted by check_law; it is the 9-3 pressure of
    eq (3) with A = 16 pi w z0^2 (measured 1.3e-15)."""
    law = Lj82(0.05, 0.3e-9)
    check_law("lj82", law)
    h = np.geomspace(0.2e-9, 20e-9, 200)
    eps = 1e-6 * h
    fd_p = (law.energy(h + eps) - law.energy(h - eps)) / (2 * eps)
    fd_dp = (law.pressure(h + eps) - law.pressure(h - eps)) / (2 * eps)
    scale = np.max(np.abs(law.pressure(h)))
    assert np.max(np.abs(fd_p - law.pressure(h))) < 1e-8 * scale
    assert np.max(np.abs(fd_dp - law.dpressure(h))) < 1e-8 * np.max(np.abs(law.dpressure(h)))
    assert law.energy(0.3e-9) == pytest.approx(-0.05, rel=1e-14, abs=0)
    assert law.pressure(0.3e-9) == pytest.approx(0.0, abs=1e-14 * scale)
    lj = LennardJones(law.hamaker, law.z0)
    assert np.max(np.abs(law.pressure(h) - lj.pressure(h))) < 1e-13 * scale


@functools.lru_cache(maxsize=None)
def _ref(mu):
    from femadh.studies.regime import lj_sphere
    return lj_sphere(mu, spacing=0.025)


@pytest.mark.parametrize("mu, accuracy", [(1.0, 1e-3), (2.0, 1e-3)])
def test_estimated_errors_bracket_the_true_errors(mu, accuracy):
    """Every headline quantity's a-posteriori estimate (Richardson from the coarser member of
    the family) is within 0.5-5x of its true error against a much finer grid (spacing 0.025
    ell), and the true error meets the request. Both points are traced with the grid following
    the edge (bistable: mu > 0.81); measured effectivities 1.15-1.22 at mu = 1 (refined once
    to 0.067 ell: the hysteresis, 0.08 of its floor 0.1, was estimated 3.2e-3 at 0.133) and
    1.03-1.85 at mu = 2 (0.133 ell, coarser member 0.167)."""
    from femadh.studies.regime import QUANTITIES, lj_sphere

    p, ref = lj_sphere(mu, accuracy=accuracy), _ref(mu)
    assert p.accuracy == accuracy and p.spacing_m > 0 and p.nodes > 10
    checked = 0
    for k in QUANTITIES:
        v, r, est = getattr(p, k), getattr(ref, k), p.error(k)
        assert (v is None) == (r is None) == (est is None)
        if v is None:
            continue
        true = abs(v - r)
        assert true <= accuracy * max(abs(r), 0.1)
        # below ~2e-5 relative non-smooth noise of the grids that Richardson does not see
        # can dominate (measured: the moving band's fixed-grip pull-off at mu = 2, 1.5e-5
        # true vs 4.4e-6 estimated): effectivity is asserted above that level
        if true > 2e-5 * abs(r):
            assert 0.5 <= est / true <= 5.0, (k, est, true)
            checked += 1
    assert checked >= 2


def test_accuracy_asked_of_the_pull_off_alone_is_met_not_over_delivered():
    """mu = 2, 3e-3 asked of the load-controlled pull-off only: with the grid following the
    edge there is no lattice cap, the spacing starts at the edge family's asymptotic cap
    (0.133 ell, coarser member 0.167; 109 nodes); the true error against spacing 0.025 ell
    meets the request and is not below a thirtieth of it (measured 2.3e-4); the estimate is
    conservative (measured effectivity 1.85, asserted within 1-5). Bad names are refused in
    one line."""
    from femadh.studies.regime import COARSE_RATIO_EDGE, MAX_SPACING_EDGE, lj_sphere

    acc = 3e-3
    p, ref = lj_sphere(2.0, accuracy=acc, judged=("pull_off",)), _ref(2.0)
    assert p.judged == ("pull_off",)
    assert p.resolution.spacing == pytest.approx(MAX_SPACING_EDGE / COARSE_RATIO_EDGE,
                                                 rel=1e-12, abs=0)
    true = abs(p.pull_off - ref.pull_off) / ref.pull_off
    assert acc / 30 <= true <= acc
    assert 1.0 <= p.relative_error("pull_off") / true <= 5.0
    with pytest.raises(ValueError, match="judged must name"):
        lj_sphere(2.0, accuracy=acc, judged=("pull_of",))


def test_pull_offs_against_maugis_dugdale_and_the_fixed_grip_limit():
    """mu = 3: the load-controlled pull-off lies between JKR and DMT and within 3 % of MD
    (LJ vs Dugdale shape, measured 2.5 %); the displacement-controlled pull-off (tension at the
    jump-out) lies between JKR's fixed-grip 5/6 and the load-controlled one, within 5 % of MD's
    fixed-grip value (measured 3.5 %); no node softens beyond half its stiffness."""
    from femadh.studies.regime import lj_sphere

    p = lj_sphere(3.0)
    assert 1.5 < p.pull_off < 2.0
    assert p.pull_off == pytest.approx(p.maugis, rel=0.03)
    assert 5 / 6 < p.pull_off_displacement < p.pull_off
    assert p.pull_off_displacement == pytest.approx(p.maugis_displacement, rel=0.05)
    assert p.jump_out > p.jump_in and p.n_folds == 2
    assert p.trapping_ratio < 0.5


def test_unresolved_grid_is_refused_with_the_setting_to_change():
    """A band spacing 30x the default lets single nodes snap (node softening ratio > 1; the
    edge-following trace refuses such a grid before tracing): no map point is reported; the
    message names the ratio and the setting. regime_map keeps the point, marked failed."""
    from femadh.studies.regime import ResolutionError, lj_sphere, regime_map

    with pytest.raises(ResolutionError) as e:
        lj_sphere(2.0, spacing=3.0)
    msg = str(e.value)
    assert "-P'(h)/K_kk" in msg and "spacing" in msg
    pts = regime_map([2.0], spacing=3.0)
    assert pts[0].failed and math.isnan(pts[0].pull_off)
    # the arclength trace on the moving band refuses it after tracing (its own guard)
    from femadh.studies.regime import Resolution
    with pytest.raises(ResolutionError) as e:
        lj_sphere(2.0, spacing=3.0, resolution=Resolution(follow_edge=False))
    assert "-P'(h)/K_kk" in str(e.value) and "spacing" in str(e.value)


def test_lattice_cap_bounds_the_moving_band_where_the_fixed_grip_pull_off_is_judged():
    """On the moving band (follow_edge=False) the jump-out fold's lattice wiggles cap the
    starting spacing when the fixed-grip pull-off is judged (mu = 2: 0.05 ell, measured), and
    do not when only the pull-off is; the edge-following trace has no such cap (0.133)."""
    from femadh.studies.regime import R_DEFAULT, Resolution, lattice_cap, lj_sphere

    band = Resolution(follow_edge=False)
    cap = lattice_cap(2.0, R_DEFAULT, LennardJones(HAMAKER, Z0))
    p = lj_sphere(2.0, accuracy=3e-3, resolution=band)
    assert p.resolution.spacing <= cap * (1 + 1e-12) and p.failed is None
    q = lj_sphere(2.0, accuracy=3e-3, resolution=band, judged=("pull_off",))
    assert q.resolution.spacing > 2 * cap


def _trace_only(mu, **res):
    """One traced curve and its read-out on the banded grid (no coarser member)."""
    from femadh.studies.regime import R_DEFAULT, Resolution, solve_point

    return solve_point(mu, R_DEFAULT, LennardJones(HAMAKER, Z0), Resolution(**res), 1e-19, None)


def test_band_follows_the_edge_through_the_jump_out_fold():
    """mu = 4, band half-width 1 ell: near the jump-out fold the contact edge travels ~2 ell
    while |dd/ds| < 0.05; grid exchanges there (state carried over on the tangent's normal
    hyperplane) keep the edge within 0.65 half-widths of the band centre (measured; 2.9
    when exchanges wait for |dd/ds| >= 0.05: the edge leaves the band and nodes soften to
    0.30 of their stiffness, against 0.16 inside it)."""
    q = _trace_only(4.0, band=1.0, spacing=0.1, follow_edge=False)
    assert q["band_offset"] < 0.8
    assert q["trapping"] < 0.2
    assert q["n_folds"] == 2 and q["n_grids"] > 10


def test_stability_flags_agree_with_the_hessian_through_four_folds():
    """mu = 5: the curve folds four times (jump-in; a second mode of the energy Hessian turns
    negative; it turns back; jump-out). Stability is not a plain parity of folds: every
    traced point away from a fold carries the Hessian's verdict, and the piece between the
    second and third fold is unstable (index 2, measured 2 negative eigenvalues)."""
    from femadh.contact.stability import is_positive_definite
    from femadh.studies.regime import Resolution, PointSetup, trace_point

    setup = PointSetup(5.0, R, LennardJones(HAMAKER, Z0), Resolution(spacing=0.1))
    curve = trace_point(setup, 1e-19, None)
    assert len(curve.folds) == 4
    near = {f.index + k for f in curve.folds for k in (0, 1)}
    checked = 0
    for i, p in enumerate(curve.points):
        if i in near or abs(p.t_d) < 0.05:
            continue
        pb = curve.problem_of(p.seg)
        assert is_positive_definite(pb.energy_hessian(pb.contour(p.d) - p.w)) == p.stable, i
        checked += 1
    assert checked > 100
    between = range(curve.folds[1].index + 1, curve.folds[2].index + 1)
    assert between and not any(curve.points[i].stable for i in between)
