"""Should the adaptive grid follow the contact edge by default? A/B of the adaptive run with
the static band against a band that follows the edge (:data:`femadh.runner.adaptive.
FOLLOW_NODES`: a trial whose static member would exceed that many nodes runs on an
:class:`~femadh.discretisation.moving.EdgeBand` of half-width FOLLOW_HALF of the band).

``python -m validation.adaptive_follow [--modes static,0,600] [--cases ...]`` writes
validation/results/adaptive_follow.md: per case and mode the trials (nodes, estimated error),
the wall time, the headline values, their achieved error against the references of
validation/results/accuracy.md (a banded member at 5-15 nm spacing on twice the adaptive
radius; its values are recovered from that table's rows to ~5e-6 relative) and the
estimate's effectivity. Each case runs its modes back to back, so that they share the
machine's load (stated).
"""
import argparse
import json
import math
import os
from pathlib import Path
import time
import warnings

import femadh
from femadh.errors import MeshResolutionWarning
from femadh.runner import adaptive
from femadh.runner.run import run

HERE = Path(__file__).resolve().parent
SCENES = HERE / "scenes"
#: the references of validation/results/accuracy.md (banded: Fig 3 7.5 nm, 1123 nodes,
#: a = 101 um; Fig 4 5 nm, 1477 nodes, a = 50.6 um; slider + meniscus 15 nm, 940 nodes),
#: each value recovered from two rows (value, achieved) of that table
REFERENCE = {
    "paper1_fig3": {"max_adhesion_N": 3.11464e-05, "F_LJ_deepest_N": 2.72389e-04},
    "paper1_fig4": {"max_adhesion_N": 1.094986e-04, "F_LJ_deepest_N": 2.05963e-03},
    "paper1_slider_meniscus": {"max_adhesion_N": 5.47051e-04, "F_LJ_deepest_N": 2.96646e-04},
}
CASES = {
    "fig3 default": ("paper1_fig3", None),
    "fig4 default (3e-3)": ("paper1_fig4", None),
    "slider+meniscus default": ("paper1_slider_meniscus", None),
    "fig3 1e-4": ("paper1_fig3", 1e-4),
    "fig4 1e-3": ("paper1_fig4", 1e-3),
    "fig4 1e-4": ("paper1_fig4", 1e-4),
}
QUANT = ("max_adhesion_N", "F_LJ_deepest_N")


def one(name, mode):
    """One adaptive run of case ``name`` with FOLLOW_NODES = ``mode`` (None: static)."""
    scene, acc = CASES[name]
    sc = femadh.load_scene(SCENES / f"{scene}.toml")
    if acc is not None:
        sc = sc.replace({"solver.accuracy": acc})
    # the grid route throughout: route "auto" sends a band that follows the edge to the edge
    # route (femadh/runner/edge_route.py route_for), whose run has no grid trials to compare
    sc = sc.replace({"solver.route": "grid"})
    saved = adaptive.FOLLOW_NODES
    adaptive.FOLLOW_NODES = mode
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", MeshResolutionWarning)
            t0 = time.perf_counter()
            res = run(sc, None, figures=False, progress=False)
            t = time.perf_counter() - t0
    finally:
        adaptive.FOLLOW_NODES = saved
    ref = REFERENCE[scene]
    out = {"case": name, "mode": mode, "status": res.status, "error": res.error,
           "time_s": t, "load": os.getloadavg()[0],
           "trials": [(s["nodes"], s["grid_rel_error"] + s["tail_rel_error"],
                       bool(s.get("follow_m"))) for s in res.accuracy.get("steps", [])],
           "regrids": res.grid.get("regrids", 0)}
    for q in QUANT:
        v, e = res.headline.get(q, math.nan), res.headline.get(f"{q}_error", math.nan)
        true = abs(v - ref[q]) / abs(ref[q])
        out[q] = {"value": v, "achieved": true, "estimated": e / abs(ref[q]),
                  "effectivity": e / abs(ref[q]) / true if true > 0 else math.nan}
    return out


def _mode(x):
    return None if x == "static" else int(x)


def _label(mode):
    return "static" if mode is None else "follow always" if mode == 0 else \
        f"follow above {mode} nodes"


def table(rows, load0):
    lines = ["# Following the contact edge by default? (validation/adaptive_follow.py)", "",
             f"Machine load (1-min average) {load0:.1f} at the start (2 cores shared with "
             "other work; each row's own load in its column): wall times compare only "
             "within a case; the node counts and errors are exact.", "",
             "Achieved: against the references of validation/results/accuracy.md, their "
             "values recovered to ~5e-6 relative (an achieved error below ~1e-5 is at that "
             "precision and its effectivity is not meaningful). Trials: nodes (estimated "
             "relative error; f: the band followed the edge). Conclusion in "
             "validation/results/adaptive_loop.md.", "",
             "| case | mode | status | trials | time (s) | load | quantity | value | achieved "
             "| estimated | effectivity |", "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        trials = ", ".join(f"{n}{'f' if f else ''} ({e:.2g})" for n, e, f in r["trials"])
        for q in QUANT:
            c = r[q]
            lines.append(f"| {r['case']} | {_label(r['mode'])} | {r['status']} | {trials} | "
                         f"{r['time_s']:.1f} | {r['load']:.1f} | {q} | {c['value']:.6g} | "
                         f"{c['achieved']:.2e} | {c['estimated']:.2e} | "
                         f"{c['effectivity']:.2f} |")
    return lines


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--modes", default="static,0,600",
                    help="FOLLOW_NODES values to compare ('static': None)")
    ap.add_argument("--cases", default=",".join(c for c in CASES if c != "fig4 1e-4"),
                    help="comma-separated case names (fig4 1e-4 takes tens of minutes)")
    ap.add_argument("--json", help="also append the rows to this json-lines file")
    ap.add_argument("--render", help="only write the table from this json-lines file (the "
                    "rows of several runs of this script)")
    args = ap.parse_args(argv)
    load0 = os.getloadavg()[0]
    rows = []
    if args.render:
        rows = [json.loads(ln) for ln in Path(args.render).read_text().splitlines() if ln]
        order = list(CASES)
        rows.sort(key=lambda r: order.index(r["case"]))
        load0 = rows[0]["load"]
        args.cases = ""
    for name in filter(None, args.cases.split(",")):
        for m in args.modes.split(","):
            r = one(name, _mode(m))
            rows.append(r)
            print(json.dumps(r), flush=True)
            if args.json:
                with open(args.json, "a") as f:
                    f.write(json.dumps(r) + "\n")
    text = "\n".join(table(rows, load0)) + "\n"
    (HERE / "results" / "adaptive_follow.md").write_text(text)
    print(text)


if __name__ == "__main__":
    main()
