"""Where a request finer than 1e-3 starts: the plan's spacing scaled, or the capped 1e-3
member's (issue 21, goal 2: Fig 4 at 1e-4).

The adaptive loop's first member for a request ``target`` is the 1e-3 member scaled by
(target / 1e-3)^(1/ORDER) (femadh/runner/adaptive.py, ``first_trial``). On scenes whose 1e-3
member is capped below the trapping-safe spacing (a cohesive zone narrower than the plan's
BAND_NODES resolve: the Fig 4 scene, sigma = 0.5 nm, and the stiction map's sigma = 0.489 nm
column) the rule used to scale the plan's uncapped spacing instead. This script runs each
request both ways in one process (the old rule patched in), one BLAS thread, no figures, and
writes validation/results/first_member.md: every trial's nodes and estimate, the CPU and wall
seconds of the whole adaptive run, the largest adhesion and its estimated error.

    python -m validation.first_member [--quick]      # --quick: without Fig 4 at 1e-4

CPU seconds are the comparison where the machine is shared (the load is recorded).
"""
import argparse
import os
from pathlib import Path
import time
import warnings

import femadh
from femadh.errors import MeshResolutionWarning
from femadh.runner import adaptive

HERE = Path(__file__).resolve().parent
RESULTS = HERE / "results"
SCENES = HERE / "scenes"

#: (label, scene file, changes)
REQUESTS = (
    ("Fig 4 at 3e-4", "paper1_fig4.toml", {"solver.accuracy": 3e-4}),
    ("slider + meniscus, sigma 0.489 nm, p/psat 0.5, at 3e-4", "paper1_slider_meniscus.toml",
     {"solver.accuracy": 3e-4, "effects.asperity_gap.sigma": "0.489 nm",
      "effects.capillary.relative_pressure": 0.5, "sweep.start": "4 nm",
      "solver.route": "grid"}),
    ("Fig 3 at 1e-4 (not capped: the same member)", "paper1_fig3.toml",
     {"solver.accuracy": 1e-4}),
    ("Fig 4 at 1e-4", "paper1_fig4.toml", {"solver.accuracy": 1e-4}),
)


def plan_scaled(scene, plan, target):
    """The rule before: the plan's spacing scaled, then capped."""
    h = min(plan.spacing * (target / adaptive.REFERENCE_ACCURACY) ** (1.0 / adaptive.ORDER),
            plan.family.band / adaptive.MIN_BAND_NODES)
    return adaptive._trial(scene, plan.family, h)


def measure(scene, rule):
    """(result, cpu s, wall s) of the adaptive run with ``rule`` as its first member."""
    keep = adaptive.first_trial
    adaptive.first_trial = rule
    try:
        c0, t0 = time.process_time(), time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", MeshResolutionWarning)
            res = femadh.run(scene, figures=False, progress=False)
        return res, time.process_time() - c0, time.perf_counter() - t0
    finally:
        adaptive.first_trial = keep


def row(label, rule_name, res, cpu, wall):
    steps = res.accuracy["steps"]
    trials = ", ".join(f"{s['nodes']} ({s['grid_rel_error'] + s['tail_rel_error']:.2g})"
                       for s in steps)
    hl = res.headline
    return (f"| {label} | {rule_name} | {trials} | {cpu:.1f} | {wall:.1f} | "
            f"{hl['max_adhesion_N']:.7e} ± {hl['max_adhesion_N_error']:.2g} | "
            f"{'yes' if res.accuracy['met'] else 'no'} |")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="leave out Fig 4 at 1e-4 (minutes)")
    args = ap.parse_args(argv)
    load0 = os.getloadavg()[0]
    lines = ["# The first member of a finer request: scaled from the capped 1e-3 member",
             "", __doc__.split("\n\n")[1].replace("\n", " "), "",
             "| request | first member | trials: nodes (estimate) | CPU (s) | wall (s) | "
             "largest adhesion (N) ± estimate | met |", "|---|---|---|---|---|---|---|"]
    for label, name, changes in REQUESTS:
        if args.quick and label == "Fig 4 at 1e-4":
            continue
        scene = femadh.load_scene(SCENES / name).replace(changes)
        for rule_name, rule in (("plan's spacing scaled (before)", plan_scaled),
                                ("capped 1e-3 member scaled (now)", adaptive.first_trial)):
            res, cpu, wall = measure(scene, rule)
            lines.append(row(label, rule_name, res, cpu, wall))
            print(lines[-1], flush=True)
    lines += ["", f"One process, one BLAS thread, no figures; 1-minute load average "
              f"{load0:.2f} at the start, {os.getloadavg()[0]:.2f} at the end, "
              f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}."]
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "first_member.md").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
