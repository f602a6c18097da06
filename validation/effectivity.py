"""Why an effectivity is off: one row of validation/accuracy.py's table taken apart.

``python -m validation.effectivity SCENE KIND SETTING [--ref-spacing H_NM ...]`` runs the
row (uniform N or adaptive request) and prints, for each headline number, the parts of its
error estimate (grid, tail, resolution, tolerance), the members' values, and the achieved
error against the reference(s) of validation/accuracy.py's family at the given band spacings
(cached in /tmp/eff: a reference is the slow part), so that the achieved error's own accuracy
is seen beside it (a finer reference that moves it).
"""
import argparse
import json
import math
from pathlib import Path

import femadh
from femadh.runner.estimates import variant

from .accuracy import CASES, SCENES, _adaptive, _timed

CACHE = Path("/tmp/eff")


def reference(name, h_ref, radius_factor=2.0):
    """Headline of the reference at band spacing h_ref (m) on radius_factor x the finest
    request's analysis radius (cached)."""
    CACHE.mkdir(exist_ok=True)
    f = CACHE / f"{name}_{h_ref * 1e9:.4g}nm_{radius_factor:g}a.json"
    if f.exists():
        return json.loads(f.read_text())
    base = femadh.load_scene(SCENES / f"{name}.toml")
    plan = CACHE / f"{name}_plan.json"
    if plan.exists():
        fam = json.loads(plan.read_text())
    else:
        requests = CASES[name][1]
        run, _ = _timed(_adaptive(base, min(requests)))
        st = run.accuracy["steps"][-1]
        fam = {"band": st["band_m"], "grading": run.grid["grading_m"],
               "a": st["analysis_radius_m"]}
        plan.write_text(json.dumps(fam))
    sc = variant(base, grid={"spacing": h_ref, "band": fam["band"], "grading": fam["grading"]},
                 radius=radius_factor * fam["a"])
    res, t = _timed(sc, estimate="peak")
    out = {k: v for k, v in res.headline.items() if isinstance(v, float)}
    out["_nodes"], out["_time_s"] = res.grid["nodes"], t
    f.write_text(json.dumps(out))
    return out


def row(name, kind, setting):
    base = femadh.load_scene(SCENES / f"{name}.toml")
    sc = variant(base, nodes=int(setting)) if kind == "uniform" else \
        _adaptive(base, float(setting))
    res, t = _timed(sc)
    return res, t


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("scene")
    ap.add_argument("kind", choices=("uniform", "adaptive"))
    ap.add_argument("setting")
    ap.add_argument("--ref-spacing", type=float, nargs="+", default=None,
                    help="reference band spacings (nm); the table's by default")
    ap.add_argument("--radius-factor", type=float, default=2.0)
    args = ap.parse_args(argv)
    quants = CASES[args.scene][3]
    hs = args.ref_spacing or [CASES[args.scene][2] * 1e9]
    refs = {h: reference(args.scene, h * 1e-9, args.radius_factor) for h in hs}
    res, t = row(args.scene, args.kind, args.setting)
    print(f"{args.scene} {args.kind} {args.setting}: nodes {res.grid.get('nodes')}, "
          f"{t:.2f} s, status {res.status}")
    print("grid:", {k: v for k, v in res.grid.items() if k not in ("deepest_members",)})
    print("deepest members:", res.grid.get("deepest_members"))
    if res.accuracy:
        for s in res.accuracy["steps"]:
            print("  step:", s)
    for q in quants:
        if q not in res.headline:
            continue
        v = res.headline[q]
        parts = res.estimates.get(q, {})
        line = f"{q} = {v!r}: " + ", ".join(f"{k} {p / abs(v):+.3e}" for k, p in parts.items())
        print(line)
        for h, ref in refs.items():
            if q in ref:
                true = (ref[q] - v) / abs(ref[q])
                est = parts.get("total", math.nan) / abs(ref[q])
                print(f"    ref {h:g} nm ({ref['_nodes']} nodes): signed achieved (ref - Q)/|ref| "
                      f"{true:+.3e}; effectivity {est / abs(true) if true else math.nan:.2f}")



def table(envelope_log=None):
    """Every row of validation/accuracy.py's CASES against the cached references: (scene,
    kind, setting, quantity, achieved, estimated, effectivity, the grid part's branch)."""
    rows = []
    try:
        for name, (nodes, requests, h_ref, quants) in CASES.items():
            ref = reference(name, h_ref)
            for kind, setting in [("uniform", n) for n in nodes] + \
                    [("adaptive", a) for a in requests]:
                res, t = row(name, kind, setting)
                for q in quants:
                    if q not in res.headline or q not in ref:
                        continue
                    true = abs(res.headline[q] - ref[q]) / abs(ref[q])
                    est = res.headline.get(f"{q}_error", math.nan) / abs(ref[q])
                    rows.append((name, kind, setting, q, true, est,
                                 est / true if true > 1e-12 else math.nan,
                                 {k: v / abs(ref[q]) for k, v in res.estimates.get(q, {}).items()}))
                    print(f"{name:24s} {kind:8s} {setting!s:7s} {q:16s} achieved {true:.2e} "
                          f"estimated {est:.2e} eff {rows[-1][6]:.2f}  "
                          + " ".join(f"{k} {v:+.2e}" for k, v in rows[-1][7].items()),
                          flush=True)
    finally:
        pass
    return rows


def deepest_reference(name, h_ref, radius_factor=2.0):
    """The F_LJ of the reference at the deepest state, checked below its own spacing
    (:func:`validation.accuracy.checked_deepest`: members placed by its deepest contact edge
    at h_ref / sqrt 2 and h_ref / 2, Richardson at the order they show, plus the tail beyond
    the reference's radius)."""
    from .accuracy import capture, checked_deepest

    base = femadh.load_scene(SCENES / f"{name}.toml")
    reference(name, h_ref, radius_factor)           # the family's plan, cached
    fam = json.loads((CACHE / f"{name}_plan.json").read_text())
    sc = variant(base, grid={"spacing": h_ref, "band": fam["band"], "grading": fam["grading"]},
                 radius=radius_factor * fam["a"])
    res, got = capture(sc)
    out = checked_deepest(res, got)
    if out is None:
        raise SystemExit(f"{name}: no members placed by the reference's deepest edge at "
                         f"{h_ref / 2**0.5:.3g} and {h_ref / 2:.3g} m (no edge the members can "
                         "be placed by, or a member that did not solve)")
    return out


if __name__ == "__main__":
    import sys
    if sys.argv[1:] == ["table"]:
        table()
    elif sys.argv[1:2] == ["deepest"]:
        print(deepest_reference(sys.argv[2], float(sys.argv[3]) * 1e-9))
    else:
        main()
