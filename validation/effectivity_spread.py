"""Effectivity across a family of band spacings: how the error estimate judges a run wherever
the adaptive loop may land, not only at the few spacings validation/accuracy.py's requests
reach.

For each paper-1 scene of validation/accuracy.py, the banded family of its finest request (the
band, grading and analysis radius of that request's last trial) is run at SPACINGS band
spacings, geometrically between the scene's limits, each with its own error estimate (two
coarser members at ratio sqrt 2), and judged against accuracy.py's reference (the same family
at the reference spacing on twice the radius, with its tails). A row whose achieved error is
below 1e-12 of the number (a fold on the reference's own stepping lattice) is not judged.

Writes validation/results/effectivity_spread.md (~40 s on two cores, one BLAS thread)::

    python -m validation.effectivity_spread

``--uniform``: uniform grids of N nodes on the scene's own disk instead (the user's explicit
``[solver] nodes``, members N/2 and N/4 or placed by the deepest edge), written to
effectivity_spread_uniform.md.
"""
import argparse
import math
import time

import numpy as np

import femadh
from femadh.runner.estimates import variant

from .accuracy import CASES, RESULTS, SCENES, _adaptive, _timed, reference

#: spacings (nm) each scene's family is run at: coarsest, finest, count. The finest is the
#: spacing of the scene's finest request in accuracy.md (Fig 3 1e-4: 9.4 nm; Fig 4 1e-3:
#: 13.2 nm; the slider 1e-3: 80.6 nm) or below it; the coarsest, near its 1e-2 request's -
#: on Fig 4 the trapping-safe spacing, 25.6 nm, which the adaptive loop never exceeds there
#: (coarser members soften beyond a node's stiffness: 39.5 and 52.2 nm read F_LJ at the
#: deepest state at effectivity 0.42 and 0.45, the only rows below 0.5 when they were run)
SPACINGS = {"paper1_fig3": (140.0, 9.0, 22), "paper1_fig4": (25.6, 11.0, 12),
            "paper1_slider_meniscus": (160.0, 20.0, 16)}
#: uniform grids run with --uniform: fewest nodes, most, count (Fig 4 from 200: below it the
#: N/4 member softens beyond a node's stiffness)
UNIFORM = {"paper1_fig3": (100, 800, 12), "paper1_fig4": (200, 800, 8),
           "paper1_slider_meniscus": (100, 600, 10)}
#: the headline numbers judged (the forces and separations the estimate states; the
#: separation of the largest adhesion too, which accuracy.py's table does not judge)
QUANTITIES = ("max_adhesion_N", "d_at_max_adhesion_m", "F_LJ_deepest_N", "jump_in_d_m",
              "jump_out_d_m")
#: the band of effectivity the issue asks for, and the estimate's optimism limit
LOW, HIGH = 0.5, 5.0


def scene_rows(name, uniform=False):
    """[(spacing m, nodes, seconds, quantity, achieved, estimated, effectivity)] of one scene's
    family (``uniform``: its uniform grids, spacing the analysis radius over N), and its
    reference's seconds."""
    _nodes, requests, h_ref, _q = CASES[name]
    base = femadh.load_scene(SCENES / f"{name}.toml")
    plan_run, _ = _timed(_adaptive(base, min(requests)))
    _ref, ref_hl, t_ref, _checked, _tails = reference(name, base, plan_run, h_ref)
    step = plan_run.accuracy["steps"][-1]
    fam = {"band": step["band_m"], "grading": plan_run.grid["grading_m"]}
    if uniform:
        lo, hi, n = UNIFORM[name]
        runs = [(None, variant(base, nodes=int(round(k)))) for k in np.geomspace(lo, hi, n)]
    else:
        hi, lo, n = SPACINGS[name]
        runs = [(float(h), variant(base, grid={**fam, "spacing": float(h)},
                                   radius=step["analysis_radius_m"]))
                for h in np.geomspace(hi, lo, n) * 1e-9]
    rows = []
    for h, sc in runs:
        res, t = _timed(sc)
        if h is None:
            h = res.grid["analysis_radius_m"] / res.grid["nodes"]
        for q in QUANTITIES:
            if res.headline.get(q) is None or ref_hl.get(q) is None:
                continue
            true = abs(res.headline[q] - ref_hl[q]) / abs(ref_hl[q])
            est = res.headline.get(f"{q}_error", math.nan) / abs(ref_hl[q])
            rows.append((h, res.grid["nodes"], t, q, true, est,
                         est / true if true > 1e-12 else math.nan))
    return rows, t_ref


def summary(rows):
    """{quantity: (judged, min, median, max, below LOW, above HIGH)} of effectivity."""
    out = {}
    for q in QUANTITIES:
        e = np.array([r[6] for r in rows if r[3] == q and math.isfinite(r[6])])
        if e.size:
            out[q] = (e.size, e.min(), float(np.median(e)), e.max(), int((e < LOW).sum()),
                      int((e > HIGH).sum()))
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--only", help="scenes whose name contains this (no file written)")
    ap.add_argument("--uniform", action="store_true",
                    help="uniform grids of N nodes instead of the banded family")
    args = ap.parse_args(argv)
    names = [n for n in SPACINGS if not args.only or args.only in n]
    t0 = time.perf_counter()
    lines = ["# Effectivity across a family of spacings (validation/effectivity_spread.py)", "",
             __doc__.split("\n\n")[1].replace("\n", " "), ""]
    every = []
    for name in names:
        rows, t_ref = scene_rows(name, args.uniform)
        every += rows
        lines += [f"## {name}", "", f"Reference: accuracy.py's ({t_ref:.1f} s).", "",
                  "| spacing (nm) | nodes | time (s) | quantity | achieved | estimated | "
                  "effectivity |", "|---|---|---|---|---|---|---|"]
        lines += [f"| {h * 1e9:.1f} | {n} | {t:.2f} | {q} | {a:.2e} | {e:.2e} | "
                  + (f"{f:.2f} |" if math.isfinite(f) else "— |")
                  for h, n, t, q, a, e, f in rows]
        lines.append("")
        print(f"{name}: {len(rows)} rows", flush=True)
    lines += ["## Summary (every scene)", "",
              f"| quantity | judged | min | median | max | below {LOW} | above {HIGH} |",
              "|---|---|---|---|---|---|---|"]
    for q, (n, lo, med, hi, below, above) in summary(every).items():
        lines.append(f"| {q} | {n} | {lo:.2f} | {med:.2f} | {hi:.2f} | {below} | {above} |")
    lines += ["", f"Wall time {time.perf_counter() - t0:.0f} s."]
    text = "\n".join(lines) + "\n"
    if args.only:
        print(text)
    else:
        (RESULTS / ("effectivity_spread_uniform.md" if args.uniform
                    else "effectivity_spread.md")).write_text(text)
        print(text.split("## Summary")[1])


if __name__ == "__main__":
    main()
