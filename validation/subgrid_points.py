"""Single points of the stiction map (validation/stiction_map.py), each run alone at the
scene's defaults with the map's sweep start and per-point time limit: status, nodes, wall
time, max adhesion and its estimated error.

    python -m validation.subgrid_points [--points 0.3:0.05,0.489:0.15 ...] [--out FILE]

Used to measure the sub-grid integration of the step laws (validation/results/subgrid.md).
"""
import argparse
import json
import os
import time

import femadh

from .stiction_map import MAP, POINT_LIMIT, SCENE

#: the corner points of the map (sigma nm, p/psat) the sub-grid integration is measured on
CORNERS = ((0.3, 0.05), (0.3, 0.35), (0.489, 0.15), (0.489, 0.25), (1.06, 0.35))


def one_point(sigma_nm, rel, limit=POINT_LIMIT):
    """(record dict) of one map point run alone, no output folder."""
    scene = femadh.load_scene(SCENE).replace({
        "effects.asperity_gap.sigma": f"{sigma_nm} nm",
        "effects.capillary.relative_pressure": rel,
        "sweep.start": MAP["sweep.start"], "solver.time_limit": limit})
    t0 = time.perf_counter()
    res = femadh.run(scene)
    wall = time.perf_counter() - t0
    hl = res.headline
    acc = getattr(res, "accuracy", None) or {}
    return {"sigma_nm": sigma_nm, "p_psat": rel, "status": res.status,
            "error": (res.error or "")[:160], "nodes": acc.get("nodes", res.grid.get("nodes")),
            "time_s": round(wall, 2), "max_adhesion_N": hl.get("max_adhesion_N"),
            "max_adhesion_N_error": hl.get("max_adhesion_N_error"),
            "load": round(os.getloadavg()[0], 2)}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--points", default=",".join(f"{s}:{r}" for s, r in CORNERS))
    ap.add_argument("--limit", default=POINT_LIMIT)
    ap.add_argument("--out", default=None, help="append one json line per point")
    args = ap.parse_args(argv)
    for item in args.points.split(","):
        s, r = item.split(":")
        rec = one_point(float(s), float(r), args.limit)
        line = json.dumps(rec)
        print(line, flush=True)
        if args.out:
            with open(args.out, "a") as f:
                f.write(line + "\n")


if __name__ == "__main__":
    main()
