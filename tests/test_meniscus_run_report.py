"""What a meniscus run prints: every number says what it is and carries its estimated error,
or says that it has none and why (never a bare number that reads as exact)."""
import math
import re

import numpy as np
import pytest

from femadh.runner.meniscus import report_lines, run_meniscus
from femadh.scene import load_scene

SCENE = "validation/scenes/paper2_ethanol_100nm.toml"


@pytest.fixture(scope="module")
def run2():
    """The bundled ethanol scene at two of its p/psat (0.15: the largest force; 0.6), all four
    methods (0.1 s)."""
    sc = load_scene(SCENE).replace({"meniscus.relative_pressure": [0.15, 0.6]})
    res = run_meniscus(sc, progress=False)
    assert res.status == "converged"
    return res


def _curve(res, meth):
    (c,) = [c for (liq, R, m), c in res.curves.items() if m == meth]
    return c


def _line(lines, meth):
    (line,) = [x for x in lines if re.match(rf"ethanol +R = +100 nm {meth} ", x)]
    return line


def test_the_header_says_what_f_and_f_over_4_pi_r_gamma_are(run2):
    head = report_lines(run2)[0]
    assert "F: capillary force on the tip in contact" in head
    assert "F/4πRγ: F over 4πRγ (R the solid tip radius, γ the liquid's surface tension)" in head
    assert "largest of its 2 computed p/psat" in head


def test_the_fe_error_printed_is_the_distance_to_the_exact_meniscus(run2):
    """The FE line's ± (the meridian on half the elements, order 4) against the exact
    meniscus (shooting, ODE to 1e-12): |F_fe - F_shooting| / printed estimate measured
    1.0026 at p/psat 0.15 (0.14-0.28 % over the bundled sweep); the printed one-digit ±
    is within its rounding (a factor 1.5 either way) of the true error."""
    lines = report_lines(run2)
    line = _line(lines, "fe")
    assert "± the meridian on half the elements, order 4" in line
    m = re.search(r"F/4πRγ = ([\d.]+) ± ([\d.e+-]+), F = ([\d.]+) ± ([\d.e+-]+) nN "
                  r"\(4πRγ = ([\d.]+) nN\) at p/psat = 0.15", line)
    assert m, line
    fe, sh = _curve(run2, "fe"), _curve(run2, "shooting")
    true = abs(fe["force_N"][0] - sh["force_N"][0])
    for printed, scale in ((float(m.group(4)) * 1e-9, 1.0),
                           (float(m.group(2)), 1 / (4 * math.pi * 1e-7 * 0.02197))):
        assert true * scale / 1.5 <= printed <= 1.5 * true * scale, (printed, true * scale)
    # each value to the decimal place of its error's digit: within half that digit of the
    # computed one (60.227 ± 6e-07 nN was 2e-4 nN off, 350 of its errors)
    for v, e, exact in ((m.group(3), m.group(4), fe["force_N"][0] * 1e9),
                        (m.group(1), m.group(2), fe["force_over_4piRgamma"][0])):
        digit = 10.0 ** math.floor(math.log10(float(e)))
        assert abs(float(v) - exact) <= 0.5 * digit * (1 + 1e-9), (v, e, exact)
    # the two printed numbers agree with each other: F = F/4πRγ x 4πRγ
    assert float(m.group(1)) * float(m.group(5)) == pytest.approx(float(m.group(3)), rel=2e-4,
                                                                  abs=0)


def test_numbers_without_an_estimate_say_so(run2):
    """Shooting and the circular approximation print no ± (none is estimated) but the reason;
    the circular line gives its measured distance from the exact meniscus at that point."""
    lines = report_lines(run2)
    for meth, why in (("shooting", "no error estimate: the ODE is solved to 1e-12 relative"),
                      ("circular", "no error estimate: the toroidal approximation")):
        line = _line(lines, meth)
        assert why in line and "±" not in line, line
    circ = _line(lines, "circular")
    fe, ci = _curve(run2, "fe"), _curve(run2, "circular")
    dx = (ci["force_N"][0] - fe["force_N"][0]) / (4 * math.pi * 1e-7 * 0.02197)
    m = re.search(r", ([+-][\d.e+-]+) from fe here", circ)
    assert m and float(m.group(1)) == pytest.approx(dx, rel=0.05, abs=0), circ


def test_too_few_elements_for_an_estimate_is_not_an_exact_number(run2):
    """An FE meridian of 3 elements cannot be halved: its force has no estimate (nan in
    meniscus.csv, not 0) and the line says so."""
    sc = run2.scene.replace({"meniscus.elements": 3, "meniscus.methods": ["fe"]})
    res = run_meniscus(sc, progress=False)
    assert np.all(np.isnan(_curve(res, "fe")["force_error_N"]))
    line = _line(report_lines(res), "fe")
    assert "no error estimate: fewer than 4 elements" in line and "±" not in line
