"""Capillary condensate inside contact scenes ([effects.capillary])."""
import math

import numpy as np
import pytest

from femadh.contact import ContactProblem, trace
from femadh.contact import AsperityGap
from femadh.laws import CapillaryCondensate
from femadh.elastic import GreenOperator, RadialGrid
from femadh.indenter import Sphere

from conftest import check_curve_against_fields

CAP = CapillaryCondensate(0.022, -5e-9, film=0.3e-9)
H = np.linspace(0.5e-9, 30e-9, 301)


def test_capillary_law_derivatives_by_finite_differences():
    eps = 1e-4 * CAP.width
    fd = (CAP.pressure(H + eps) - CAP.pressure(H - eps)) / (2 * eps)
    # central differences: O(eps^2 / w^2) ~ 1e-8 relative; measured 8.2e-10 of the peak slope
    assert np.max(np.abs(CAP.dpressure(H) - fd)) <= 5e-9 * np.abs(fd).max()
    fd = (CAP.energy(H + eps) - CAP.energy(H - eps)) / (2 * eps)
    # measured 1.6e-10 of the Laplace pressure
    assert np.max(np.abs(CAP.pressure(H) - fd)) <= 1e-9 * CAP.laplace_pressure
    # full Laplace pressure well inside, none well outside the filled gap: the logistic
    # tail is exp(-20) = 2.1e-9 of it 20 widths from the edge
    assert CAP.pressure(CAP.fill_gap - 20 * CAP.width) / CAP.laplace_pressure == \
        pytest.approx(1 - math.exp(-20), rel=1e-12)
    assert CAP.pressure(CAP.fill_gap + 20 * CAP.width) / CAP.laplace_pressure == \
        pytest.approx(math.exp(-20), rel=1e-6, abs=0)


def test_rigid_sphere_limit_is_4_pi_R_gamma():
    """E* -> inf, touching at h0 = sigma << |r_K|: F_cap = 4 pi R gamma (1 + t/|r_K|) minus the
    part of the filled gap the asperities occupy, (sigma / (2|r_K| + 2t))."""
    R, sigma = 1e-6, 0.05e-9
    cap = CapillaryCondensate(0.022, -5e-9, film=0.0)
    a = math.sqrt(2 * R * 4 * cap.fill_gap)
    expected = 4 * math.pi * R * cap.surface_tension * (1 - sigma / cap.fill_gap)
    errs = []
    for n in (200, 400):
        p = ContactProblem(GreenOperator(RadialGrid.uniform(a, n), 1e22), Sphere(R),
                           {"capillary": cap}, AsperityGap(sigma))
        s = trace(p, [sigma], branch="approach", tol=1e-19).states[0]
        errs.append(abs(p.grid.force(s.p_effects["capillary"]) / expected - 1))
    # midpoint sampling of the smoothed edge: measured 8.4e-6 and 2.1e-6, order 2
    assert errs[1] < 1e-5
    assert errs[0] / errs[1] == pytest.approx(4.0, rel=0.05)


@pytest.mark.slow
def test_scene_with_capillary_writes_F_cap_and_includes_it_in_F_ex(tmp_path):
    import femadh

    sc = femadh.load_scene("validation/scenes/paper1_slider_meniscus.toml")
    res = femadh.run(sc, str(tmp_path), figures=False, progress=False)
    assert res.status == "converged"
    header = (tmp_path / "curve.csv").read_text().splitlines()[0].split(",")
    assert header[-2:] == ["F_cap_N", "crc32"]     # the law's force, then the row checksum
    check_curve_against_fields(tmp_path)
    # paper 1 sec 6: the meniscus force 4 pi R gamma = 0.55 mN dwarfs the LJ adhesion
    c = res.curve("approach")
    four_pi_R_gamma = 4 * math.pi * 2e-3 * 0.02197
    # paper 1 sec 6 claims ~4 pi R gamma; femadh 0.988 x (sigma takes 4.9 % of the filled gap,
    # LJ and the meniscus area gained by the flattened contact add about as much)
    assert c["F_ex"].max() / four_pi_R_gamma == pytest.approx(1.0, abs=0.03)
    # and it is ~19x the LJ-only adhesion of the same slider (0.029 mN, test_contact)
    assert c["F_ex"].max() > 15 * 0.0294e-3


def test_meniscus_must_fit_in_analysis_radius(tmp_path):
    import femadh
    from femadh.errors import SceneError

    text = open("validation/scenes/paper1_slider_meniscus.toml").read()
    p = tmp_path / "s.toml"
    p.write_text(text.replace('delta = "50 nm"', 'delta = "10 nm"'))
    with pytest.raises(SceneError, match="filled gap"):
        femadh.load_scene(p)


def test_rigid_sphere_with_films_fills_a_gap_of_two_films():
    """Films of thickness t on both surfaces widen the condensate-filled gap to
    2|r_K| + 2t: a rigid sphere touching at h0 = sigma gets F = 2 pi R (gamma/|r_K|)
    (2|r_K| + 2t - sigma) = 4 pi R gamma (1 + t/|r_K| - sigma/(2|r_K|)) (midpoint rule on the
    smoothed edge: measured 2e-6 at N = 400)."""
    R, sigma, t = 1e-6, 0.05e-9, 1.0e-9
    cap = CapillaryCondensate(0.022, -5e-9, film=t)
    a = math.sqrt(2 * R * 4 * cap.fill_gap)
    p = ContactProblem(GreenOperator(RadialGrid.uniform(a, 400), 1e22), Sphere(R),
                       {"capillary": cap}, AsperityGap(sigma))
    s = trace(p, [sigma], branch="approach", tol=1e-19).states[0]
    rk = abs(cap.kelvin_radius)
    expected = 4 * math.pi * R * cap.surface_tension * (1 + t / rk - sigma / (2 * rk))
    assert p.grid.force(s.p_effects["capillary"]) == pytest.approx(expected, rel=1e-5)
