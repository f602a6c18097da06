"""The scene schema: every problem of a scene at once, each naming file, key, value and
expectation; suggestions for misspelt keys; units (offset temperatures, bare numbers); scenes
built and changed in code through the same validation; the reference page; resource checks."""
import math
from pathlib import Path

import pytest

import femadh
from conftest import fig3_uniform_text
from femadh.errors import DependencyError, SceneError, SceneErrors
from femadh.scene import Scene, reference_page, scene_from_dict
from femadh.scene.resources import check_resources, memory_estimate, physical_memory

ROOT = Path(__file__).resolve().parents[1]
SCENES = ROOT / "validation" / "scenes"
FIG3 = SCENES / "paper1_fig3.toml"


def write(tmp_path, text, name="s.toml"):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_every_error_of_a_scene_at_once(tmp_path):
    text = (fig3_uniform_text().replace("poisson_ratio = 0.3", "poisson_ratio = 0.7")
            .replace('sigma = "1.0 nm"', 'sigma = "1.0 kg"').replace("nodes = 200", "nodez = 200"))
    p = write(tmp_path, text)
    with pytest.raises(SceneErrors) as e:
        femadh.load_scene(p)
    keys = [x.key for x in e.value.errors]
    assert keys == ["materials.disk.poisson_ratio", "effects.asperity_gap.sigma",
                    "solver.nodez"]
    lines = str(e.value).splitlines()
    assert len(lines) == 3 and all(line.startswith(str(p)) for line in lines)
    assert "did you mean 'nodes'?" in lines[2]
    assert "(-1, 0.5)" in lines[0] and "'kg' is not a length unit" in lines[1]


def test_misspelt_table_and_effect_get_suggestions(tmp_path):
    p = write(tmp_path, fig3_uniform_text().replace("[effects.lennard_jones]",
                                                 "[effects.lenard_jones]"))
    with pytest.raises(SceneError, match="did you mean 'lennard_jones'"):
        femadh.load_scene(p)
    p = write(tmp_path, fig3_uniform_text().replace("[sweep]", "[swep]"))
    with pytest.raises(SceneError, match="did you mean 'sweep'"):
        femadh.load_scene(p)


def test_bare_number_for_a_length_is_refused_in_files_and_si_in_code(tmp_path):
    p = write(tmp_path, fig3_uniform_text().replace('radius = "2 mm"', "radius = 2"))
    with pytest.raises(SceneError, match="bare number has no unit") as e:
        femadh.load_scene(p)
    assert e.value.key == "sphere.radius"
    sc = femadh.load_scene(FIG3)
    data = dict(sc.raw, sphere={"radius": 2e-3})
    assert Scene.from_dict(data).sphere.radius == 2e-3


def test_offset_temperature_units(tmp_path):
    text = (SCENES / "paper1_slider_meniscus.toml").read_text()
    a = femadh.load_scene(write(tmp_path, text.replace(
        'isotherm = { model = "none" }', 'isotherm = { model = "none" }\ntemperature = "25 degC"')))
    b = femadh.load_scene(write(tmp_path, text.replace(
        'isotherm = { model = "none" }', 'isotherm = { model = "none" }\ntemperature = "298.15 K"'),
        "b.toml"))
    # the Kelvin radius follows the temperature: the same scene at 25 degC and 298.15 K
    assert a.effects["capillary"].kelvin_radius == pytest.approx(
        b.effects["capillary"].kelvin_radius, rel=1e-12, abs=0)


def test_replace_revalidates_and_recomputes_derived_values():
    sc = femadh.load_scene(FIG3)
    small = sc.replace({"sphere.radius": "1 mm"})
    # the analysis radius a = sqrt(2 R delta) follows R (delta = 10 nm): 4.47 um, not 6.32
    assert small.analysis_radius == pytest.approx(math.sqrt(2 * 1e-3 * 10e-9), rel=1e-14, abs=0)
    assert sc.analysis_radius == pytest.approx(math.sqrt(2 * 2e-3 * 10e-9), rel=1e-14, abs=0)
    soft = sc.replace(effects__asperity_gap__sigma="0.5 nm")
    assert soft.gap.sigma == pytest.approx(0.5e-9, rel=1e-14, abs=0) and sc.gap.sigma == 1e-9
    with pytest.raises(SceneError) as e:
        sc.replace({"materials.disk.poisson_ratio": 0.5})
    assert e.value.key == "materials.disk.poisson_ratio"


def test_a_value_given_to_replace_is_named_against_the_call_not_the_file(tmp_path):
    """A bad value given through ``scene.replace`` (a dict of dotted keys, a table given
    whole, keywords) is the call's, not the scene file's, which does not hold it (a newcomer
    trial was sent to look for it there): one line naming the call, the key, the value and
    what was expected. A line about a value the file does hold (the sigma a smaller sphere
    no longer admits) still names the file, and a file's own bad value names the file."""
    sc = femadh.load_scene(FIG3)
    want = "given to Scene.replace: [solver.accuracy] = -1: expected a number in (0, 0.1]"
    for args, kw in ((({"solver.accuracy": -1},), {}), (({"solver": {"accuracy": -1}},), {}),
                     ((), {"solver__accuracy": -1})):
        with pytest.raises(SceneError) as e:
            sc.replace(*args, **kw)
        assert str(e.value) == want, (args, kw)
    with pytest.raises(SceneErrors) as e:
        sc.replace({"sphere.radius": "0.5 nm", "solver.accuracy": -1})
    lines = {x.key: str(x) for x in e.value.errors}
    assert lines["solver.accuracy"] == want
    assert lines["effects.asperity_gap.sigma"].startswith(f"{FIG3}: [effects.asperity_gap.sigma]"
                                                          " = '1.0 nm': expected a sigma below")
    p = write(tmp_path, fig3_uniform_text().replace("[solver]\n", "[solver]\naccuracy = -1\n"))
    with pytest.raises(SceneError) as e:
        femadh.load_scene(p)
    assert str(e.value) == f"{p}: [solver.accuracy] = -1: expected a number in (0, 0.1]"


def test_eq20_model_choice_builds_the_constraint_or_the_law():
    sc = femadh.load_scene(SCENES / "paper1_fig8_rho179.toml")
    # default: eq 20 exactly on the contact set, carried by the sigma-gap
    assert sc.gap.adhesion == pytest.approx(2 * math.pi * 0.94e-6 * 0.06 * 179e12 * 0.5,
                                            rel=1e-12)
    assert "asperity_adhesion" not in sc.effects
    sm = sc.replace({"effects.asperity_adhesion.model": "smoothed"})
    assert sm.gap.adhesion == 0 and "asperity_adhesion" in sm.effects
    with pytest.raises(SceneError, match="contact-set"):
        sm.replace({"effects.asperity_gap.contact_model": "hertz-closure"})


@pytest.mark.parametrize("old,new,key", [
    ('tip_radius = "100 nm"', 'tip_radius = "1e-30 nm"', "meniscus.tip_radius"),
    ('liquid = "ethanol"', 'liquid = { name = {}, surface_tension = "22 mN/m", '
     'molar_volume = "58 cm^3/mol" }', "meniscus.liquid.name"),
    ('isotherm = { model = "gab", monolayer = "0.46 nm", c = 15, k = 0.7 }',
     'isotherm = { model = "tabulated", p_ratio = { a = 1 }, thickness = ["1 nm"] }',
     "meniscus.isotherm.p_ratio"),
    ('dir = "out/paper2-ethanol-100nm"', "dir = 3", "output.dir"),
    ("relative_pressure = [0.05, 0.1, 0.15, 0.2, 0.4, 0.6, 0.8, 0.95]",
     "relative_pressure = { start = 0.1, stop = 0.9, num = 100000000 }",
     "meniscus.relative_pressure.num"),
])
def test_bad_meniscus_values_name_their_key(tmp_path, old, new, key):
    text = (SCENES / "paper2_ethanol_100nm.toml").read_text()
    assert old in text
    with pytest.raises(SceneError) as e:
        femadh.load_scene(write(tmp_path, text.replace(old, new)))
    assert e.value.key == key


def test_reference_page_lists_every_key_of_the_bundled_scenes():
    """Every key used by a bundled scene appears in the generated page (the schema covers the
    scenes), with its expectation."""
    import tomllib

    page = reference_page()
    for path in SCENES.glob("*.toml"):
        data = tomllib.loads(path.read_text())
        stack = [data]
        while stack:
            t = stack.pop()
            for k, v in t.items():
                if isinstance(v, dict):
                    stack.append(v)
                assert f"`{k}`" in page or f"[{k}" in page or f".{k}]" in page, (path, k)
    assert "| `sigma` | a length > 0 | required |" in page


def test_resources_memory_estimate_and_missing_dependency(monkeypatch):
    sc = femadh.load_scene(FIG3)
    big = sc.replace({"solver.nodes": 20000})
    mem, _ = memory_estimate(big)
    assert mem == pytest.approx(11 * 8 * 20000**2, rel=1e-12)      # 11 dense N x N arrays
    total = physical_memory()
    if total and mem > 0.8 * total:
        with pytest.raises(SceneError, match="GiB") as e:
            check_resources(big)
        assert e.value.key == "solver.nodes"
    check_resources(sc)                        # the bundled scene fits
    import importlib.util

    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec",
                        lambda name, *a: None if name == "gmsh" else real(name, *a))
    fe = femadh.load_scene(SCENES / "paper1_fig3_fe.toml")
    with pytest.raises(DependencyError, match=r"pip install 'femadh\[fe\]'"):
        check_resources(fe)


def test_code_built_scene_matches_the_file():
    import tomllib

    data = tomllib.loads(fig3_uniform_text())
    a, b = femadh.load_scene(FIG3), scene_from_dict(data, str(FIG3))
    assert a.resolved == b.resolved


def test_fast_unit_path_agrees_with_pint():
    """The common units are converted without loading pint; the result equals pint's to
    round-off (measured <= 2.2e-16 relative)."""
    from femadh import units

    pint_only = {}
    for text, dim in [("2 mm", "length"), ("0.165 nm", "length"), ("1.08e-9 m", "length"),
                      ("163 GPa", "pressure"), ("1e-19 J", "energy"), ("0.06 J/m^2", "surface_energy"),
                      ("22 mN/m", "surface_energy"), ("100 um^-2", "areal_density"),
                      ("179 µm^-2", "areal_density"), ("298.15 K", "temperature"),
                      ("58.7 cm^3/mol", "molar_volume"), ("-5 nm", "length"), ("10 pm", "length")]:
        fast = units._fast(text, dim)
        assert fast is not None, text
        ureg = units._registry()
        mag, unit = units._split(text)
        ref = ureg.Quantity(float(mag), unit.replace("^", "**")).to(
            units.DIMENSIONS[dim][1].replace("^", "**")).magnitude
        assert fast == pytest.approx(ref, rel=1e-15, abs=0), text
        pint_only[text] = fast
    # anything else still goes through pint (offset temperatures, compound units)
    assert units._fast("25 degC", "temperature") is None
    assert units.to_si("25 degC", "temperature") == pytest.approx(298.15, rel=1e-15, abs=0)
    assert units._fast("2 mm", "pressure") is None          # wrong dimension: pint says why
