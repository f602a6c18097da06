"""The instrument in series with the contact: what it costs beside the plain run, and what it
reads across the spring's stiffness against its limits.

``python -m validation.instrument`` writes validation/results/instrument.md (a minute on two
cores, one BLAS thread; state the machine's load, printed with the table):

1. cost: each scene run end to end as a user runs it (``femadh.run`` with its error
   estimates, no figures), without and with an ``[instrument]``, alternated, median of
   ``--repeat`` runs; the goal is a ratio <= 1.2;
2. the smooth LJ sphere at Tabor mu = 2 read through springs from 1e9 to 1 N/m: snap-off,
   largest recorded tension, jump positions, loop hysteresis, beside the displacement-
   controlled fold (k -> infinity), the largest tension (k -> 0) and JKR with a compliant
   drive (normalised to each model's own range, see tests/test_instrument.py);
3. the bundled AFM scene's numbers.
"""
import argparse
import copy
import math
import os
from pathlib import Path
import statistics
import time

import numpy as np

import femadh
from femadh.instrument import Spring, read_instrument
from femadh.reference.maugis import jkr_snap_off_with_spring, maugis_length_units
from femadh.runner.instrument import instrument_numbers
from femadh.scene import scene_from_dict

HERE = Path(__file__).resolve().parent
SCENES = HERE / "scenes"
RESULTS = HERE / "results"

#: scene file -> spring stiffness used in the cost comparison (N/m)
COST = {"paper1_fig3.toml": 3e4, "paper1_fig4.toml": 3e4,
        "lj_sphere_mu2_arclength.toml": 3e3, "afm_tip_cantilever.toml": None}


def _timed(scene):
    t0 = time.perf_counter()
    res = femadh.run(scene, None, figures=False, progress=False)
    return time.perf_counter() - t0, res


def cost(repeat):
    rows = []
    for name, k in COST.items():
        scene = femadh.load_scene(SCENES / name)
        raw = copy.deepcopy(scene.raw)
        if k is not None:
            raw["instrument"] = {"stiffness": f"{k} N/m"}
        with_ = scene_from_dict(raw, scene.path)
        raw.pop("instrument")
        plain = scene_from_dict(raw, scene.path)
        t_plain, t_with = [], []
        for _ in range(repeat):
            t, _ = _timed(plain)
            t_plain.append(t)
            t, res = _timed(with_)
            t_with.append(t)
        hl = res.headline
        rows.append((name, with_.instrument.stiffness, statistics.median(t_plain),
                     statistics.median(t_with), hl.get("instrument_pull_off_N"),
                     hl.get("instrument_pull_off_N_error"),
                     res.instrument.get("fresh_states", 0), res.status))
    return rows


def stiffness_sweep():
    scene = femadh.load_scene(SCENES / "lj_sphere_mu2_arclength.toml")
    res = femadh.run(scene, None, figures=False, progress=False, estimate=False)
    R, E = scene.sphere.radius, scene.e_star
    dg = scene.effects["lj"].work_of_adhesion
    unit, du = math.pi * dg * R, maugis_length_units(R, E, dg)[1]
    c = res.branches["retract"]
    largest = float(np.max(c["F_ex_N"] + c["F_tail_N"]))
    stiff = read_instrument(res.branches, res.jumps, 1e9).headline()["snap_off_N"]
    rows = []
    for k in (1e9, 1e5, 3e4, 1e4, 3e3, 1e3, 3e2, 1e2, 10.0, 1.0):
        res.warnings = []
        hl = instrument_numbers(res, Spring(k))
        kt = k * du / unit
        snap = hl.get("instrument_snap_off_N")
        ours = None if snap is None else (snap - stiff) / (largest - stiff)
        jkr = (jkr_snap_off_with_spring(kt) - 5 / 6) / (1.5 - 5 / 6)
        rows.append((k, kt, None if snap is None else snap / unit,
                     hl["instrument_pull_off_N"] / unit, hl.get("instrument_jump_in_d_m"),
                     hl.get("instrument_jump_out_z_m"), hl.get("instrument_hysteresis_J"),
                     ours, jkr, "; ".join(res.warnings)))
    released = sum(j["energy_released_J"] for j in res.jumps)
    return rows, stiff / unit, largest / unit, released


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args(argv)
    load = os.getloadavg()[0]
    lines = ["# The instrument in series with the contact", "",
             f"`python -m validation.instrument --repeat {args.repeat}`; 2 cores, one BLAS "
             f"thread, load average {load:.1f} at the start.", "",
             "## What it costs", "",
             "Each scene end to end as a user runs it (error estimates on, no figures), "
             "without and with the spring, alternated; median of the repeats. The instrument "
             "reads the same states and adds fresh ones where it interpolates (its own and the "
             "estimate's coarser members').", "",
             "| scene | k (N/m) | plain run (s) | with instrument (s) | ratio | pull-off | "
             "fresh states | status |", "|---|---|---|---|---|---|---|---|"]
    for name, k, tp, tw, po, pe, fresh, status in cost(args.repeat):
        pull = "-" if po is None else f"{po:.6g} ± {pe:.1g} N"
        lines.append(f"| {name} | {k:.4g} | {tp:.2f} | {tw:.2f} | {tw / tp:.2f} | {pull} | "
                     f"{fresh} | {status} |")
    rows, stiff, largest, released = stiffness_sweep()
    lines += ["", "## Through the stiffness: the smooth LJ sphere at Tabor mu = 2", "",
              f"Forces in pi dg R. Displacement-controlled pull-off (the fold) {stiff:.4f}, the "
              f"largest tension {largest:.4f} (JKR: 5/6 and 3/2); the jumps' released energy "
              f"{released:.4g} J. 'fraction': how far the snap-off has moved from the fold "
              "toward the largest tension, femadh against JKR with a compliant drive at the "
              "same k_tilde = k delta_unit / (pi dg R).", "",
              "| k (N/m) | k_tilde | snap-off | largest recorded | jump-in d (nm) | "
              "jump-out z (nm) | hysteresis (J) | fraction | JKR fraction | note |",
              "|---|---|---|---|---|---|---|---|---|---|"]
    for k, kt, so, po, jin, jout, hy, ours, jkr, note in rows:
        f = (lambda x, s=1e9, fmt=".4f": "-" if x is None else f"{x * s:{fmt}}")
        lines.append(f"| {k:.3g} | {kt:.3g} | {f(so, 1)} | {po:.4f} | {f(jin)} | {f(jout)} | "
                     f"{f(hy, 1, '.4g')} | {f(ours, 1, '.3f')} | {jkr:.3f} | {note} |")
    lines += ["", "A soft spring's loop reaches beyond the traced separations (the jump-out "
              "lands ~F/k above the sweep's start): its hysteresis is not reported (a warning "
              "says past which separation to extend the sweep)."]
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "instrument.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
