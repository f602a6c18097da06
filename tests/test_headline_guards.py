"""Guards on what a run's headline claims, found by a newcomer's trial on a fresh clone: a
sphere radius beyond what femadh models is refused in one line (a unit typo, '2 m' for
'2 mm'); a largest adhesion at an end of the sweep is reported as a lower bound, not as a
peak located between computed separations; a request refused before its first grid reports
its reason without a crash."""
import pytest

import femadh
from conftest import fig3_uniform_text
from femadh.errors import SceneError
from femadh.runner.report import headline_lines
from femadh.runner.result import ContactResult


@pytest.mark.parametrize("radius", ["2 m", "2 km", "2 parsec"])
def test_a_sphere_larger_than_ten_centimetres_is_refused_in_one_line(tmp_path, radius):
    p = tmp_path / "s.toml"
    p.write_text(fig3_uniform_text().replace('radius = "2 mm"', f'radius = "{radius}"'))
    with pytest.raises(SceneError) as e:
        femadh.load_scene(p)
    msg = str(e.value)
    assert "[sphere.radius]" in msg and radius in msg and "0.1" in msg
    assert len(msg.splitlines()) == 1


def test_a_peak_beyond_the_sweep_is_a_warned_lower_bound(tmp_path):
    """Fig 3's largest adhesion is at d = 1.134 nm (README); a sweep starting at 1.0 nm
    only sees the force still growing towards its start: the largest computed adhesion is the
    branch's end state, and the run says it is a lower bound. The full sweep says nothing."""
    text = fig3_uniform_text().replace("nodes = 200", "nodes = 60")
    p = tmp_path / "s.toml"
    p.write_text(text.replace('start = "2 nm"', 'start = "1.0 nm"')
                 .replace('step = "0.2 nm"', 'step = "0.5 nm"'))
    res = femadh.run(p, progress=False, estimate=False)
    warned = [w for w in res.warnings if "largest adhesion is at an end" in w]
    assert len(warned) == 1 and "d = 1 nm" in warned[0], res.warnings
    q = tmp_path / "full.toml"
    q.write_text(text.replace('step = "0.2 nm"', 'step = "0.5 nm"'))
    full = femadh.run(q, progress=False, estimate=False)
    assert not [w for w in full.warnings if "largest adhesion is at an end" in w]


def test_a_request_refused_before_its_first_grid_reports_without_a_crash():
    res = ContactResult("s", None, status="failed", error="accuracy 0.001 not met: the grid "
                        "would need more than 4000 nodes",
                        accuracy={"target": 1e-3, "met": False, "nodes": None,
                                  "analysis_radius_m": None, "steps": []})
    lines = headline_lines(res)
    # no grid ran: no accuracy line with nodes or radius of None (the error line says why)
    assert not any("None" in line or "analysis radius" in line for line in lines), lines
