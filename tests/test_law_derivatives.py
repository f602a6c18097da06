"""Every pressure law's three parts belong together, checked here by finite differences
written in the test (not through :func:`femadh.laws.check_law`, which is itself checked on
both sides of its tolerance).

Newton takes ``dpressure`` as the Jacobian of ``pressure`` and the landing after a fold
descends ``energy`` (dU/dh = P): a derivative off by a few per cent makes the solvers crawl or
land elsewhere instead of failing.
"""
import numpy as np
import pytest

from femadh.errors import LawError
from femadh.laws import LennardJones, Lj82, check_law
from femadh.laws.asperity import AsperityAdhesion
from femadh.laws.capillary import CapillaryCondensate
from femadh.laws.gw import GWAdhesion, GWElastic, Summits

SUMMITS = Summits(sigma_a=1.3e-9, z_m=1.1e-9, radius=0.94e-6, density=1.8e13)
LAWS = {
    "lj": (LennardJones(1e-19, 0.165e-9), np.geomspace(0.15e-9, 20e-9, 40)),
    "lj82": (Lj82(0.05, 0.3e-9), np.geomspace(0.25e-9, 20e-9, 40)),
    "gw_elastic": (GWElastic(SUMMITS, 9.5e10), np.linspace(-2e-9, 8e-9, 40)),
    "gw_adhesion": (GWAdhesion(SUMMITS, 0.05), np.linspace(-2e-9, 8e-9, 40)),
    # the step law over its transition (fill gap 1.6 nm +- 5 widths): saturated, its derivative
    # is below the difference quotient's round-off
    "capillary": (CapillaryCondensate(0.072, -0.5e-9, 0.3e-9),
                  np.linspace(1.44e-9, 1.76e-9, 40)),
    "asperity": (AsperityAdhesion(2e6, 1e-9, 0.02e-9), np.linspace(0.95e-9, 1.25e-9, 40)),
}


def central(f, h, step):
    return (f(h + step) - f(h - step)) / (2 * step)


def local_scale(x, half=3):
    """max |x| over the neighbouring samples (a derivative crossing zero keeps its scale)."""
    pad = np.pad(np.abs(x), half, mode="edge")
    return np.array([pad[i:i + 2 * half + 1].max() for i in range(len(x))])


@pytest.mark.parametrize("name", LAWS)
def test_derivative_and_energy_by_central_differences(name):
    """|dP/dh - central difference of P| and |P - central difference of U| within 1e-6 of the
    local scale (the largest |difference| of the neighbouring samples), steps 1e-6 of the gap
    (power laws) or of the sampled range (the rest): truncation and round-off ~1e-10,
    measured <= 2.2e-8 (GW elastic) on every law; a 1e-5 change of either part fails."""
    law, h = LAWS[name]
    step = 1e-6 * (h if h[0] > 0 and h[-1] / h[0] > 10 else (h[-1] - h[0]))
    for part, of in ((law.dpressure, law.pressure), (law.pressure, law.energy)):
        exact, fd = np.asarray(part(h)), central(of, h, step)
        err = np.max(np.abs(exact - fd) / local_scale(fd))
        assert err <= 1e-6, (name, part.__name__, err)


class Scaled:
    """A law whose derivative is ``factor`` times the true one (a planted inconsistency)."""

    def __init__(self, law, factor):
        self.law, self.factor = law, factor

    def pressure(self, h):
        return self.law.pressure(h)

    def dpressure(self, h):
        return self.factor * self.law.dpressure(h)

    def energy(self, h):
        return self.law.energy(h)


@pytest.mark.parametrize("name", ["lj", "gw_adhesion", "capillary"])
def test_check_law_on_both_sides_of_its_tolerance(name):
    """The law check (RTOL = 1e-4 of the local scale) accepts each law and a derivative 2e-5
    off, and refuses one 1e-3 off, naming the part."""
    law = LAWS[name][0]
    check_law(name, law)
    check_law(name, Scaled(law, 1 + 2e-5))
    with pytest.raises(LawError, match="dpressure is not the derivative"):
        check_law(name, Scaled(law, 1 + 1e-3))
