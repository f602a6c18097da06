"""A contact scene made of frozen parts (body, laws, discretisation, sweep, output), and the
key a study's worker keeps a surface operator under: the content hash of the pair the operator
is built from, ``(scene.body, scene.discretisation)``.

The key's tests enumerate the parts' fields (``dataclasses.fields``) rather than naming them,
so that a field added to a part is tested without anyone remembering to: every field of the
body and the discretisation changes the key, no field of the other parts does. (The key it
replaces was a hand-written tuple of "everything the operator reads".)
"""
import copy
import dataclasses
import math
import pickle
from pathlib import Path

import numpy as np
import pytest

import femadh
from femadh.contact.constraints import AsperityGap
from femadh.instrument import Spring
from femadh.materials import IsotropicMaterial
from femadh.scene import build_operator, operator_key, scene_id
from femadh.scene.parts import Body, Discretisation, Laws, Output, Sweep
from femadh.studies.executors import study_operator_key, worker_operator, OPERATOR_CACHE
from femadh.studies.sweep import study_points

SCENES = Path(__file__).resolve().parents[1] / "validation" / "scenes"

#: scene ids computed on main at 36c0894 (the flat 24-field Scene, before the parts) with
#: femadh.scene.scene_id: a run folder or a study point written then is known again (resume,
#: reuse) only if the parts give every bundled scene the same id
IDS_BEFORE_THE_PARTS = {
    "afm_tip_cantilever.toml": "ebe6294bd187c200",
    "lj_sphere_mu2_arclength.toml": "50054c6a9867525f",
    "paper1_fig3.toml": "f40c5bf4d7ff4626",
    "paper1_fig3_fe.toml": "e94f4a697922c94a",
    "paper1_fig4.toml": "0dd0fc39b6a555ce",
    "paper1_fig4_coated.toml": "bb2c8d20b70d98b5",
    "paper1_fig6_sigma0.20.toml": "9d15673215073c24",
    "paper1_fig8_rho179.toml": "d06a182d14b475b0",
    "paper1_slider_gw.toml": "f64e6247393a5951",
    "paper1_slider_meniscus.toml": "1f65548b376fe9e9",
    "paper2_alcohols.toml": "1ee0b38998ad07c1",
    "paper2_ethanol_100nm.toml": "3e42a19c1e019a50",
}
#: study points (scenes built by replace), same origin
REPLACED_IDS_BEFORE_THE_PARTS = [
    ("paper1_fig3.toml", {"effects.asperity_gap.sigma": "0.8 nm"}, "df32488d584ce6de"),
    ("paper1_fig3.toml", {"solver.nodes": 100, "sweep.stop": "-1 nm"}, "27bece1b91bd06d2"),
    ("paper1_fig4_coated.toml", {"substrate.layers.0.youngs_modulus": "40 GPa"},
     "e9a63d57a9a38ae8"),
]

#: a value for a field whose value in the scenes below is None (a field added with a None
#: default needs an entry here: the enumeration below refuses to skip it)
WHEN_NONE = {
    "disk": IsotropicMaterial(100e9, 0.3),
    "slider": IsotropicMaterial(80e9, 0.2),
    "grid": {"spacing": 1e-8, "band": 1e-6, "grading": 1e-6},
    "mesh": {"outer_factor": 1e4, "growth": 0.25, "surface_fraction": 0.5,
             "far_field": "boussinesq"},
    "accuracy": 1e-3,
    "time_limit": 60.0,
    "gap": AsperityGap(1e-9),
    "topography": {"asperity_density": 1e12},
    "instrument": Spring(1.0),
    "study": {"vary": {"sphere.radius": "1 um,2 um"}, "zip": False},
    "path": "elsewhere.toml",
}

#: the same for a field that is an empty tuple
WHEN_EMPTY = {"layers": ((1e-8, 1e11, 0.25),)}


def coated():
    """The layered FE scene: every body field set (disk, slider, layers), an FE mesh."""
    return femadh.load_scene(SCENES / "paper1_fig4_coated.toml")


def green():
    """The Fig 3 Green scene with explicit nodes (not adaptive: its operator is kept)."""
    return femadh.load_scene(SCENES / "paper1_fig3.toml").replace({"solver.nodes": 60})


def variants(name, value):
    """Values that differ from ``value`` in one place each, as little as possible: a float
    by one ulp, an int by one, a flag flipped, a string extended, one element of a tuple or
    one entry of a table, one field of a dataclass (recursively). Built without validation
    (the key is computed from the values, whatever they are)."""
    if value is None:
        assert name in WHEN_NONE, f"no value for the field {name!r} that is None: add one " \
                                  "to WHEN_NONE"
        yield WHEN_NONE[name]
    elif isinstance(value, bool):
        yield not value
    elif isinstance(value, int):
        yield value + 1
    elif isinstance(value, float):
        yield math.nextafter(value, math.inf)
    elif isinstance(value, str):
        yield value + "_other"
    elif isinstance(value, tuple) and not value:
        assert name in WHEN_EMPTY, f"no value for the empty {name!r}: add one to WHEN_EMPTY"
        yield WHEN_EMPTY[name]
    elif isinstance(value, tuple):
        for i, x in enumerate(value):
            for v in variants(f"{name}[{i}]", x):
                yield value[:i] + (v,) + value[i + 1:]
    elif isinstance(value, dict):
        for k, x in value.items():
            for v in variants(k, x):
                yield type(value)({**value, k: v}) if type(value) is dict else \
                    _frozen({**value, k: v})
    elif dataclasses.is_dataclass(value):
        for f in dataclasses.fields(value):
            for v in variants(f.name, getattr(value, f.name)):
                yield _with(value, f.name, v)
    else:
        pytest.fail(f"no variant of {name!r}, a {type(value).__name__}: teach variants()")


def _frozen(d):
    from femadh.scene.parts import FrozenMap

    return FrozenMap(d)


def _with(obj, name, value):
    """A copy of a (frozen) dataclass with one field set, without its validation."""
    new = copy.copy(obj)
    object.__setattr__(new, name, value)
    return new


def part_variants(scene, part):
    """(field, scene with one field of the part changed) for every field of the part."""
    p = getattr(scene, part)
    for f in dataclasses.fields(p):
        for v in variants(f.name, getattr(p, f.name)):
            yield f.name, dataclasses.replace(scene, **{part: _with(p, f.name, v)})


@pytest.mark.parametrize("name", sorted(IDS_BEFORE_THE_PARTS))
def test_bundled_scenes_keep_their_ids(name):
    assert scene_id(femadh.load_scene(SCENES / name)) == IDS_BEFORE_THE_PARTS[name]


@pytest.mark.parametrize("name, changes, sid", REPLACED_IDS_BEFORE_THE_PARTS)
def test_study_points_keep_their_ids(name, changes, sid):
    assert scene_id(femadh.load_scene(SCENES / name).replace(changes)) == sid


@pytest.mark.parametrize("make", [coated, green])
@pytest.mark.parametrize("part", ["body", "discretisation"])
def test_every_field_the_operator_is_built_from_changes_its_key(make, part):
    """One ulp of the modulus, one node, the slider's Poisson ratio, a layer's thickness,
    the mesh's growth, a flag: each gives another key (with ``None`` when the change makes
    the run adaptive: it then keeps no operator at all)."""
    sc = make()
    key = study_operator_key(sc)
    assert key is not None and key == operator_key(sc.body, sc.discretisation)
    seen = 0
    for name, other in part_variants(sc, part):
        assert study_operator_key(other) != key, f"{part}.{name} is not in the operator's key"
        seen += 1
    assert seen >= len(dataclasses.fields(getattr(sc, part)))


@pytest.mark.parametrize("make", [coated, green])
@pytest.mark.parametrize("part", ["laws", "sweep", "output"])
def test_no_field_of_the_laws_sweep_or_output_changes_the_key(make, part):
    sc = make()
    key = study_operator_key(sc)
    seen = 0
    for name, other in part_variants(sc, part):
        assert study_operator_key(other) == key, f"{part}.{name} changed the operator's key"
        seen += 1
    assert seen >= len(dataclasses.fields(getattr(sc, part)))


def test_the_scenes_name_path_study_and_raw_are_not_in_the_key():
    sc = green()
    key = study_operator_key(sc)
    for name in ("name", "path", "study"):
        for v in variants(name, getattr(sc, name)):
            assert study_operator_key(dataclasses.replace(sc, **{name: v})) == key, name
    assert study_operator_key(dataclasses.replace(sc, raw={})) == key


def test_the_operator_is_a_function_of_its_key():
    """Scenes that differ in laws, sweep and output share a key and get bit-identical
    operators; E* changed (same grid) gives another key and, the Green function being
    C = f(grid) / E* (paper 1 eq 3), C * E* equal to rounding (measured 5.7e-15 of the largest
    entry, the edge displacements' differences losing digits; bound 4x that, 2.5e-14)."""
    sc = green()
    other = sc.replace({"effects.asperity_gap.sigma": "0.8 nm", "sweep.stop": "-1 nm",
                        "output.dir": "elsewhere"})
    assert study_operator_key(other) == study_operator_key(sc)
    c0, c1 = build_operator(sc).compliance, build_operator(other).compliance
    assert np.array_equal(c0, c1)
    stiff = sc.replace({"materials.disk.youngs_modulus": "400 GPa"})
    assert study_operator_key(stiff) != study_operator_key(sc)
    c2 = build_operator(stiff).compliance
    scaled = np.abs(c2 * stiff.e_star - c0 * sc.e_star).max() / np.abs(c0 * sc.e_star).max()
    assert 0 <= scaled <= 2.5e-14
    assert stiff.e_star / sc.e_star > 1.2        # a stiffer disk: E* 24 % up (the slider)


def test_no_field_of_the_laws_sweep_or_output_reaches_the_operator():
    """What the key leaves out, the operator must not read: with any one field of the laws,
    the sweep or the output changed (unvalidated, so a read of it shows), the built operator
    is bit for bit the scene's."""
    sc = green().replace({"solver.nodes": 24})
    c0 = build_operator(sc).compliance
    n = 0
    for part in ("laws", "sweep", "output"):
        for name, other in part_variants(sc, part):
            assert np.array_equal(build_operator(other).compliance, c0), f"{part}.{name}"
            n += 1
    assert n >= 8


def test_study_points_share_an_operator_exactly_when_their_pairs_agree():
    """A sweep of a law's value keeps one operator; a sweep of the nodes does not."""
    OPERATOR_CACHE.clear()
    sc = green()
    pts = study_points(sc, {"effects.asperity_gap.sigma": "0.5 nm,1 nm,2 nm"})
    reused = [worker_operator(p.scene)[1] for p in pts]
    assert reused == [False, True, True]
    pts = study_points(sc, {"solver.nodes": "40,60,60"})
    assert [worker_operator(p.scene)[1] for p in pts] == [False, False, True]
    OPERATOR_CACHE.clear()


def test_parts_are_frozen():
    sc = coated()
    for part in ("body", "laws", "discretisation", "sweep", "output"):
        p = getattr(sc, part)
        for f in dataclasses.fields(p):
            with pytest.raises(dataclasses.FrozenInstanceError):
                setattr(p, f.name, getattr(p, f.name))
    # the tables inside them too: the laws, the mesh
    for table in (sc.laws.effects, sc.discretisation.mesh):
        k = next(iter(table))
        for change in (lambda t: t.__setitem__(k, 1.0), lambda t: t.pop(k),
                       lambda t: t.update({k: 1.0}), lambda t: t.clear(),
                       lambda t: t.__delitem__(k), lambda t: t.setdefault("new", 1.0)):
            with pytest.raises(TypeError, match="frozen"):
                change(table)
    # fe_settings is made afresh: changing it changes nothing of the scene's
    key = study_operator_key(sc)
    sc.fe_settings.growth = 1.5
    assert sc.fe_settings.growth == 0.25 and study_operator_key(sc) == key


def test_flat_attributes_read_the_parts_and_old_writes_replace_a_part():
    sc = coated()
    assert [type(getattr(sc, p)) for p in ("body", "laws", "discretisation", "sweep",
                                           "output")] == [Body, Laws, Discretisation, Sweep,
                                                          Output]
    assert sc.operator_inputs == (sc.body, sc.discretisation)
    assert (sc.nodes, sc.method, sc.analysis_radius) == (
        sc.discretisation.nodes, sc.discretisation.method, sc.discretisation.analysis_radius)
    assert sc.sphere is sc.body.sphere and sc.e_star == sc.body.e_star
    assert sc.effects is sc.laws.effects and sc.vtk == sc.output.vtk
    assert isinstance(sc.d_values, list) and sc.d_values == list(sc.sweep.d_values)
    # code of earlier versions assigns d_values (validation/paper1.py): a new sweep part
    before = sc.sweep
    sc.d_values = [2e-9, 1e-9]
    assert sc.d_values == [2e-9, 1e-9] and sc.sweep is not before
    assert len(before.d_values) > 2
    with pytest.raises(AttributeError, match="replace"):
        sc.fe_settings = None


def test_a_scene_pickles_with_its_parts():
    """Study points travel to the workers pickled: the parts, their tables and the key
    survive."""
    sc = coated()
    back = pickle.loads(pickle.dumps(sc))
    assert back == sc and study_operator_key(back) == study_operator_key(sc)
    assert type(back.laws.effects) is type(sc.laws.effects)
    with pytest.raises(TypeError, match="frozen"):
        back.laws.effects["x"] = 1


def test_replace_changes_one_part_and_refuses_bare_numbers():
    """``scene.replace`` is what it was for users: dotted keys, a bare number for a length
    refused with the file's one-line error; the parts not concerned come out equal."""
    sc = green()
    new = sc.replace({"effects.asperity_gap.sigma": "0.7 nm"})
    assert new.gap.sigma == pytest.approx(0.7e-9, rel=1e-15, abs=0)
    assert new.body == sc.body and new.discretisation == sc.discretisation
    assert new.sweep == sc.sweep and new.laws != sc.laws
    with pytest.raises(femadh.SceneError, match="effects.asperity_gap.sigma"):
        sc.replace({"effects.asperity_gap.sigma": 0.7})
    si = sc.replace({"effects.asperity_gap.sigma": 0.7e-9}, si=True)
    assert si.gap.sigma == 0.7e-9
