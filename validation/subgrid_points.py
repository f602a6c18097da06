"""Single points of the stiction map (validation/stiction_map.py), each run alone at the
scene's defaults with the map's sweep start and per-point time limit: status, nodes, wall
time, max adhesion and its estimated error.

    python -m validation.subgrid_points [--points 0.3:0.05,0.489:0.15 ...] [--out FILE]
    python -m validation.subgrid_points --cost     # the integrated law's price, both ways

Used to measure the sub-grid integration of the step laws (validation/results/subgrid.md).
``--cost``: the bundled slider + meniscus scene (p/psat 0.95) on uniform N = 400, its sweep
with the meniscus collocated and integrated (solves, Newton iterations, factorisations, jumps,
wall and CPU time: on a loaded machine the CPU time is the comparison), and the time of one law evaluation (nodal pressures and the law Jacobian, as a
Newton iteration asks for them) at a state with the meniscus edge inside the disk, median of
50.
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


def cost(nodes=400):
    """Rows (dict) of the slider + meniscus sweep with the meniscus collocated and integrated."""
    import statistics

    import numpy as np

    from femadh.contact import ContactProblem
    from femadh.runner.contact import solve_sweeps
    from femadh.scene import build_problem

    scene = femadh.load_scene(SCENE).replace({"solver.nodes": nodes})
    base = build_problem(scene)
    rows = []
    for sub in (False, True):
        p = ContactProblem(base.operator, base.sphere, dict(base.effects), base.gap,
                           subgrid=sub)
        t0, c0 = time.perf_counter(), time.process_time()
        p, sweeps, err = solve_sweeps(scene, p)
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        work = {}
        for sw in sweeps.values():
            for k, v in sw.work.items():
                work[k] = work.get(k, 0) + v
        st = max((s for sw in sweeps.values() for s in sw.states),
                 key=lambda s: float(np.sum(s.h < p.effects["capillary"].fill_gap)))
        ts = []
        for _ in range(50):
            h = st.h * (1 + 1e-15 * len(ts))        # a new gap field each time (no cache)
            t1 = time.perf_counter()
            p.pressure(h)
            p.law_jacobian(h)
            ts.append(time.perf_counter() - t1)
        rows.append({"meniscus": "integrated" if sub else "collocated", "nodes": p.grid.n,
                     "error": err, "jumps": sum(len(sw.jumps) for sw in sweeps.values()),
                     **work, "sweep_s": round(wall, 2), "sweep_cpu_s": round(cpu, 2),
                     "law_eval_ms": round(1e3 * statistics.median(ts), 3),
                     "load": round(os.getloadavg()[0], 2)})
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--points", default=",".join(f"{s}:{r}" for s, r in CORNERS))
    ap.add_argument("--limit", default=POINT_LIMIT)
    ap.add_argument("--out", default=None, help="append one json line per point")
    ap.add_argument("--cost", action="store_true", help="the integrated law's price")
    args = ap.parse_args(argv)
    if args.cost:
        for row in cost():
            print(json.dumps(row), flush=True)
        return
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
