"""What each digit costs, uniform against adaptive: the paper-1 scenes on today's explicit
uniform grids and on femadh's adaptive banded grid at several requested accuracies, each
judged against a reference on a much finer member of the banded family.

``python -m validation.adaptive [--quick]`` writes validation/results/adaptive.md (a few
minutes on two cores, one BLAS thread; the times are the numbers, so run it on a quiet
machine and state its load). Columns: nodes, analysis radius, wall time of the whole run
(solve, estimates, refinements; no figures), the achieved relative error against the
reference, femadh's own estimate, and their ratio (effectivity).
"""
import argparse
import copy
import math
import os
from pathlib import Path
import time
import warnings

import femadh
from femadh.errors import MeshResolutionWarning
from femadh.runner.estimates import variant
from femadh.scene import scene_from_dict

HERE = Path(__file__).resolve().parent
RESULTS = HERE / "results"
SCENES = HERE / "scenes"
QUANT = ("max_adhesion_N", "F_LJ_deepest_N")

#: scene -> (uniform node counts, requested accuracies, reference band spacing (m))
CASES = {
    "paper1_fig3": ((200, 400, 800), (1e-2, 3e-3, 1e-3, 3e-4), 7.5e-9),
    "paper1_fig4": ((200, 400, 800), (1e-2, 3e-3, 1e-3), 8.5e-9),
    "paper1_slider_meniscus": ((200, 400), (1e-2, 1e-3), 15e-9),
}


def _timed(sc, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshResolutionWarning)
        t0 = time.perf_counter()
        res = femadh.run(sc, progress=False, figures=False, **kw)
        return res, time.perf_counter() - t0


def _adaptive(base, accuracy):
    raw = copy.deepcopy(base.raw)
    raw["solver"].pop("nodes", None)
    raw["solver"]["accuracy"] = accuracy
    return scene_from_dict(raw, base.path, bare_numbers=False)


def case(name, quick=False):
    """Rows for one scene and its reference record."""
    nodes, requests, h_ref = CASES[name]
    if quick:
        nodes, requests = nodes[:1], requests[:2]
    base = femadh.load_scene(SCENES / f"{name}.toml")
    # the reference: the finest adaptive request's family, at h_ref, on twice its radius
    plan_run, _ = _timed(_adaptive(base, min(requests)))
    fam = plan_run.accuracy["steps"][-1]
    ref_sc = variant(base, grid={"spacing": h_ref, "band": fam["band_m"],
                                 "grading": plan_run.grid["grading_m"]},
                     radius=2 * fam["analysis_radius_m"])
    ref, t_ref = _timed(ref_sc, estimate="peak")
    rows = []
    runs = [("uniform", n, variant(base, nodes=n)) for n in nodes]
    runs += [("adaptive", acc, _adaptive(base, acc)) for acc in requests]
    for kind, setting, sc in runs:
        res, t = (plan_run, plan_run.accuracy["wall_time_s"]) if (
            kind == "adaptive" and setting == min(requests)) else _timed(sc)
        for q in QUANT:
            if q not in res.headline or q not in ref.headline:
                continue
            true = abs(res.headline[q] - ref.headline[q]) / abs(ref.headline[q])
            est = res.headline.get(f"{q}_error", math.nan) / abs(ref.headline[q])
            rows.append({"kind": kind, "setting": setting, "nodes": res.grid.get("nodes"),
                         "a_um": res.grid.get("analysis_radius_m", math.nan) * 1e6,
                         "time_s": t, "quantity": q, "achieved": true, "estimated": est,
                         "effectivity": est / true if true > 0 else math.nan,
                         "status": res.status, "met": res.accuracy.get("met")})
    return rows, {"nodes": ref.grid["nodes"], "spacing_nm": h_ref * 1e9, "time_s": t_ref,
                  "a_um": ref.grid["analysis_radius_m"] * 1e6}


def _f(x, fmt=".2e"):
    return "—" if x is None or (isinstance(x, float) and not math.isfinite(x)) else format(x, fmt)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="one uniform and two adaptive rows")
    ap.add_argument("--only", help="run the scenes whose name contains this")
    args = ap.parse_args(argv)
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else math.nan
    lines = ["# What each digit costs: uniform vs adaptive grids (validation/adaptive.py)", "",
             "Uniform: `[solver] nodes = N` on the scene's own analysis disk (the former "
             "defaults). Adaptive: no nodes, `[solver] accuracy` as given (the default is "
             "1e-3): femadh's banded grid, its analysis radius grown until the tail is 5 % of "
             "the request, refined by its own estimate. Achieved: against a reference on the "
             "same banded family at the stated spacing, on twice the adaptive radius. Time: "
             "the whole run (solve, estimate members, refinements), no figures, one BLAS "
             f"thread; 1-minute load average at the start {load:.2f} on 2 cores.", ""]
    for name in CASES:
        if args.only and args.only not in name:
            continue
        rows, ref = case(name, args.quick)
        lines += [f"## {name}", "",
                  f"Reference: banded, spacing {ref['spacing_nm']:.3g} nm, {ref['nodes']} "
                  f"nodes, a = {ref['a_um']:.3g} um ({ref['time_s']:.1f} s).", "",
                  "| grid | N or request | nodes | a (um) | time (s) | quantity | achieved | "
                  "estimated | effectivity | status |", "|---|---|---|---|---|---|---|---|---|---|"]
        for r in rows:
            status = r["status"] + ("" if r["kind"] == "uniform" else
                                    "; met" if r["met"] else "; not met")
            lines.append(f"| {r['kind']} | {r['setting']} | {r['nodes']} | {r['a_um']:.3g} | "
                         f"{r['time_s']:.2f} | {r['quantity']} | {_f(r['achieved'])} | "
                         f"{_f(r['estimated'])} | {_f(r['effectivity'], '.2f')} | {status} |")
        lines.append("")
        print("\n".join(lines[-len(rows) - 6:]), flush=True)
    out = RESULTS / ("adaptive_quick.md" if args.quick else "adaptive.md")
    if not args.only:
        out.write_text("\n".join(lines) + "\n")
        print(f"written: {out}")


if __name__ == "__main__":
    main()
