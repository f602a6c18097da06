"""What the adaptive loop's sizing costs: every adaptive row of validation/accuracy.py and the
bundled adaptive scenes at their defaults, each run's nodes, spacing and estimate, and the work.

``python -m validation.adaptive_order [--only NAME] [--no-accuracy] [--json FILE]`` runs the
adaptive rows of :mod:`validation.accuracy` (``case(name, adaptive_only=True)``: its reference
and its achieved errors) while recording, for every adaptive request, each run of the refine
loop (``result.accuracy["steps"]``: nodes, band spacing, estimated grid and tail error) and
the Newton iterations of the last run's sweep (the branches' ``n_iter``), then the bundled
scenes without ``[solver] nodes`` at their defaults. Work is counted, not timed (the machine
this was measured on was shared): sum over the runs of nodes^3 (a dense LU per corrector
factorisation is N^3 / 3; every run factorises at the states it solves) and, for the last
run, Newton iterations x nodes^2.

Run it from the worktree whose ``femadh`` is to be measured (the cwd copy wins).
"""
import argparse
import json
import math
import os
from pathlib import Path
import warnings

import femadh
from femadh.errors import MeshResolutionWarning

import validation.accuracy as acc

HERE = Path(__file__).resolve().parent
#: the bundled scenes that run on the adaptive grid (no [solver] nodes)
ADAPTIVE_SCENES = ("paper1_fig3", "paper1_fig4", "paper1_slider_meniscus")


def _record(res):
    steps = (res.accuracy or {}).get("steps", [])
    iters = 0
    for b in res.branches.values():
        iters += int(sum(b.get("n_iter", ())))
    return {"runs": len(steps), "nodes": [s["nodes"] for s in steps],
            "spacing_nm": [s["spacing_m"] * 1e9 for s in steps],
            "estimate": [s["grid_rel_error"] + s["tail_rel_error"] for s in steps],
            "status": res.status, "met": (res.accuracy or {}).get("met"),
            "work_n3": float(sum(float(n) ** 3 for n in (s["nodes"] for s in steps))),
            "last_newton": iters,
            "last_newton_n2": float(iters) * float(steps[-1]["nodes"]) ** 2 if steps else 0.0,
            "headline": {k: v for k, v in res.headline.items()
                         if isinstance(v, float)}}


def accuracy_rows(only=None):
    """The adaptive rows of validation/accuracy.py with each request's runs."""
    seen = {}
    timed = acc._timed

    def spy(sc, **kw):
        res, t = timed(sc, **kw)
        a = (sc.target_accuracy if "nodes" not in sc.raw.get("solver", {}) and not kw
             else None)
        if a is not None and res.accuracy:
            seen[(Path(sc.path).stem, a)] = _record(res)
        return res, t

    acc._timed = spy
    out = []
    try:
        for name in acc.CASES:
            if only and only not in name:
                continue
            rows, ref = acc.case(name, adaptive_only=True)
            for r in rows:
                r["scene"] = name
                r.update(seen.get((name, r["setting"]), {}))
                out.append(r)
            print(f"{name}: reference {ref['nodes']} nodes", flush=True)
    finally:
        acc._timed = timed
    return out


def requests(spec):
    """Each request of ``spec`` ("scene:accuracy,...") run alone: its runs, no reference."""
    out = {}
    for item in spec.split(","):
        name, a = item.split(":")
        base = femadh.load_scene(acc.SCENES / f"{name}.toml")
        res, _ = acc._timed(acc._adaptive(base, float(a)))
        out[item] = _record(res)
        print(item, out[item]["nodes"], [f"{e:.3g}" for e in out[item]["estimate"]],
              out[item]["status"], out[item]["met"], flush=True)
    return out


def scenes(only=None):
    out = {}
    for name in ADAPTIVE_SCENES:
        if only and only not in name:
            continue
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", MeshResolutionWarning)
            res = femadh.run(femadh.load_scene(acc.SCENES / f"{name}.toml"), progress=False,
                             figures=False)
        out[name] = _record(res)
        out[name]["errors"] = {k: v for k, v in res.headline.items() if k.endswith("_error")}
        print(name, out[name]["nodes"], out[name]["estimate"], flush=True)
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", help="the scenes whose name contains this")
    ap.add_argument("--no-accuracy", action="store_true", help="the bundled scenes only")
    ap.add_argument("--no-scenes", action="store_true", help="the accuracy rows only")
    ap.add_argument("--json", help="write the records here")
    ap.add_argument("--requests", help="scene:accuracy,... run alone (no reference)")
    args = ap.parse_args(argv)
    load = os.getloadavg()[0]
    data = {"load_start": load, "femadh": femadh.__file__}
    if args.requests:
        data["requests"] = requests(args.requests)
    elif not args.no_accuracy:
        data["accuracy"] = accuracy_rows(args.only)
        for r in data["accuracy"]:
            print(f"{r['scene']} {r['setting']:g} {r['quantity']}: nodes {r.get('nodes')} "
                  f"runs {r.get('runs')} {r.get('nodes')} est {r['estimated']:.2e} "
                  f"achieved {r['achieved']:.2e} {r['status']} met={r['met']}")
    if not (args.no_scenes or args.requests):
        data["scenes"] = scenes(args.only)
    data["load_end"] = os.getloadavg()[0]
    if args.json:
        Path(args.json).write_text(json.dumps(data, indent=1, default=lambda x: (
            None if isinstance(x, float) and not math.isfinite(x) else str(x))))


if __name__ == "__main__":
    main()
