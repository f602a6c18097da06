"""The MEMS verdict: which designs stick. Paper 1's 2-mm slider with LJ forces, the sigma-gap and
an ethanol meniscus (validation/scenes/paper1_slider_meniscus.toml), hung on a fixed-fixed
silicon bridge (200 x 20 x 4 um, k = 16 E w t^3 / L^3 = 410 N/m) that holds it 1 um above the
disk at rest, swept over sigma x p/psat as a study:

    femadh study sweep SCENE_WITH_INSTRUMENT \\
        --vary effects.asperity_gap.sigma="0.5 nm,1 nm,1.5 nm,2 nm" \\
        --vary effects.capillary.relative_pressure="0.1,0.3,0.5,0.7,0.9"

Once stuck (pressed into contact), the part frees itself iff the suspension lets go before its
base is back at the rest gap: the instrument's jump-out z below the rest gap, or, where it
peels off without a jump, the part hanging near the rest gap rather than near contact when
the base is there (femadh.runner.instrument.mems_verdict). ``python -m validation.mems_verdict`` writes
validation/results/mems_verdict.md and mems_verdict.png (the largest adhesion with stuck / free
marked; about a minute on two cores).
"""
import copy
import os
from pathlib import Path
import shutil
import tempfile
import time

import femadh
from femadh.scene import scene_from_dict
from femadh.studies.sweep import run_study

HERE = Path(__file__).resolve().parent
RESULTS = HERE / "results"
SCENE = HERE / "scenes" / "paper1_slider_meniscus.toml"
BRIDGE = {"length": "200 um", "width": "20 um", "thickness": "4 um",
          "youngs_modulus": "160 GPa"}
REST_GAP = "1 um"
VARY = {"effects.asperity_gap.sigma": "0.5 nm,1 nm,1.5 nm,2 nm",
        "effects.capillary.relative_pressure": "0.1,0.3,0.5,0.7,0.9"}


def main():
    base = femadh.load_scene(SCENE)
    raw = copy.deepcopy(base.raw)
    raw["instrument"] = {"bridge": BRIDGE, "rest_gap": REST_GAP}
    scene = scene_from_dict(raw, base.path)
    k, g = scene.instrument.stiffness, scene.instrument.rest_gap
    load = os.getloadavg()[0]
    out = Path(tempfile.mkdtemp(prefix="mems-verdict-"))
    t0 = time.perf_counter()
    points, rec = run_study(scene, VARY, out / "study", workers=2)
    wall = time.perf_counter() - t0
    lines = ["# The MEMS verdict: which designs stick", "",
             f"`python -m validation.mems_verdict`: {len(points)} points in {wall:.0f} s on 2 "
             f"processes (load average {load:.1f} at the start). Paper 1's slider on a "
             f"fixed-fixed bridge, k = {k:.4g} N/m, held {g * 1e6:.3g} um above the disk at rest: "
             f"its restoring force at the disk is k g = {k * g * 1e6:.4g} uN. Stuck iff, with "
             "the base back at the rest gap, the instrument still holds the slider near "
             "contact: its jump-out z beyond the rest gap (margin: jump-out z minus the rest "
             "gap), or, where it peels off without a jump ('-' margin), the slider hanging "
             "closer than half the rest gap.", "",
             "| sigma | p/psat | status | largest adhesion (uN) | instrument pull-off (uN) | "
             "verdict | margin (um) |", "|---|---|---|---|---|---|---|"]
    for p in points:
        r = rec.get(p.id, {})
        ch = p.changes
        verdict = {1.0: "stuck", 0.0: "free"}.get(r.get("instrument_stuck"), "-")

        def f(key, scale):
            v = r.get(key)
            e = r.get(f"{key}_error")
            if v is None:
                return "-"
            return f"{v * scale:.4g}" + (f" ± {e * scale:.1g}" if e is not None else "")
        lines.append(f"| {ch['effects.asperity_gap.sigma']} | "
                     f"{ch['effects.capillary.relative_pressure']} | {r.get('status', '-')} | "
                     f"{f('max_adhesion_N', 1e6)} | {f('instrument_pull_off_N', 1e6)} | "
                     f"{verdict} | {f('instrument_release_margin_m', 1e6)} |")
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "mems_verdict.md").write_text("\n".join(lines) + "\n")
    if (out / "study" / "study.png").exists():
        shutil.copy(out / "study" / "study.png", RESULTS / "mems_verdict.png")
    shutil.rmtree(out, ignore_errors=True)
    print("\n".join(lines))


if __name__ == "__main__":
    import argparse

    # no arguments: --help says what it writes instead of running it
    argparse.ArgumentParser(prog="python -m validation.mems_verdict",
                            description=__doc__.split("\n\n")[0]).parse_args()
    main()
