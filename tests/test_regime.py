"""Smooth-sphere regime map (femadh.studies.regime): Tabor range, accuracy on demand, guards,
and the peer benchmark's Lj82 law."""
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
    assert law.energy(0.3e-9) == pytest.approx(-0.05, rel=1e-14)
    assert law.pressure(0.3e-9) == pytest.approx(0.0, abs=1e-14 * scale)
    lj = LennardJones(law.hamaker, law.z0)
    assert np.max(np.abs(law.pressure(h) - lj.pressure(h))) < 1e-13 * scale
