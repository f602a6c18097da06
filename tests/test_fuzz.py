"""Fuzzing the scene contract: one key of a bundled scene replaced by an arbitrary value. Every
mutant must end in a validated scene or femadh's own errors (SceneError / DependencyError),
never another exception; the ones that validate and are small enough are run, and must end in
a result or a FemadhError. Deterministic (derandomized) so CI sees the same examples."""
import copy
from pathlib import Path
import tomllib

from hypothesis import HealthCheck, given, settings, strategies as st
import pytest

from femadh.errors import DependencyError, FemadhError, SceneError
from femadh.runner.run import run
from femadh.scene import scene_from_dict
from femadh.scene.resources import check_resources

SCENES = sorted((Path(__file__).resolve().parents[1] / "validation" / "scenes").glob("*.toml"))
DATA = {p.stem: tomllib.loads(p.read_text()) for p in SCENES}


def leaves(d, prefix=()):
    for k, v in d.items():
        if isinstance(v, dict):
            yield from leaves(v, prefix + (k,))
        yield prefix + (k,)


PATHS = [(name, path) for name, data in DATA.items() for path in leaves(data)]

values = st.one_of(
    st.integers(min_value=-10**12, max_value=10**12),
    st.floats(allow_nan=True, allow_infinity=True),
    st.booleans(),
    st.text(max_size=12),
    st.sampled_from(["1 nm", "-3 mm", "0 nm", "2 GPa", "1e300 m", "nan m", "25 degC", "abc kg",
                     "1e-30 nm", "0.5", "", "contact", "ethanol", "green", "fe", "arclength",
                     "hertz-closure", "smoothed"]),
    st.lists(st.one_of(st.floats(allow_nan=False, width=32), st.text(max_size=4)), max_size=4),
    st.dictionaries(st.text(max_size=5), st.integers(), max_size=2),
)


def small_enough(sc):
    """Run only mutants that stay cheap: Green contact scenes of <= 400 nodes and <= 60
    separations, meniscus scenes of <= 12 solves."""
    if sc.kind == "meniscus":
        return (len(sc.liquids) * len(sc.radii) * len(sc.methods) * len(sc.p_ratios) <= 12
                and sc.elements <= 64)
    return (sc.method == "green" and sc.nodes <= 400 and len(sc.d_values) <= 60
            and sc.continuation == "steps")


@settings(max_examples=60, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow])
@given(st.sampled_from(PATHS), values)
def test_mutated_scene_ends_in_a_scene_or_a_clear_error(target, value):
    name, path = target
    data = copy.deepcopy(DATA[name])
    node = data
    for k in path[:-1]:
        node = node[k]
    node[path[-1]] = value
    try:
        sc = scene_from_dict(data, f"{name}.toml", bare_numbers=False)
        check_resources(sc)
    except (SceneError, DependencyError) as exc:
        assert str(exc) and "Traceback" not in str(exc)
        return
    if not small_enough(sc):
        return
    try:
        res = run(sc, progress=False)
    except FemadhError:
        return
    assert res.status in ("converged", "failed")


@pytest.mark.parametrize("name", sorted(DATA))
def test_bundled_scenes_validate(name):
    sc = scene_from_dict(DATA[name], f"{name}.toml", bare_numbers=False)
    check_resources(sc)
