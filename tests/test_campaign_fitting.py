"""Independent campaign (2026-11-25): the fit's standard errors are the linearised ones.

At the least-squares solution the covariance is s^2 (J^T J)^-1 with J the derivative of the
model force with respect to the parameters themselves (here the Hamaker constant in J and the
contact-point offset in m) and s^2 = RSS/(n - p), whatever the fit's internal scaling and
wherever it started. J is rebuilt here by central differences of independent runs at the
fitted values; the fit starts 27 % below the fitted Hamaker constant so that a derivative taken
in the wrong unknowns (relative to the start) shows.
"""
import numpy as np

from conftest import fig3_uniform_text
from femadh.fitting.lsq import fit_curve, simulate
from femadh.io.force_curve import ForceCurve
from femadh.scene import load_scene

A_TRUE, OFFSET_TRUE, KEY = 1.1e-19, 3e-9, "effects.lennard_jones.hamaker"


def test_fit_standard_errors_are_the_linearised_covariance(tmp_path):
    text = fig3_uniform_text().replace("nodes = 200", "nodes = 80")
    text = text.replace('dir = "out/paper1-fig3"', f'dir = "{tmp_path / "out"}"')
    (tmp_path / "fig3.toml").write_text(text)
    scene = load_scene(tmp_path / "fig3.toml")
    sim, err = simulate(scene.replace({KEY: A_TRUE}, si=True))
    assert err is None
    n_b = 30
    d = np.linspace(1.9, -0.3, n_b) * 1e-9 + 0.037e-9
    d = np.r_[d, d[::-1]]
    branch = np.array(["approach"] * n_b + ["retract"] * n_b)
    clean = sim.force_at(d, branch, 0.0)
    noise = 0.01 * np.max(np.abs(clean)) * np.random.default_rng(7).standard_normal(d.size)
    curve = ForceCurve(d + OFFSET_TRUE, clean + noise, branch, "synthetic")

    start = scene.replace({KEY: 0.8e-19}, si=True)
    r = fit_curve(start, curve, [KEY], workers=1)
    A, off = r.values
    assert A / 0.8e-19 > 1.25                     # the fit moved far from its start

    step = 1e-3 * A
    plus, _ = simulate(scene.replace({KEY: A + step}, si=True))
    minus, _ = simulate(scene.replace({KEY: A - step}, si=True))
    J = np.empty((curve.z.size, 2))
    J[:, 0] = (plus.force_at(curve.z, curve.branch, off)
               - minus.force_at(curve.z, curve.branch, off)) / (2 * step)
    J[:, 1] = r.sim.slope_at(curve.z, curve.branch, off, 1e-12)
    s2 = r.rss / (r.n - 2)
    stderr = np.sqrt(np.diag(s2 * np.linalg.inv(J.T @ J)))
    # measured: fit / linearised = 0.99971 (Hamaker), 0.99996 (offset), the difference steps'
    # noise; tolerance 0.5 % (17x). A derivative in units of the start is 27 % off here.
    assert abs(r.stderr[0] / stderr[0] - 1) < 0.005
    assert abs(r.stderr[1] / stderr[1] - 1) < 0.005
