"""The figures say what the terminal says: the force curve's inset states the max adhesion
with the very digits, unit and error of the terminal's line, and every figure calls the force
it shows the force on the sphere (no "slider" in one figure and "sphere" in another)."""
import math
import re

import matplotlib
import numpy as np
import pytest

import femadh
from conftest import fig3_uniform_text
from femadh.io import plots
from femadh.io.plots import force_text, value_error_text
from femadh.runner.report import headline_lines


def test_force_text_picks_the_unit_of_the_force_and_one_digit_of_its_error():
    assert force_text(3.1152e-5, 2.56e-8) == "31.15 ± 0.03 µN"
    # (the unit is the force's own, not the error's: 2.6e-8 N would be nN alone)
    assert force_text(1.6029e-3, 4.4e-7) == "1.6029 ± 0.0004 mN"
    assert force_text(1.5e-3) == "1.5 mN" == force_text(1.5e-3, float("nan"))
    assert force_text(-2.5e-10, 1e-12) == "-250 ± 1 pN"


def test_value_printed_to_the_decimal_place_of_its_error():
    """Each value to the decimal place of its error's one digit (metrology's convention).
    The newcomer's three lines, with the values and errors of their summary.json: Fig 3 at
    accuracy 1e-4 printed F_ex -1.602 ± 5e-07 mN (0.0000443 mN off: 89 of its errors),
    Fig 4 at 1e-4 its max adhesion 109.5 ± 0.008 µN (0.0035 µN off), paper 2 (ethanol,
    100 nm) F = 60.227 ± 6e-07 nN (0.0002 nN off)."""
    assert force_text(-1.6020443099635687e-3, 4.64986340651508e-10) == "-1.6020443 ± 5e-07 mN"
    assert force_text(1.0949652642307841e-4, 8.173821861318682e-09) == "109.497 ± 0.008 µN"
    assert force_text(6.022721468895611e-08, 6.425871970492789e-16) == "60.2272147 ± 6e-07 nN"
    # the error rounded first sets the place (0.0096 -> 0.01); above 1 it is an integer;
    # a value smaller than half the error's digit is 0 (no "-0.0"); tiny numbers in e-form
    assert value_error_text(0.98765, 0.0096) == "0.99 ± 0.01"
    assert value_error_text(272.35, 46) == "270 ± 50"
    assert value_error_text(-0.01, 0.3) == "0 ± 0.3"
    assert value_error_text(1.2345e-15, 3e-18, 4) == "1.235e-15 ± 3e-18"
    # the form and the digits of the value rounded to the error's place (review: 9.99996e6
    # +- 100 printed 1.0000e+07, a digit short; 6e-4 +- 0.005 printed 6e-04, a place finer
    # than its error); an e-form value keeps its error in e-form
    assert value_error_text(9.99996e6, 100) == "1.00000e+07 ± 100"
    assert value_error_text(6e-4, 0.005) == "0.001 ± 0.005"
    assert value_error_text(1.5e9, 3e7) == "1.50e+09 ± 3e+07"
    # no error: the value to its digits, readable; an error of 0 says so
    assert value_error_text(1.23456789) == "1.2346" == value_error_text(1.23456789, math.nan)
    assert value_error_text(5.0, 0.0) == "5 ± 0"


def test_the_instrument_lines_print_each_value_to_its_errors_place():
    """The AFM scene's instrument lines (its summary.json values and errors, the run of the
    README's block): z, d and the hysteresis each to the decimal place of their error."""
    from types import SimpleNamespace

    hl = {"instrument_jump_in_z_m": 1.8385732680741112e-09,
          "instrument_jump_in_z_m_error": 3.232619966080636e-14,
          "instrument_jump_in_d_m": 1.226096964935722e-09,
          "instrument_jump_in_d_m_error": 7.244484546993736e-13,
          "instrument_hysteresis_J": 1.0699531673243805e-16,
          "instrument_hysteresis_J_error": 1.584026271128711e-20}
    lines = headline_lines(SimpleNamespace(
        headline=hl, instrument={"spring": {"stiffness_N_per_m": 0.3622}}, branches={},
        jumps=[], accuracy=None, status="converged", warnings=[]))
    assert lines[1:] == ["instrument jumps in at z = 1.83857 ± 3e-05 nm (d = 1.2261 ± 0.0007 "
                         "nm)", "instrument hysteresis 1.0700e-16 ± 2e-20 J"]


def test_the_regime_table_prints_the_pull_off_to_its_errors_place():
    """`femadh regime`'s table: the pull-off / πRΔγ to the decimal place of its error (was
    four decimals whatever the error: 1.2346 ± 2e-06, 1.2346 ± 0.003)."""
    from types import SimpleNamespace

    from femadh.studies.regime import regime_table

    def point(e):
        return SimpleNamespace(failed=None, mu=1.0, pull_off=1.23456789, error=lambda k: e,
                               maugis=1.2, jump_in=1.0, jump_out=0.5, hysteresis=0.0,
                               nodes=100)
    cells = [regime_table([point(e)]).splitlines()[1].split("  ") for e in (2e-6, 3e-3, None)]
    assert [next(c.strip() for c in r if "." in c and "1.23" in c) for r in cells] == [
        "1.234568 ± 2e-06", "1.235 ± 0.003", "1.2346"]


@pytest.fixture(scope="module")
def fig3_small(tmp_path_factory):
    """The Fig 3 scene on 60 uniform nodes in 0.5-nm steps, with its error estimates (the
    inset's ±), and the text of each figure it draws: {figure: [every text on it]}."""
    path = tmp_path_factory.mktemp("fig3") / "s.toml"
    path.write_text(fig3_uniform_text().replace("nodes = 200", "nodes = 60").replace(
        'step = "0.2 nm"', 'step = "0.5 nm"'))
    # (the run draws no figures of its own: the ones whose text is read are drawn below)
    res = femadh.run(femadh.load_scene(path), progress=False, figures=False)
    texts = {}
    real = plots._save

    def keep_text(fig, p, dpi=100):
        texts[p.name] = [t.get_text() for t in fig.findobj(matplotlib.text.Text)]
        real(fig, p, dpi)
    plots._save = keep_text
    try:
        plots.contact_figures(res, tmp_path_factory.mktemp("figures"))
    finally:
        plots._save = real
    return res, texts


def test_the_inset_states_the_terminal_s_max_adhesion(fig3_small):
    res, texts = fig3_small
    assert np.isfinite(res.headline["max_adhesion_N_error"])
    line = next(ln for ln in headline_lines(res) if ln.startswith("max adhesion "))
    inset = [t for t in texts["force_curve.png"] if t.startswith("max adhesion ")]
    # the terminal's line goes on with the DMT and JKR values: the inset is its beginning
    assert len(inset) == 1 and line.startswith(inset[0] + " ("), (inset, line)
    # the force and its separation each with its own error, to one digit, the value to that
    # digit's place (the separation was printed to four digits whatever its error)
    m = re.match(r"max adhesion ([\d.]+) ± ([\d.e-]+) µN at d = ([\d.]+) ± ([\d.e-]+) nm$",
                 inset[0])
    assert m, inset[0]
    for (v, e), name, s in ((m.group(1, 2), "max_adhesion_N", 1e6),
                            (m.group(3, 4), "d_at_max_adhesion_m", 1e9)):
        err = res.headline[f"{name}_error"] * s
        assert float(e) == float(f"{err:.1g}"), (name, e, err)
        place = math.floor(math.log10(float(e)))
        decimals = len(v.split(".")[1]) if "." in v else 0
        assert decimals == max(-place, 0), (name, v, e)
        assert abs(float(v) - res.headline[name] * s) <= 0.5 * 10.0**place, (name, v)


def test_every_figure_calls_the_force_the_force_on_the_sphere(fig3_small):
    _, texts = fig3_small
    assert set(texts) == {"force_curve.png", "profiles_and_forces.png"}
    for name, words in texts.items():
        assert not [t for t in words if "slider" in t], name
        assert [t for t in words if "force on the sphere" in t], name
    # panels (d) and (e) both: the force axis of each
    assert len([t for t in texts["profiles_and_forces.png"]
                if "force on the sphere" in t]) == 2


def test_a_prepared_six_panel_figure_is_the_same_picture(fig3_small, tmp_path, monkeypatch):
    """The figure worker lays the six panels out before the result arrives
    (plots.prepare): the PNG is the same, byte for byte, as one drawn from nothing, and
    the draw then makes none of the ~120 Tick objects of its 12 axes (measured: 121 made
    from nothing on this run; validation/figure_pace.py times both)."""
    import matplotlib.axis as maxis

    res, _ = fig3_small
    made, real = [0], maxis.Tick.__init__

    def count(self, *a, **k):
        made[0] += 1
        real(self, *a, **k)
    monkeypatch.setattr(maxis.Tick, "__init__", count)
    plots.paper1_panels(res, tmp_path / "new.png")
    from_nothing, made[0] = made[0], 0
    plots.prepare()
    # (prepare makes 12 a major axis, and a first minor tick: 156; a draw from nothing
    # makes what its axes show: 121 on this run)
    assert made[0] >= from_nothing >= 60
    made[0] = 0
    plots.paper1_panels(res, tmp_path / "prepared.png")
    assert made[0] == 0
    assert (tmp_path / "prepared.png").read_bytes() == (tmp_path / "new.png").read_bytes()
