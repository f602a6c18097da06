"""Fresh states the instrument's readout adds near a fold stay on the branch they refine: at a
traced fold the branch's last state and its landing share a separation, and a fresh state
solved from the wrong pair (a fold and its landing) lands on the other piece, reads as a turn
of z that is not there and made a pull-off larger than any tension on the curve."""
import math

import numpy as np
import pytest

from femadh.instrument import read_instrument
from femadh.runner.run import run
from femadh.scene import scene_from_dict

try:
    import tomllib
except ModuleNotFoundError:          # Python 3.10
    import tomli as tomllib

MU2 = "validation/scenes/lj_sphere_mu2_arclength.toml"
K = 3e4                               # N/m: the instrument jumps out next to the contact's fold


@pytest.fixture(scope="module")
def stiff():
    text = open(MU2).read().replace("[output]", f'[instrument]\nstiffness = "{K:g} N/m"\n\n'
                                    "[output]")
    res = run(scene_from_dict(tomllib.loads(text), "t.toml", bare_numbers=False), None,
              figures=False, progress=False, estimate="peak")
    assert res.status == "converged"
    return res


def test_no_recorded_tension_beyond_the_curves_largest(stiff):
    """The smooth LJ sphere at mu = 2 (its largest tension 1.5835 pi dg R at d = 0.445 nm) on
    a 3e4 N/m spring: the pull-off is that maximum plus the tail there (held: dF/dd = 0 > -k),
    exactly; the snap-off is the raw readout's at the fold (0.9301 pi dg R, measured equal to
    the last digit: no fresh state stays on the contact branch within 1.3 pm of its fold, so
    none is added) and lies within its resolution of it. Before the pairing the readout took
    the fold's landing as a bracket end and recorded 468 nN (2.04 pi dg R). The located peak
    lies 1.0e-4 above the curve's largest computed state (tolerance 3e-4)."""
    hl, ins = stiff.headline, stiff.instrument
    tail = ins["pull_off_tail"]
    assert tail["at_max_adhesion"]
    assert hl["instrument_pull_off_N"] == pytest.approx(hl["max_adhesion_N"] + tail["F_tail_N"],
                                                        rel=1e-12, abs=0)
    # nothing the instrument holds pulls harder than the pull-off (plus its resolution)
    ret = ins["paths"]["retract"]
    assert np.max(ret["F_N"]) <= hl["instrument_pull_off_N"] + ins["resolution"]["pull_off_N"]
    curve = max(float(np.max(c["F_ex_N"] + c["F_tail_N"])) for c in stiff.branches.values())
    assert hl["instrument_pull_off_N"] <= curve * (1 + 3e-4)    # measured 1.0e-4 above
    raw = read_instrument(stiff.branches, stiff.jumps, K).headline()
    assert abs(hl["instrument_snap_off_N"] - raw["snap_off_N"]) <= raw["snap_off_N_resolution"]
    unit = math.pi * 1e-19 / (16 * math.pi * 0.165e-9**2) * 1e-6        # pi dg R
    assert hl["instrument_snap_off_N"] / unit == pytest.approx(0.9301, abs=1e-4)
