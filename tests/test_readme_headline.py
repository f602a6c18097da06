"""The README's printed headline of the Fig 3 scene ("Two commands for a fresh machine") is
what the scene gives: each number within the error printed beside it (the estimate's stated
accuracy) plus half a unit of its last printed digit, the grid femadh chose to its digits."""
import re
from pathlib import Path

import pytest

import femadh

ROOT = Path(__file__).resolve().parents[1]
NUM = r"(-?[\d.]+(?:e-?\d+)?)"


def printed():
    """The numbers of the README's printed block (strings, to keep their digits)."""
    text = (ROOT / "README.md").read_text()
    block = text[text.index("prints its headline numbers"):]
    block = block[:block.index("results in out/paper1-fig3")]
    pats = {
        "adhesion": rf"max adhesion {NUM} ± {NUM} µN at d = {NUM} ± {NUM} nm \(DMT 2πRW = "
                    rf"{NUM} µN, "
                    rf"JKR 1.5πRW = {NUM} µN\)",
        "deepest": rf"F_ex\(d = -5 nm\) = {NUM} ± {NUM} mN, F_LJ = {NUM} ± {NUM} µN",
        "grid": rf"accuracy {NUM} met: (\d+) nodes, band spacing {NUM} nm to {NUM} µm, "
                rf"analysis radius {NUM} µm",
    }
    out = {}
    for name, pat in pats.items():
        m = re.search(pat, block)
        assert m, f"README's printed {name} line not found"
        out[name] = m.groups()
    return out


def half_digit(s):
    """Half a unit of the last printed digit of a number string."""
    mant = s.split("e")[0]
    dec = len(mant.split(".")[1]) if "." in mant else 0
    exp = int(s.split("e")[1]) if "e" in s else 0
    return 0.5 * 10.0 ** (exp - dec)


def close(value, s, err="0"):
    """|value - printed| within the printed error plus half its last digit."""
    return abs(value - float(s)) <= float(err) + half_digit(s) + half_digit(err) * (err != "0")


@pytest.fixture(scope="module")
def fig3():
    res = femadh.run(femadh.load_scene("validation/scenes/paper1_fig3.toml"), progress=False)
    assert res.status == "converged", res.error
    return res


def test_readme_headline_of_the_fig3_scene(fig3):
    p, hl, acc = printed(), fig3.headline, fig3.accuracy
    F, Fe, d, de, dmt, jkr = p["adhesion"]
    assert close(hl["max_adhesion_N"] * 1e6, F, Fe)
    assert close(hl["d_at_max_adhesion_m"] * 1e9, d, de)
    assert close(hl["dmt_pull_off_N"] * 1e6, dmt) and close(hl["jkr_pull_off_N"] * 1e6, jkr)
    fex, fex_e, flj, flj_e = p["deepest"]
    assert close(hl["F_ex_deepest_N"] * 1e3, fex, fex_e)
    assert close(hl["F_LJ_deepest_N"] * 1e6, flj, flj_e)
    target, nodes, spacing, _, radius = p["grid"]
    assert acc["met"] and acc["target"] == float(target)
    assert acc["nodes"] == int(nodes)
    assert close(acc["spacing_m"] * 1e9, spacing) and close(acc["analysis_radius_m"] * 1e6,
                                                            radius)
    # the printed errors are the estimate's, to its one printed digit
    assert close(hl["max_adhesion_N_error"] * 1e6, Fe)
    assert close(hl["d_at_max_adhesion_m_error"] * 1e9, de)
    assert close(hl["F_ex_deepest_N_error"] * 1e3, fex_e)
    assert close(hl["F_LJ_deepest_N_error"] * 1e6, flj_e)


def test_the_golden_check_bites():
    """A number off by more than its printed error fails the comparison."""
    assert close(31.152, "31.152", "0.03") and close(31.18, "31.152", "0.03")
    assert not close(31.19, "31.152", "0.03") and not close(1.1346, "1.134")
