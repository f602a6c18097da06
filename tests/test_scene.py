"""Scene files: the contract, and errors that name file, key, value and expectation."""
import json
from pathlib import Path

import pytest

import femadh
from femadh.cli import main
from femadh.errors import SceneError
from femadh.io.writers import CURVE_HEADER, read_curve

from conftest import fig3_uniform_text, check_curve_against_fields

ROOT = Path(__file__).resolve().parents[1]
FIG3 = ROOT / "validation" / "scenes" / "paper1_fig3.toml"


def write(tmp_path, text, name="s.toml"):
    p = tmp_path / name
    p.write_text(text)
    return p


def variant(tmp_path, old, new):
    text = fig3_uniform_text()
    assert old in text
    return write(tmp_path, text.replace(old, new))


def test_fig3_scene_loads_in_si():
    s = femadh.load_scene(FIG3)
    # unit conversion by pint: exact up to round-off
    assert s.sphere.radius == pytest.approx(2e-3, rel=1e-15, abs=0)
    assert s.e_star == pytest.approx(58.48e9, rel=1e-4)     # eq 2, paper: 58.5 GPa (4 digits)
    assert s.gap.sigma == pytest.approx(1e-9, rel=1e-15, abs=0)
    assert s.tolerance == pytest.approx(1e-19, rel=1e-15, abs=0)
    assert len(s.d_values) == 36 and s.d_values[0] == pytest.approx(2e-9, rel=1e-15, abs=0)
    assert s.analysis_radius == pytest.approx((2 * 2e-3 * 10e-9) ** 0.5, rel=1e-15, abs=0)


@pytest.mark.parametrize("old,new,key,expect", [
    ('poisson_ratio = 0.3', 'poisson_ratio = 0.5', "materials.disk.poisson_ratio", "(-1, 0.5)"),
    ('"163 GPa"', '"-163 GPa"', "materials.disk.youngs_modulus", "a pressure > 0"),
    ('sigma = "1.0 nm"', 'sigma = "0 nm"', "effects.asperity_gap.sigma", "a length > 0"),
    ('radius = "2 mm"', 'radius = "2 GPa"', "sphere.radius", "length"),
    ('stop = "-5 nm"', 'stop = "5 nm"', "sweep.stop", "below start"),
    ('nodes = 200', 'nodez = 200', "solver.nodez", "no such key"),
    ('radius = "2 mm"', '', "sphere.radius", "required"),
    ('contact_model = "complementarity"', 'contact_model = "penalty"',
     "effects.asperity_gap.contact_model", "one of"),
    ('step = "0.2 nm"', 'step = "0.3 nm"', "sweep.step", "whole steps"),
])
def test_bad_scene_names_file_key_value_expectation(tmp_path, old, new, key, expect):
    p = variant(tmp_path, old, new)
    with pytest.raises(SceneError) as ei:
        femadh.load_scene(p)
    msg = str(ei.value)
    assert str(p) in msg and f"[{key}]" in msg and expect in msg


def test_composite_modulus_alternative(tmp_path):
    text = fig3_uniform_text()
    start = text.index("[materials]")
    end = text.index("[effects.lennard_jones]")
    p = write(tmp_path, text[:start] + '[materials]\ncomposite_modulus = "58.5 GPa"\n\n' + text[end:])
    assert femadh.load_scene(p).e_star == pytest.approx(58.5e9, rel=1e-15)


def test_cli_run_writes_outputs_and_keeps_header(tmp_path):
    p = variant(tmp_path, 'nodes = 200', 'nodes = 60')
    out = tmp_path / "out"
    assert main(["run", str(p), "--out", str(out), "--quiet"]) == 0
    header = (out / "curve.csv").read_text().splitlines()[0]
    assert header == ",".join(CURVE_HEADER + ["crc32"])     # the row checksum last
    c = read_curve(out / "curve.csv")
    assert set(c["branch"]) == {"approach", "retract"} and c["converged"].all()
    # the force balance of eq 13 holds row by row, with forces integrated from fields.csv
    assert check_curve_against_fields(out) == len(c["d_m"])
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "converged" and summary["femadh_version"] == femadh.__version__
    assert (out / "profiles_and_forces.png").stat().st_size > 10_000
    assert (out / "fields.csv").exists()


def test_cli_bad_scene_exits_2_with_message(tmp_path, capsys):
    p = variant(tmp_path, 'poisson_ratio = 0.3', 'poisson_ratio = 0.7')
    assert main(["check", str(p)]) == 2
    err = capsys.readouterr().err
    assert "poisson_ratio" in err and "0.7" in err
