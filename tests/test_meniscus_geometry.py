"""The pendular ring's film geometry (paper 2 Fig 2b), pinned directly: the film-covered
sphere of radius R_e = R + h whose lowest point is s - 2h above the flat's film surface
(-2h in contact), and the meridian that runs from that film surface to that sphere."""
import math

import numpy as np
import pytest

from femadh.meniscus.geometry import Geometry
from femadh.meniscus.solve import meniscus


@pytest.mark.parametrize("D", [0.3, 0.0, -0.01])
def test_unit_geometry_sphere_points_and_smallest_filling_angle(D):
    """In units of R_e: the sphere point at filling angle phi is on the unit circle about
    (0, 1 + D), at (0, D) for phi = 0; below the flat (D < 0) the smallest filling angle puts
    it on the flat, z = 0 (and is 0 otherwise)."""
    geo = Geometry(-40.0, D)
    assert geo.zc == pytest.approx(1.0 + D, rel=1e-15, abs=0)
    for phi in (0.0, 0.2, 1.0):
        x, z = geo.sphere_point(phi)
        assert math.hypot(x, z - (1 + D)) == pytest.approx(1.0, rel=1e-14, abs=0)
        assert x == pytest.approx(math.sin(phi), abs=1e-15)
    assert geo.sphere_point(0.0) == pytest.approx((0.0, D), abs=1e-15)
    if D < 0:
        assert geo.sphere_point(geo.phi_min)[1] == pytest.approx(0.0, abs=1e-14)
        assert geo.sphere_point(0.5 * geo.phi_min)[1] < 0
    else:
        assert geo.phi_min == 0.0


@pytest.mark.parametrize("method", ["circular", "shooting", "fe"])
@pytest.mark.parametrize("separation", [None, 0.3e-9])
def test_meridian_runs_from_the_film_to_the_film_covered_sphere(method, separation):
    """The meniscus of a 100-nm sphere with 0.5-nm films at r_K = -2 nm: the meridian starts on
    the flat's film surface (z = 0) and ends on the film-covered sphere (radius R + h, lowest
    point at s - 2h: -1 nm in contact, -0.7 nm at s = 0.3 nm) at the filling angle: measured
    on it to 1.3e-16 of R_e."""
    R, h = 100e-9, 0.5e-9
    s = 0.0 if separation is None else separation
    res = meniscus(method, R, 0.072, -2e-9, film=h, separation=separation)
    r, z = np.asarray(res.r), np.asarray(res.z)
    Re, lowest = R + h, s - 2 * h
    assert z[0] == pytest.approx(0.0, abs=1e-12 * Re)
    assert math.hypot(r[-1], z[-1] - (lowest + Re)) == pytest.approx(Re, rel=1e-12, abs=0)
    assert r[-1] == pytest.approx(Re * math.sin(res.filling_angle), rel=1e-12, abs=0)
    # the contact line's height on that sphere (a lowest point one film off, s - h, moves it
    # by h = 5e5 x the tolerance)
    assert z[-1] == pytest.approx(lowest + Re * (1 - math.cos(res.filling_angle)),
                                  abs=1e-6 * h)
