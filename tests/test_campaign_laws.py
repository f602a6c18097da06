"""Independent campaign (2026-11-25): identities of the laws that no other test asserted.

- the LJ law's work of adhesion is the energy it takes to separate from z0 (eq 19), and
  2 pi R times it is the rigid sphere's maximum force (eq 14);
- a capillary condensate built from a scene's liquid and isotherm fills the gap up to
  2 |r_K| + 2 t with t the isotherm's film, so a rigid sphere touching the flat feels the
  textbook 4 pi R gamma (1 + t/|r_K|).
"""
import math

import numpy as np
import pytest

from femadh.laws import LennardJones
from femadh.reference.rigid_lj import max_rigid_lj_force


def test_lj_work_of_adhesion_is_minus_the_energy_at_z0():
    for A, z0 in ((1e-19, 0.165e-9), (4e-20, 0.3e-9)):
        lj = LennardJones(A, z0)
        # identity (eq 19): measured relative difference <= 2e-16; tolerance 1e-13
        assert lj.work_of_adhesion == pytest.approx(-float(lj.energy(np.array([z0]))[0]),
                                                    rel=1e-13, abs=0)
        R = 2e-3
        # Derjaguin: 2 pi R dg = the rigid sphere's largest force A R / (8 z0^2) (eq 14)
        assert 2 * math.pi * R * lj.work_of_adhesion == pytest.approx(
            max_rigid_lj_force(A, z0, R), rel=1e-13, abs=0)


@pytest.mark.parametrize("x", [0.3, 0.6, 0.85])
def test_capillary_scene_law_carries_the_isotherm_film(x):
    from femadh.laws.capillary import REGISTRATION
    from femadh.meniscus.isotherms import default_isotherm
    from femadh.meniscus.kelvin import kelvin_radius
    from femadh.meniscus.liquids import LIQUIDS

    water = LIQUIDS["water"]
    T = 298.15
    built = REGISTRATION.build({"liquid": water, "relative_pressure": x, "temperature": T,
                                "isotherm": "default", "smoothing": 0.02}, None)
    law = built.laws["capillary"]
    r_k = kelvin_radius(water, x, T)
    t = float(default_isotherm("water")(x))
    assert t > 0.1 * abs(r_k)      # the film matters here (t/|r_K| = 0.2 ... 0.65)
    # rigid sphere touching the flat (Derjaguin): F = -2 pi R U(0)
    R = 1e-6
    F = -2 * math.pi * R * float(law.energy(np.array([0.0]))[0])
    expected = 4 * math.pi * R * water.surface_tension * (1 + t / abs(r_k))
    # the smoothed edge is exact up to softplus(50) - 50 ~ 2e-22: measured 1e-16; tol 1e-12
    assert F == pytest.approx(expected, rel=1e-12, abs=0)
