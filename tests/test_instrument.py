"""The instrument in series with the contact: its limits (k -> infinity is the displacement
control, k -> 0 the load control), Derjaguin's jump-in of a nearly rigid sphere, JKR's
snap-off with a compliant drive, the beams' stiffness, its outputs and its bad input."""
import csv
import math

import numpy as np
import pytest

from femadh.errors import SceneError
from femadh.instrument import bridge_stiffness, cantilever_stiffness, read_instrument
from femadh.laws import LennardJones
from femadh.reference.maugis import jkr_snap_off_with_spring, maugis_length_units
from femadh.runner.run import run
from femadh.scene import load_scene, scene_from_dict

try:
    import tomllib
except ModuleNotFoundError:          # Python 3.10
    import tomli as tomllib


def scene_from_text(text):
    """A scene from TOML text, validated like a file (units required)."""
    return scene_from_dict(tomllib.loads(text), "test.toml", bare_numbers=False)

MU2 = "validation/scenes/lj_sphere_mu2_arclength.toml"
R, HAMAKER, Z0 = 1e-6, 1e-19, 0.165e-9
DG = HAMAKER / (16 * math.pi * Z0**2)
E_STAR = 12.19e9
UNIT = math.pi * DG * R                      # Maugis' force unit pi dg R


@pytest.fixture(scope="module")
def mu2():
    """The smooth LJ sphere at Tabor mu = 2 traced through its folds (0.2 s)."""
    res = run(load_scene(MU2), None, estimate=False, figures=False, progress=False)
    assert res.status == "converged"
    return res


def _tension(res, branch):
    c = res.branches[branch]
    return c["F_ex_N"] + c["F_tail_N"]


def test_a_stiff_spring_is_displacement_control(mu2):
    """k -> infinity: the instrument jumps at the contact's own folds, reads the tension
    there, and its loop encloses the energy the displacement-controlled jumps release (energy
    balance, computed independently from the energy functional): measured 0.56 % apart, the
    loop's trapezoid resolution estimate 0.65 %."""
    ip = read_instrument(mu2.branches, mu2.jumps, 1e9)
    hl = ip.headline()
    (j_in,) = [j for j in mu2.jumps if j["branch"] == "approach"]
    (j_out,) = [j for j in mu2.jumps if j["branch"] == "retract"]
    assert hl["jump_in_d_m"] == pytest.approx(j_in["d_fold_m"], rel=1e-12, abs=0)
    assert hl["jump_out_d_m"] == pytest.approx(j_out["d_fold_m"], rel=1e-12, abs=0)
    # z = d + F/k differs from d by F/k ~ 2e-16 m
    assert abs(hl["jump_out_z_m"] - j_out["d_fold_m"]) < 1e-15
    tail = float(np.interp(j_out["d_fold_m"], mu2.branches["retract"]["d_m"],
                           mu2.branches["retract"]["F_tail_N"]))
    assert hl["snap_off_N"] == pytest.approx(j_out["F_ex_before_N"] + tail, rel=1e-12, abs=0)
    # it lands where the displacement control lands (the same d, d_land = d_fold on a traced
    # curve), its force interpolated between the landing branch's states: measured 1.9x and
    # 0.48x the landing's resolution estimate (approach, retract)
    for mine, theirs in zip(ip.jumps, mu2.jumps):
        c = mu2.branches[theirs["branch"]]
        order = np.argsort(c["d_m"])
        F = theirs["F_ex_after_N"] + np.interp(theirs["d_land_m"], c["d_m"][order],
                                               c["F_tail_N"][order])
        assert abs(mine["d_land_m"] - theirs["d_land_m"]) < 1e-15
        assert abs(mine["F_after_N"] - F) <= 3 * mine["resolution_land_F_N"]
    released = sum(j["energy_released_J"] for j in mu2.jumps)
    assert abs(hl["hysteresis_J"] - released) < 2 * hl["hysteresis_J_resolution"]
    assert hl["hysteresis_J_resolution"] < 0.01 * released


def test_a_soft_spring_reads_the_load_controlled_pull_off(mu2):
    """k -> 0: the instrument snaps off at the largest tension of the curve (load control),
    and the largest tension it records is that one whatever k (k = 1e3 ... 1e9 N/m here;
    measured agreement 3e-5 relative, the readout's parabola vs the states)."""
    largest = float(np.max(_tension(mu2, "retract")))
    soft = read_instrument(mu2.branches, mu2.jumps, 1.0).headline()
    assert soft["snap_off_N"] == pytest.approx(largest, rel=5e-4, abs=0)
    assert soft["pull_off_N"] >= largest
    assert soft["pull_off_N"] == pytest.approx(largest, rel=5e-4, abs=0)
    snaps = []
    # 300 N/m: z turns on the retract's trace of the contact branch 1.5 pm below where the
    # approach's trace of that branch begins (its landing): that trace is no landing
    for k in (1e9, 1e5, 1e4, 3e3, 1e3, 300.0, 1.0):
        ip = read_instrument(mu2.branches, mu2.jumps, k)
        hl = ip.headline()
        # one jump each way, as the contact's S-shaped curve has one fold each way
        assert [j["branch"] for j in ip.jumps] == ["approach", "retract"], k
        # and lands off the contact branch it left (the free surface: a small tension; nan
        # where the landing lies beyond the sweep's start, k = 1 N/m)
        assert not ip.jumps[1]["F_after_N"] >= 0.5 * ip.jumps[1]["F_before_N"], k
        assert hl["pull_off_N"] == pytest.approx(soft["pull_off_N"], rel=5e-4, abs=0)
        snaps.append(hl["snap_off_N"])
    # the softer the spring, the later it lets go
    assert all(b >= a for a, b in zip(snaps, snaps[1:]))


def test_jkr_side_snap_off_follows_jkr_with_a_compliant_drive(mu2):
    """On the JKR side the snap-off moves from the fixed-grip value (k -> infinity, JKR 5/6)
    to the largest tension (k -> 0, JKR 3/2) as dF/dd meets -k. At mu = 2 the LJ sphere's
    limits sit ~0.08 pi dg R above JKR's (finite mu); the fraction of that range the snap-off
    has covered at k_tilde = k delta_unit / (pi dg R) follows JKR's: measured at most 0.017
    apart (k_tilde = 3), where the readout's resolution is 0.027 of the range; tolerance
    0.03."""
    du = maugis_length_units(R, E_STAR, DG)[1]
    stiff = read_instrument(mu2.branches, mu2.jumps, 1e4 * UNIT / du).headline()["snap_off_N"]
    load = float(np.max(_tension(mu2, "retract")))
    for kt in (0.3, 1.0, 3.0, 10.0):
        hl = read_instrument(mu2.branches, mu2.jumps, kt * UNIT / du).headline()
        ours = (hl["snap_off_N"] - stiff) / (load - stiff)
        jkr = (jkr_snap_off_with_spring(kt) - 5 / 6) / (1.5 - 5 / 6)
        assert ours == pytest.approx(jkr, abs=0.03), kt


def test_jkr_with_a_spring_limits():
    """The reference itself: 3/2 at k -> 0, 5/6 at k -> infinity, monotone between."""
    assert jkr_snap_off_with_spring(0.0) == pytest.approx(1.5, rel=1e-12, abs=0)
    assert jkr_snap_off_with_spring(1e9) == pytest.approx(5 / 6, rel=1e-6, abs=0)
    vals = [jkr_snap_off_with_spring(k) for k in (0.01, 0.1, 1, 10, 100)]
    assert all(b < a for a, b in zip(vals, vals[1:]))


DERJAGUIN = """
[scene]
name = "derjaguin-tip"
[sphere]
radius = "50 nm"
[materials]
composite_modulus = "{E}"
[effects.lennard_jones]
hamaker = "1e-19 J"
equilibrium_distance = "0.165 nm"
[solver]
nodes = 60
analysis_radius = {{ delta = "5 nm" }}
[sweep]
start = "2 nm"
stop = "0.3 nm"
step = "0.02 nm"
directions = ["approach"]
[instrument]
stiffness = "5 N/m"
"""


def test_a_nearly_rigid_tip_jumps_in_where_derjaguin_says():
    """A 50-nm tip on a 5 N/m cantilever: a rigid sphere (Derjaguin, F = -2 pi R U(d), exact
    for the paraboloid) jumps in where 2 pi R p(D) = k (paper 1 eq 3 for p). The elastic tip
    jumps a little farther out; the difference shrinks as E* grows (measured 3.6e-3 relative
    at 100 GPa, 8.3e-4 at 1000 GPa). The landing lies below the sweep: it is reported as
    beyond the traced separations, the jump itself is read."""
    from scipy import optimize

    lj = LennardJones(HAMAKER, Z0)
    D = optimize.brentq(lambda h: 2 * math.pi * 50e-9 * float(lj.pressure(h)) - 5.0,
                        0.3e-9, 2e-9, xtol=1e-16)
    dev = {}
    for E in ("100 GPa", "1000 GPa"):
        res = run(scene_from_text(DERJAGUIN.format(E=E)), None, estimate=False, figures=False,
                  progress=False)
        dev[E] = res.headline["instrument_jump_in_d_m"] / D - 1
        assert any("lands beyond the traced separations" in w for w in res.warnings)
    assert 0 < dev["1000 GPa"] < 2e-3
    assert dev["1000 GPa"] < dev["100 GPa"] / 3


def test_beam_stiffness_is_euler_bernoulli():
    """k = 3 E I / L^3 (end-loaded cantilever) and 192 E I / L^3 (fixed-fixed bridge, centre
    load), I = w t^3 / 12: e.g. a 450 x 50 x 2 um silicon cantilever is 0.185 N/m."""
    L, w, t, E = 450e-6, 50e-6, 2e-6, 169e9
    inertia = w * t**3 / 12
    assert cantilever_stiffness(L, w, t, E) == pytest.approx(3 * E * inertia / L**3, rel=1e-14, abs=0)
    assert bridge_stiffness(L, w, t, E) == pytest.approx(192 * E * inertia / L**3, rel=1e-14, abs=0)
    assert cantilever_stiffness(L, w, t, E) == pytest.approx(0.18546, rel=1e-4, abs=0)


def test_an_instrument_run_writes_its_curve_and_numbers(tmp_path, mu2):
    """curve.csv gains z_m = d + F/k and F_instrument_N = k (z - d) on the states the
    instrument holds (nan elsewhere); instrument.csv holds its paths; summary.json the
    numbers with their estimated errors; the figure exists."""
    import json

    text = open(MU2).read().replace("[output]", '[instrument]\ncantilever = { length = '
                                    '"20 um", width = "10 um", thickness = "2 um", '
                                    'youngs_modulus = "169 GPa" }\n\n[output]')
    sc = scene_from_text(text)
    k = sc.instrument.stiffness
    assert k == pytest.approx(169e9 * 10e-6 * 8e-18 / (4 * 8e-15), rel=1e-12, abs=0)   # 422.5 N/m
    res = run(sc, tmp_path, progress=False)
    assert res.status == "converged"
    with open(tmp_path / "curve.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    held = [r for r in rows if r["F_instrument_N"] != "nan"]
    assert 0 < len(held) < len(rows)
    for r in held:
        F = float(r["F_ex_N"]) + float(r["F_tail_N"])
        assert float(r["F_instrument_N"]) == pytest.approx(F, rel=1e-12, abs=0)
        assert k * (float(r["z_m"]) - float(r["d_m"])) == pytest.approx(F, rel=1e-9, abs=0)
    s = json.load(open(tmp_path / "summary.json"))["instrument"]
    for name in ("pull_off_N", "snap_off_N", "jump_in_z_m", "jump_out_z_m", "hysteresis_J"):
        assert s[name] > 0 and 0 < s[f"{name}_error"] < 0.1 * abs(s[name]), name
    assert s["jump_out_d_m"] < s["jump_out_z_m"]          # in tension: the tip lags the base
    assert (tmp_path / "instrument.csv").exists() and (tmp_path / "instrument.png").exists()


@pytest.mark.parametrize("table, expected", [
    ('stiffness = "-1 N/m"', "instrument.stiffness"),
    ('stiffness = "0.5 N"', "a stiffness such as"),
    ('cantilever = { length = "0 um", width = "30 um", thickness = "2 um", '
     'youngs_modulus = "169 GPa" }', "instrument.cantilever.length"),
    ('stiffness = "1 N/m"\nbridge = { length = "100 um", width = "30 um", thickness = "2 um", '
     'youngs_modulus = "169 GPa" }', "exactly one of stiffness, cantilever, bridge"),
])
def test_bad_instrument_is_one_clear_line(table, expected):
    text = open(MU2).read().replace("[output]", f"[instrument]\n{table}\n\n[output]")
    with pytest.raises(SceneError) as e:
        scene_from_text(text)
    assert expected in str(e.value) and "\n" not in str(e.value)


def test_an_instrument_on_a_meniscus_scene_is_refused():
    text = open("validation/scenes/paper2_ethanol_100nm.toml").read() + \
        '\n[instrument]\nstiffness = "0.1 N/m"\n'
    with pytest.raises(SceneError) as e:
        scene_from_text(text)
    assert "no [instrument] in a meniscus scene" in str(e.value)


def test_a_stepped_sigma_gap_run_is_read_and_sharpened():
    """Fig 3 (sigma-gap complementarity, stepped in d every 0.2 nm) on a 3e4 N/m suspension:
    the instrument holds the contact's largest tension (dF/dd = 0 > -k), so its pull-off is
    the displacement-controlled peak found by the run's bounded search plus the tail there
    (1e-4: the peak's own search tolerance). At each jump z turns where dF/dd = -k: the slope
    between the instrument's last two (fresh) states before it, measured within 0.02 %
    (approach) and 1.7 % (retract) of -k (a secant across the turn); tolerance 3 %."""
    from conftest import fig3_uniform_text

    k = 3e4
    text = fig3_uniform_text().replace("nodes = 200", "nodes = 100").replace(
        "[output]", f'[instrument]\nstiffness = "{k:g} N/m"\n\n[output]')
    res = run(scene_from_text(text), None, figures=False, progress=False, estimate="peak")
    assert res.status == "converged" and res.instrument["fresh_states"] > 0
    hl = res.headline
    c = res.branches["retract"]
    order = np.argsort(c["d_m"])
    tail = float(np.interp(hl["d_at_max_adhesion_m"], c["d_m"][order], c["F_tail_N"][order]))
    assert hl["instrument_pull_off_N"] == pytest.approx(hl["max_adhesion_N"] + tail, rel=1e-4, abs=0)
    # that is one reading of the maximum; the path's own states give another, and their
    # difference is the pull-off's resolution: never zero, and no state the instrument holds
    # pulls harder than the pull-off plus it
    resolution = res.instrument["resolution"]["pull_off_N"]
    assert resolution > 0
    ret = res.instrument["paths"]["retract"]
    assert np.max(ret["F_N"]) <= hl["instrument_pull_off_N"] + resolution
    for b in ("approach", "retract"):
        p = res.instrument["paths"][b]
        held = np.array([x for x, kind in zip(p["d_m"], p["kind"]) if kind == "point"])
        # fresh states never repeat a computed one (two states at one d read as a turn)
        assert np.all(np.diff(held) != 0), b
    for b in ("approach", "retract"):
        p = res.instrument["paths"][b]
        i = p["kind"].index("fold")
        slope = (p["F_N"][i] - p["F_N"][i - 1]) / (p["d_m"][i] - p["d_m"][i - 1])
        assert slope == pytest.approx(-k, rel=0.03, abs=0), b


def test_mems_verdict_across_the_rest_gap(tmp_path, mu2):
    """The verdict follows the instrument's jump-out: a part stuck to the flat frees itself
    iff its suspension's base, back at the rest gap, lies beyond the jump-out z. A study over
    the rest gap on both sides of it (k = 3000 N/m: jump-out z = 0.80 nm) records stuck and
    free, and its figure marks them."""
    from femadh.instrument import Spring
    from femadh.runner.instrument import instrument_numbers
    from femadh.studies.sweep import run_study

    z_out = instrument_numbers(mu2, Spring(3000.0))["instrument_jump_out_z_m"]
    for gap, stuck in ((0.9 * z_out, 1.0), (1.1 * z_out, 0.0)):
        hl = instrument_numbers(mu2, Spring(3000.0, rest_gap=gap))
        assert hl["instrument_stuck"] == stuck
        # the margin (jump-out z beyond the rest gap) carries the verdict's sign
        assert (hl["instrument_release_margin_m"] > 0) == bool(stuck)
    text = open(MU2).read().replace("[output]", '[instrument]\nstiffness = "3000 N/m"\n'
                                    'rest_gap = "1 nm"\n\n[output]')
    sc = scene_from_text(text)
    vary = {"instrument.rest_gap": "0.6 nm,1.2 nm"}
    _, rec = run_study(sc, vary, tmp_path / "s", workers=1, estimate=False)
    verdicts = sorted((r["instrument_stuck"], r["instrument_release_margin_m"] > 0)
                      for r in rec.values())
    assert verdicts == [(0.0, False), (1.0, True)]
    assert (tmp_path / "s" / "study.png").exists()


#: a 100-nm SiO2 tip in ethanol vapour at p/psat 0.5 (GAB film) on a 0.1 N/m lever, traced 30 nm
#: -> 0 nm: the meniscus forms within one 0.5-nm step near d = 3 nm (issue 22's first try)
MENISCUS_ONSET = """
[scene]
name = "meniscus-onset"
[sphere]
radius = "100 nm"
[materials]
disk   = { youngs_modulus = "73 GPa",  poisson_ratio = 0.17 }
slider = { youngs_modulus = "73 GPa", poisson_ratio = 0.17 }
[effects.lennard_jones]
hamaker = "6.5e-20 J"
equilibrium_distance = "0.165 nm"
[effects.capillary]
liquid = "ethanol"
relative_pressure = 0.5
[solver]
analysis_radius = { delta = "20 nm" }
continuation = "arclength"
nodes = 60
[sweep]
start = "30 nm"
stop = "0 nm"
step = "0.5 nm"
[instrument]
stiffness = "0.1 N/m"
"""


def test_a_step_like_force_is_not_read_past_its_states():
    """The meniscus switches on within one step: F (nN) 0.087, 0.13, 5.1 at d = 3.5, 3, 2.5 nm,
    monotone, while z = d + F/k turns between them. The parabola through the three states put
    z's turning point at z = -1.82 nm with F = -0.51 nN (repulsive, between attractive states,
    z below every state's): the readout must not read an extremum that the monotone states do
    not have. It reads the state itself, resolved to the bracket."""
    d = np.array([5.0, 4.5, 4.0, 3.5, 3.0, 2.5, 2.0, 1.5]) * 1e-9
    F = np.array([0.0433, 0.0535, 0.06583, 0.08648, 0.1315, 5.105, 10.2, 15.3]) * 1e-9
    ip = read_instrument({"approach": {"d_m": d, "F_ex_N": F}}, [], 0.1, ("approach",))
    (j,) = ip.jumps
    assert j["F_before_N"] == pytest.approx(0.1315e-9, rel=1e-6, abs=0)
    assert j["z_m"] == pytest.approx(3e-9 + 1.315e-9, rel=1e-6, abs=0)
    assert j["resolution_d_m"] == pytest.approx(0.5e-9, rel=1e-6, abs=0)


def test_the_warnings_name_the_sharpened_jump():
    """The instrument's warning (a jump landing beyond the sweep) is read from the same states
    as the headline: the sharpened reading, not the first one between the sweep's states (which
    named a jump at z = -1.8 nm, F = -0.5 nN, while the headline said z = 4.25 nm). Both jumps
    land beyond the traced range (the lever needs z ~ 4 nm in, ~745 nm out): both are named."""
    res = run(scene_from_text(MENISCUS_ONSET), None, estimate="peak", figures=False,
              progress=False)
    assert res.status == "converged" and res.instrument["fresh_states"] > 0
    hl = res.headline
    inst = [w for w in res.warnings if w.startswith("instrument:")]
    assert len(inst) == 1
    assert f"approach jump at z = {hl['instrument_jump_in_z_m'] * 1e9:.6g} nm" in inst[0]
    assert f"retract jump at z = {hl['instrument_jump_out_z_m'] * 1e9:.6g} nm" in inst[0]
    assert 4e-9 < hl["instrument_jump_in_z_m"] < 4.5e-9


def test_mems_verdict_of_a_continuous_peel_off():
    """A suspension stiffer than the contact everywhere never jumps: the part peels off as the
    base rises, and the verdict is where it hangs with its base at the rest gap g - near
    contact (the adhesion balancing k (g - d): stuck) or near g (free); not traced up to g:
    no verdict."""
    from femadh.runner.instrument import mems_verdict

    g, k = 1e-6, 100.0
    z = np.array([-0.2, 0.5, 1.0, 1.5]) * g

    def path(d):
        d = np.array(d) * g
        return {"z_m": z, "d_m": d, "F_N": k * (z - d), "kind": ["point"] * 4}
    assert mems_verdict(path([-0.2, 0.002, 0.004, 1.2]), g, k) is True
    assert mems_verdict(path([-0.2, 0.45, 0.97, 1.49]), g, k) is False
    # not traced up to z = g: still pulling at least k g / 2 at its end (unknown), or less
    # (the laws only decay beyond: too weak to hold it within g / 2 of contact: free)
    assert mems_verdict(path([-0.2, 0.002, 0.004, 0.005]), 2 * g, k) is None
    assert mems_verdict(path([-0.2, 0.002, 0.004, 1.2]), 2 * g, k) is False
    # a jump-out decides exactly: beyond g stuck, short of it free
    jump = {"z_m": np.array([0.0, 0.8, 0.8]) * g, "d_m": np.array([0.0, 0.001, 0.8]) * g,
            "F_N": np.array([0.0, 0.799, 0.0]) * g * k, "kind": ["point", "fold", "land"]}
    assert mems_verdict(jump, g, k) is False and mems_verdict(jump, 0.7 * g, k) is True


def test_a_spring_softer_than_the_contact_at_the_start_reads_no_jump_in():
    """Fig 3 on a 3000 N/m spring: at the sweep's start (2 nm) the contact already pulls with
    a stiffness beyond k, so the instrument's jump-in lies farther out than the sweep: it is
    not read (a bound is no number) and a warning names the key to extend."""
    from conftest import fig3_uniform_text

    text = fig3_uniform_text().replace("nodes = 200", "nodes = 60").replace(
        "[output]", '[instrument]\nstiffness = "3000 N/m"\n\n[output]')
    res = run(scene_from_text(text), None, figures=False, progress=False, estimate=False)
    assert "instrument_jump_in_d_m" not in res.headline
    assert "instrument_jump_out_z_m" in res.headline
    assert any("already softer than the contact" in w and "[sweep] start" in w
               for w in res.warnings)


def test_mems_verdict_after_a_jump_onto_a_longer_range_hold():
    """A jump-out that lands on a state still held near contact (a meniscus holding after the
    LJ contact let go) is no release: at z = g the part hangs at 0.02 g - stuck."""
    from femadh.runner.instrument import mems_verdict

    g, k = 1e-6, 100.0
    path = {"z_m": np.array([0.0, 0.3, 0.3, 0.6, 1.2]) * g,
            "d_m": np.array([0.0, 0.001, 0.01, 0.015, 0.025]) * g,
            "kind": ["point", "fold", "land", "point", "point"]}
    path["F_N"] = k * (path["z_m"] - path["d_m"])
    assert mems_verdict(path, g, k) is True


def test_jump_in_read_on_a_coarse_sweep_agrees_with_a_fine_one_within_its_resolution():
    """The mu = 2 sphere stepped in d every 0.2 nm and every 0.02 nm (80 nodes, 3000 N/m): the
    coarse sweep's jump-in d and z, read through fresh states at z's turn, agree with the fine
    sweep's within 3x the sum of their readout resolutions (measured 0.03x and 0.0001x; a fresh
    state repeating a computed one used to stop the walk early: 6.5x)."""
    text = open(MU2).read().replace('continuation = "arclength"', "").replace(
        "nodes = 150", "nodes = 80").replace(
        "[output]", '[instrument]\nstiffness = "3000 N/m"\n\n[output]')
    read = {}
    for step in ("0.2 nm", "0.02 nm"):
        sc = scene_from_text(text.replace('step = "0.1 nm"', f'step = "{step}"'))
        res = run(sc, None, figures=False, progress=False, estimate="peak")
        read[step] = res.headline, res.instrument["resolution"]
    (hc, rc), (hf, rf) = read["0.2 nm"], read["0.02 nm"]
    for name in ("jump_in_d_m", "jump_in_z_m"):
        diff = abs(hc[f"instrument_{name}"] - hf[f"instrument_{name}"])
        assert diff <= 3 * (rc[name] + rf[name]), name
