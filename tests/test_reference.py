"""Reference solutions: limits and identities (they judge the solvers, so they are judged too)."""
import math

import numpy as np
import pytest

from femadh.reference import (dmt_contact_radius, jkr_contact_radius, jkr_pull_off,
                              surface_energy_from_hamaker, tabor_parameter)
from femadh.reference.maugis import (dmt_curve, jkr_approach, jkr_curve, jkr_load,
                                     lj_dugdale_lambda, maugis_curve, maugis_pull_off)


def test_maugis_tends_to_dmt_and_jkr():
    assert maugis_pull_off(1e-3) == pytest.approx(2.0, abs=1e-3)   # lambda -> 0: DMT
    assert maugis_pull_off(1e3) == pytest.approx(1.5, abs=1e-3)    # lambda -> inf: JKR
    vals = [maugis_pull_off(l) for l in (0.01, 0.1, 0.5, 1, 2, 5, 10)]
    assert np.all(np.diff(vals) < 0)  # monotone between the limits


def test_maugis_curve_approaches_jkr_curve_for_large_lambda():
    A, P, D = maugis_curve(200.0, 1.0 + np.logspace(-6, -2, 50))
    Pj, Dj = jkr_curve(A)
    # the cohesive zone shrinks as 1/lambda: the curves agree to O(1/lambda)
    assert np.max(np.abs(P - Pj)) < 2e-2 and np.max(np.abs(D - Dj)) < 2e-2


def test_maugis_curve_approaches_dmt_for_small_lambda():
    A, P, D = maugis_curve(1e-4, 1.0 + np.logspace(1, 3, 50))
    Pd, Dd = dmt_curve(A)
    sel = A > 0.5
    # the Dugdale zone's force differs from DMT's constant 2 by O(lambda) relative
    assert np.max(np.abs(P[sel] - Pd[sel]) / np.maximum(1.0, np.abs(Pd[sel]))) < 1e-2


def test_jkr_identities():
    R, E, dg = 1e-6, 50e9, 0.05
    # pull-off (load control) = 1.5 pi R dg at the minimum of the JKR load over a
    a = np.linspace(1e-9, 1e-7, 20001)
    loads = np.array([jkr_load(x, R, E, dg) for x in a])
    assert -loads.min() == pytest.approx(jkr_pull_off(R, dg), rel=1e-6)
    # load-radius relation of paper 1 sec 4 is the inverse of jkr_load
    for x in (2e-8, 5e-8, 8e-8):  # the stable branch, beyond the pull-off radius 1.5e-8 m
        assert jkr_contact_radius(jkr_load(x, R, E, dg), R, E, dg) == pytest.approx(x, rel=1e-9)
    assert jkr_approach(2e-8, R, E, dg) == pytest.approx(
        (2e-8) ** 2 / R - math.sqrt(2 * math.pi * 2e-8 * dg / E))
    assert dmt_contact_radius(-2 * math.pi * R * dg, R, E, dg) == pytest.approx(0.0, abs=1e-20)


def test_surface_energy_relations_eqs_17_19():
    A, z0 = 1e-19, 0.165e-9
    assert surface_energy_from_hamaker(A, z0, z0) == pytest.approx(A / (16 * math.pi * z0**2))
    # eq 18: far from z0 the repulsive correction vanishes
    s = 10 * z0
    assert surface_energy_from_hamaker(A, s, z0) == pytest.approx(A / (12 * math.pi * s**2),
                                                                  rel=1e-6)
    assert lj_dugdale_lambda(1.0) == pytest.approx(1.16, abs=0.005)  # Johnson & Greenwood 1997
    assert tabor_parameter(1.0, 1.0, 1.0, 1.0) == 1.0
