"""Pressure laws: finite-difference checks of derivatives and the LJ identities (eqs 3, 19)."""
import math

import numpy as np
import pytest

from femadh.effects import AsperityGap, LennardJones

from conftest import HAMAKER, Z0

LJ = LennardJones(HAMAKER, Z0)
H = np.linspace(0.12e-9, 3e-9, 37)


def test_lj_dpressure_matches_central_difference():
    eps = 1e-6 * H
    fd = (LJ.pressure(H + eps) - LJ.pressure(H - eps)) / (2 * eps)
    # 1e-8: central difference truncation O(eps^2) ~ 1e-12 relative plus round-off ~1e-10/1e-6
    assert np.allclose(LJ.dpressure(H), fd, rtol=1e-8, atol=1e-8 * np.abs(fd).max())


def test_lj_pressure_is_derivative_of_energy():
    eps = 1e-6 * H
    fd = (LJ.energy(H + eps) - LJ.energy(H - eps)) / (2 * eps)
    assert np.allclose(LJ.pressure(H), fd, rtol=1e-8, atol=1e-8 * np.abs(fd).max())


def test_lj_identities():
    assert LJ.pressure(Z0) == pytest.approx(0.0, abs=1e-9 * HAMAKER / Z0**3)  # eq 3 at z0
    assert LJ.dpressure(LJ.peak_gap) == pytest.approx(0.0, abs=1e-6 * HAMAKER / Z0**4)
    assert LJ.peak_gap == pytest.approx(0.198e-9, abs=5e-13)  # paper sec 5.1: 0.198 nm
    assert -LJ.energy(Z0) == pytest.approx(HAMAKER / (16 * math.pi * Z0**2), rel=1e-14)  # eq 19
    # far field: van der Waals A/(6 pi h^3)
    assert LJ.pressure(100 * Z0) == pytest.approx(HAMAKER / (6 * math.pi * (100 * Z0) ** 3), rel=1e-11)


def test_gap_rejects_unphysical():
    with pytest.raises(ValueError):
        AsperityGap(0.0)
    with pytest.raises(ValueError):
        AsperityGap(1e-9, "penalty")
