"""Capillary condensate inside contact scenes ([effects.capillary])."""
import math

import numpy as np
import pytest

from femadh.contact import ContactProblem, trace
from femadh.effects import AsperityGap, CapillaryCondensate
from femadh.elastic import GreenOperator, RadialGrid
from femadh.indenter import Sphere

CAP = CapillaryCondensate(0.022, -5e-9, film=0.3e-9)
H = np.linspace(0.5e-9, 30e-9, 301)


def test_capillary_law_derivatives_by_finite_differences():
    eps = 1e-4 * CAP.width
    fd = (CAP.pressure(H + eps) - CAP.pressure(H - eps)) / (2 * eps)
    # central differences: O(eps^2 / w^2) ~ 1e-8 relative to the peak slope
    assert np.allclose(CAP.dpressure(H), fd, atol=1e-6 * np.abs(fd).max())
    fd = (CAP.energy(H + eps) - CAP.energy(H - eps)) / (2 * eps)
    assert np.allclose(CAP.pressure(H), fd, atol=1e-6 * CAP.laplace_pressure)
    # full Laplace pressure well inside, none well outside the filled gap
    assert CAP.pressure(CAP.fill_gap - 20 * CAP.width) == pytest.approx(CAP.laplace_pressure)
    assert CAP.pressure(CAP.fill_gap + 20 * CAP.width) < 1e-8 * CAP.laplace_pressure


def test_rigid_sphere_limit_is_4_pi_R_gamma():
    """E* -> inf, touching at h0 = sigma << |r_K|: F_cap = 4 pi R gamma (1 + t/|r_K|) minus the
    part of the filled gap the asperities occupy, (sigma / (2|r_K| + 2t))."""
    R, sigma = 1e-6, 0.05e-9
    cap = CapillaryCondensate(0.022, -5e-9, film=0.0)
    a = math.sqrt(2 * R * 4 * cap.fill_gap)
    p = ContactProblem(GreenOperator(RadialGrid.uniform(a, 400), 1e22), Sphere(R),
                       {"capillary": cap}, AsperityGap(sigma))
    s = trace(p, [sigma], branch="approach", tol=1e-19).states[0]
    F = p.grid.force(s.p_effects["capillary"])
    expected = 4 * math.pi * R * cap.surface_tension * (1 - sigma / cap.fill_gap)
    # the smoothed edge spans ~2 nodes: midpoint sampling of it costs ~1e-4
    assert F == pytest.approx(expected, rel=5e-4)


def test_scene_with_capillary_writes_F_cap_and_includes_it_in_F_ex(tmp_path):
    import femadh

    sc = femadh.load_scene("validation/scenes/paper1_slider_meniscus.toml")
    res = femadh.run(sc, str(tmp_path), figures=False, progress=False)
    assert res.status == "converged"
    header = (tmp_path / "curve.csv").read_text().splitlines()[0].split(",")
    assert header[-1] == "F_cap_N"
    import csv
    rows = list(csv.DictReader(open(tmp_path / "curve.csv")))
    for r in rows:
        f_ex = float(r["F_LJ_N"]) + float(r["F_cap_N"]) - float(r["F_el_N"])
        assert float(r["F_ex_N"]) == pytest.approx(f_ex, rel=1e-12, abs=1e-18)
    # paper 1 sec 6: the meniscus force 4 pi R gamma = 0.55 mN dwarfs the LJ adhesion
    c = res.curve("approach")
    four_pi_R_gamma = 4 * math.pi * 2e-3 * 0.02197
    assert c["F_ex"].max() == pytest.approx(four_pi_R_gamma, rel=0.03)


def test_meniscus_must_fit_in_analysis_radius(tmp_path):
    import femadh
    from femadh.errors import SceneError

    text = open("validation/scenes/paper1_slider_meniscus.toml").read()
    p = tmp_path / "s.toml"
    p.write_text(text.replace('delta = "50 nm"', 'delta = "10 nm"'))
    with pytest.raises(SceneError, match="filled gap"):
        femadh.load_scene(p)
