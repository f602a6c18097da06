"""Pressure laws: finite-difference checks of derivatives and the LJ identities (eqs 3, 19)."""
import math

import numpy as np
import pytest

from femadh.contact import AsperityGap
from femadh.laws import LennardJones

from conftest import HAMAKER, Z0

LJ = LennardJones(HAMAKER, Z0)
H = np.linspace(0.12e-9, 3e-9, 37)


def test_lj_dpressure_matches_central_difference():
    eps = 1e-6 * H
    fd = (LJ.pressure(H + eps) - LJ.pressure(H - eps)) / (2 * eps)
    # central difference: truncation O(eps^2) ~ 1e-12 plus round-off ~1e-16/1e-6; measured
    # 1.7e-11 of the largest slope (1e-9 pointwise where the slope crosses zero)
    assert np.max(np.abs(LJ.dpressure(H) - fd)) <= 1e-10 * np.abs(fd).max()


def test_lj_pressure_is_derivative_of_energy():
    eps = 1e-6 * H
    fd = (LJ.energy(H + eps) - LJ.energy(H - eps)) / (2 * eps)
    # measured 2.2e-12 of the largest pressure
    assert np.max(np.abs(LJ.pressure(H) - fd)) <= 2e-11 * np.abs(fd).max()


def test_lj_identities():
    # scale of the law: A/z0^3 (Pa) and A/z0^4 (Pa/m); measured 0 and 5e-17 of them
    assert abs(LJ.pressure(Z0)) <= 1e-15 * HAMAKER / Z0**3                   # eq 3 at z0
    assert abs(LJ.dpressure(LJ.peak_gap)) <= 1e-15 * HAMAKER / Z0**4        # the peak
    # paper sec 5.1: 0.198 nm (3 digits)
    assert LJ.peak_gap == pytest.approx(0.198e-9, rel=1e-3, abs=0)
    assert -LJ.energy(Z0) == pytest.approx(HAMAKER / (16 * math.pi * Z0**2), rel=1e-14,
                                           abs=0)  # eq 19
    # far field: van der Waals A/(6 pi h^3) with the repulsive correction -(z0/h)^6 = -1e-12
    ratio = LJ.pressure(100 * Z0) / (HAMAKER / (6 * math.pi * (100 * Z0) ** 3))
    assert ratio - 1 == pytest.approx(-1e-12, rel=1e-3, abs=0)


def test_gap_rejects_unphysical():
    with pytest.raises(ValueError):
        AsperityGap(0.0)
    with pytest.raises(ValueError):
        AsperityGap(1e-9, "penalty")
