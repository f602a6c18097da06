"""Where an adaptive request starts: its first member (issue 21, goal 2: Fig 4 at 1e-3 and 1e-4).

The adaptive loop's first member (femadh/runner/adaptive.py, ``first_trial``) was the plan's
spacing (BAND_NODES across the band) scaled by (target / 1e-3)^(1/ORDER) and capped below the
trapping-safe spacing. Two changes, measured here against it:

- **capped**: a request finer than 1e-3 scales the capped 1e-3 member, not the plan's uncapped
  spacing (where the cap binds, the cohesive zone is narrower than BAND_NODES resolve);
- **cohesive zone** (now): a sigma-gap Lennard-Jones request at or below 1e-3 starts no
  coarser than CZ_NODES spacings across the law's Maugis-Dugdale cohesive zone at pull-off
  (``cohesive_spacing``), scaled by the LJ share of the work of adhesion and the request.

Each request is run with each rule in one process (the older rules patched in), one BLAS
thread, no figures; every trial's nodes and estimate, the CPU and wall seconds of the whole
adaptive run, the largest adhesion and its estimated error. Writes
validation/results/first_member.md.

    python -m validation.first_member [--quick]      # --quick: without Fig 4 at 1e-4

CPU seconds are the comparison where the machine is shared (the load is recorded).
"""
import argparse
import math
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
    ("Fig 4 at 1e-3", "paper1_fig4.toml", {"solver.accuracy": 1e-3}),
    ("Fig 4 at 3e-4", "paper1_fig4.toml", {"solver.accuracy": 3e-4}),
    ("Fig 4, sigma 0.6 nm, at 1e-3", "paper1_fig4.toml",
     {"solver.accuracy": 1e-3, "effects.asperity_gap.sigma": "0.6 nm"}),
    ("Fig 4, sigma 0.7 nm, at 1e-3", "paper1_fig4.toml",
     {"solver.accuracy": 1e-3, "effects.asperity_gap.sigma": "0.7 nm"}),
    *((f"slider + meniscus, sigma {float(s):.3g} nm, p/psat {p}, at 1e-3",
       "paper1_slider_meniscus.toml",
       {"solver.accuracy": 1e-3, "effects.asperity_gap.sigma": f"{s} nm",
        "effects.capillary.relative_pressure": p, "sweep.start": "4 nm",
        "solver.route": "grid"})
      for s, p in (("0.488888888889", 0.05), ("0.488888888889", 0.25),
                   ("0.488888888889", 0.35), ("0.488888888889", 0.45),
                   ("0.677777777778", 0.05), ("0.677777777778", 0.15))),
    ("slider + meniscus, sigma 0.489 nm, p/psat 0.5, at 3e-4", "paper1_slider_meniscus.toml",
     {"solver.accuracy": 3e-4, "effects.asperity_gap.sigma": "0.489 nm",
      "effects.capillary.relative_pressure": 0.5, "sweep.start": "4 nm",
      "solver.route": "grid"}),
    ("Fig 3 at 1e-4 (neither rule binds)", "paper1_fig3.toml", {"solver.accuracy": 1e-4}),
    ("Fig 4 at 1e-4", "paper1_fig4.toml", {"solver.accuracy": 1e-4}),
)


def plan_scaled(scene, plan, target):
    """The rule before: the plan's spacing scaled, then capped."""
    h = min(plan.spacing * (target / adaptive.REFERENCE_ACCURACY) ** (1.0 / adaptive.ORDER),
            plan.family.band / adaptive.MIN_BAND_NODES)
    return adaptive._trial(scene, plan.family, h)


def capped_only(scene, plan, target):
    """The capped rule without the cohesive zone's."""
    keep = adaptive.cohesive_spacing
    adaptive.cohesive_spacing = lambda scene, target: None
    try:
        return keep_first(scene, plan, target)
    finally:
        adaptive.cohesive_spacing = keep


keep_first = adaptive.first_trial
RULES = (("plan's spacing scaled (before)", plan_scaled),
         ("capped 1e-3 member scaled", capped_only),
         ("with the cohesive zone (now)", keep_first))


def measure(scene, rule):
    """(result, cpu s, wall s) of the adaptive run with ``rule`` as its first member."""
    adaptive.first_trial = rule
    try:
        c0, t0 = time.process_time(), time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", MeshResolutionWarning)
            res = femadh.run(scene, figures=False, progress=False)
        return res, time.process_time() - c0, time.perf_counter() - t0
    finally:
        adaptive.first_trial = keep_first


def row(label, rule_name, res, cpu, wall):
    steps = res.accuracy["steps"]
    trials = ", ".join(f"{s['nodes']} ({s['grid_rel_error'] + s['tail_rel_error']:.2g})"
                       for s in steps)
    hl = res.headline
    return (f"| {label} | {rule_name} | {trials} | {cpu:.1f} | {wall:.1f} | "
            f"{hl['max_adhesion_N']:.7e} ± {hl['max_adhesion_N_error']:.2g} | "
            f"{'yes' if res.accuracy['met'] else 'no'} |")


#: the Fig 4 family CZ_NODES is measured on: (sigma, sphere radius)
ZONE_FAMILY = (("0.42 nm", "2 mm"), ("0.45 nm", "2 mm"), ("0.5 nm", "2 mm"),
               ("0.55 nm", "2 mm"), ("0.6 nm", "2 mm"), ("0.7 nm", "2 mm"),
               ("0.5 nm", "1 mm"), ("0.5 nm", "4 mm"))


def zone_rows():
    """Per member of ZONE_FAMILY at 1e-3 on the capped rule (no cohesive-zone start): lambda,
    the zone's width, the runs, the band spacing that meets 1e-3 (the estimate's power law
    between the last two runs; order 2 from a single run) and the width over that spacing."""
    rows = ["", "## How many spacings across the cohesive zone meet 1e-3 (CZ_NODES)", "",
            "The Fig 4 scene (sigma-gap LJ) at 1e-3 with the capped rule alone; lambda and "
            "the Maugis-Dugdale zone width at pull-off as `cohesive_spacing` computes them; "
            "h(1e-3): the band spacing at which the estimate's power law between the last two "
            "runs reaches 1e-3 (order 2 where one run met).", "",
            "| sigma | R | lambda | zone width (nm) | runs: spacing nm (estimate) | h(1e-3) (nm) "
            "| width / h(1e-3) |", "|---|---|---|---|---|---|---|"]
    for sigma, radius in ZONE_FAMILY:
        scene = femadh.load_scene(SCENES / "paper1_fig4.toml").replace(
            {"solver.accuracy": 1e-3, "effects.asperity_gap.sigma": sigma,
             "sphere.radius": radius})
        lam, width = adaptive.cohesive_zone(scene)
        res, _, _ = measure(scene, capped_only)
        st = [(s["spacing_m"], s["grid_rel_error"] + s["tail_rel_error"])
              for s in res.accuracy["steps"]]
        if len(st) > 1 and st[-2][1] > st[-1][1]:
            (h0, e0), (h1, e1) = st[-2:]
            p = math.log(e0 / e1) / math.log(h0 / h1)
        else:
            (h1, e1), p = st[-1], 2.0
        h = h1 * (1e-3 / e1) ** (1 / p)
        runs = ", ".join(f"{a * 1e9:.3g} ({b:.2g})" for a, b in st)
        rows.append(f"| {sigma} | {radius} | {lam:.2f} | {width * 1e9:.0f} | {runs} | "
                    f"{h * 1e9:.3g} | {width / h:.1f} |")
        print(rows[-1], flush=True)
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="leave out Fig 4 at 1e-4 (minutes)")
    args = ap.parse_args(argv)
    load0 = os.getloadavg()[0]
    lines = ["# The first member of an adaptive request",
             "", *__doc__.split("\n\n")[1:4], "",
             "| request | first member | trials: nodes (estimate) | CPU (s) | wall (s) | "
             "largest adhesion (N) ± estimate | met |", "|---|---|---|---|---|---|---|"]
    for label, name, changes in REQUESTS:
        if args.quick and label == "Fig 4 at 1e-4":
            continue
        scene = femadh.load_scene(SCENES / name).replace(changes)
        target = scene.target_accuracy
        for rule_name, rule in RULES:
            if target >= adaptive.REFERENCE_ACCURACY and rule is plan_scaled:
                continue            # (at 1e-3 the first two rules are one)
            res, cpu, wall = measure(scene, rule)
            lines.append(row(label, rule_name, res, cpu, wall))
            print(lines[-1], flush=True)
    lines += zone_rows()
    lines += ["", f"One process, one BLAS thread, no figures; 1-minute load average "
              f"{load0:.2f} at the start, {os.getloadavg()[0]:.2f} at the end, "
              f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}."]
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "first_member.md").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
