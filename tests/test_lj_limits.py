"""The Lennard-Jones law (paper 1 eq 3) at h -> 0+: its values there are its exact limits
(P -> -inf, dP/dh -> +inf, U -> +inf: infinite repulsion), reached without a floating-point
warning (a failed contact solve evaluates its last iterate at gaps clamped to 1e-300 m: the
suite's 16 RuntimeWarnings), and a NaN made inside the law is still signalled."""
import warnings

import numpy as np
import pytest

from femadh.laws.lj import LennardJones

LJ = LennardJones(1e-19, 0.165e-9)
#: from contact down past every threshold: (z0/h)^6 overflows below ~1e-61 m, h^4, h^3, h^2
#: underflow below ~1e-81, 1e-108, 1e-162 m; 5e-324 the least double; 0 the limit itself
GAPS = np.array([1e-9, 0.165e-9, 0.1e-9, 1e-20, 1e-50, 1e-61, 1e-62, 1e-81, 1e-82, 1e-108,
                 1e-109, 1e-162, 1e-163, 1e-300, 5e-324, 0.0])


def _strict(fn, h):
    """fn(h) with every numpy floating-point event raised and every warning an error."""
    with warnings.catch_warnings(), np.errstate(all="raise"):
        warnings.simplefilter("error")
        return fn(h)


def test_the_limits_at_contact_without_a_warning():
    p, dp, u = (_strict(f, GAPS) for f in (LJ.pressure, LJ.dpressure, LJ.energy))
    for v in (p, dp, u):
        assert not np.any(np.isnan(v))
    below = GAPS < LJ.z0                     # the repulsive side: P < 0, dP/dh > 0, U > 0
    assert np.all(p[below] < 0) and np.all(dp[below] > 0) and np.all(u[below] > 0)
    # monotone all the way down (more repulsive, stiffer, higher), ending at the infinities
    pb, db, ub = p[below], dp[below], u[below]      # GAPS descend
    assert np.all(pb[1:] <= pb[:-1]) and np.all(db[1:] >= db[:-1]) and np.all(ub[1:] >= ub[:-1])
    assert p[-1] == -np.inf and dp[-1] == np.inf and u[-1] == np.inf
    assert np.isinf(p[GAPS == 1e-300]).all()
    # the far side is untouched: P(z0) = 0 exactly, attractive beyond it
    assert p[GAPS == LJ.z0][0] == 0.0 and p[0] > 0


def test_a_failed_solves_clamped_gaps_are_evaluated_quietly():
    """The gaps a stalled complementarity solve reports (an iterate with penetration, clamped
    to 1e-300 m): -inf pressure at the clamped nodes, the law's value elsewhere."""
    h = np.maximum(np.array([-2e-10, 0.0, 3e-10]), 1e-300)
    p = _strict(LJ.pressure, h)
    assert p[0] == p[1] == -np.inf
    assert p[2] == pytest.approx(1e-19 / (6 * np.pi * 27e-30) * (1 - (0.165 / 0.3) ** 6),
                                 rel=1e-14, abs=0)


def test_a_nan_made_in_the_law_is_still_an_error():
    """Only overflow, division by zero and underflow are the law's limits: an invalid
    operation (inf * 0 at P(z0) with an infinite Hamaker constant) still raises."""
    bad = LennardJones(np.inf, 0.165e-9)
    with pytest.raises(FloatingPointError):
        _strict(bad.pressure, np.array([0.165e-9]))
