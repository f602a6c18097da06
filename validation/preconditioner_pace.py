"""The Krylov preconditioner's cost, this checkout against an earlier one: a refresh (the
trailing Cholesky of the energy Hessian at a Fig 4 contact state, built and made ready to
solve) and one application (the solve GMRES calls once per Krylov iteration), on the Fig 4
scene's adaptive member of 631 nodes, one BLAS thread.

``python -m validation.preconditioner_pace --before PATH [--repeat 15]`` prints the median
of ``repeat`` alternating timings of each, with the 1-minute load average; PATH is a
checkout of an earlier femadh (``git archive <commit> | tar -x -C PATH``). Each side runs
in its own process (its own ``femadh``), on the same state: the Fig 4 disk at d = 0 solved
afresh by each side's corrector.
"""
import argparse
import json
import os
from pathlib import Path
import statistics
import subprocess
import sys
import time

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
#: the band spacing (m) of the Fig 4 scene's member at accuracy 1e-3 (631 nodes)
SPACING = 11.312e-9


def _child(repeat):
    import numpy as np

    from femadh.contact.complementarity import (DISK_MARGIN_FRACTION, _held_zero,
                                                solve_complementarity)
    from femadh.contact.linalg import TrailingCholesky, disk_size
    from femadh.discretisation import plan_grid
    from femadh.elastic import GreenOperator
    from femadh.scene import build_problem, load_scene

    scene = load_scene(HERE / "scenes" / "paper1_fig4.toml")
    plan = plan_grid(scene.effects, scene.gap.sigma, scene.sphere, scene.analysis_radius,
                     scene.d_values, 1e-3)
    p = build_problem(scene, operator=GreenOperator(plan.family.member(SPACING),
                                                    scene.e_star))
    st = solve_complementarity(p, 0.0, np.zeros(p.grid.n), tol=scene.tolerance, max_iter=80)
    m, n = disk_size(st.active), p.grid.n
    m0 = max(0, m - max(4, int(DISK_MARGIN_FRACTION * n)))
    D = _held_zero(p.law_jacobian(st.h), st.active)
    r = np.random.default_rng(0).standard_normal(n - m)
    refresh, apply = [], []
    for _ in range(repeat):
        t = time.perf_counter()
        pre = TrailingCholesky(p.S_sym, p.areas, D, m0)
        assert pre.covers(m)
        pre.solve(m, r)                 # the first solve of a block readies it
        refresh.append(time.perf_counter() - t)
        t = time.perf_counter()
        for _ in range(20):
            pre.solve(m, r)
        apply.append((time.perf_counter() - t) / 20)
    print(json.dumps({"nodes": n, "free": n - m, "converged": bool(st.converged),
                      "refresh_ms": [x * 1e3 for x in refresh],
                      "apply_us": [x * 1e6 for x in apply]}))


def _run(code, repeat):
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env.update(OPENBLAS_NUM_THREADS="1", PYTHONPATH=str(code))
    p = subprocess.run([sys.executable, str(Path(__file__).resolve()), "--child",
                        str(repeat)], capture_output=True, text=True, env=env, cwd=str(code))
    if p.returncode != 0:
        raise RuntimeError(p.stderr.strip().splitlines()[-1])
    return json.loads([x for x in p.stdout.splitlines() if x.startswith("{")][-1])


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--before", required=False, help="a checkout of an earlier femadh")
    ap.add_argument("--repeat", type=int, default=15)
    ap.add_argument("--rounds", type=int, default=3, help="alternating processes per side")
    ap.add_argument("--child", type=int, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        _child(args.child)
        return 0
    sides = [("this", ROOT)] + ([("before", Path(args.before).resolve())] if args.before
                                else [])
    got = {label: {"refresh_ms": [], "apply_us": []} for label, _ in sides}
    loads = [os.getloadavg()[0]]
    for _ in range(args.rounds):
        for label, code in sides:
            r = _run(code, args.repeat)
            got[label]["refresh_ms"] += r["refresh_ms"]
            got[label]["apply_us"] += r["apply_us"]
            got[label]["nodes"], got[label]["free"] = r["nodes"], r["free"]
        loads.append(os.getloadavg()[0])
    for label, g in got.items():
        print(f"{label}: {g['nodes']} nodes, {g['free']} free; refresh median "
              f"{statistics.median(g['refresh_ms']):.2f} ms, application median "
              f"{statistics.median(g['apply_us']):.1f} us "
              f"({len(g['refresh_ms'])} timings each)")
    print(f"1-minute load average {min(loads):.1f}-{max(loads):.1f} (2 cores)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
