"""Accuracy vs time of the Green-function sweep (paper 1 Fig 3, sigma = 1 nm, 36 steps, approach
and retract, tolerance 1e-10 nm), for N nodes = 50 ... 1600 (3200 with --full).

Error is relative to a Richardson extrapolation (order fitted from the two finest N) of
F_LJ(d = -5 nm) and max F_ex. Time is the sweep alone (operator + both branches, no output),
best of ``--repeat`` runs, with OPENBLAS_NUM_THREADS=1 (set below, before numpy loads).
Writes validation/results/benchmark_green.md.
"""
import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from femadh.contact import trace  # noqa: E402
from femadh.contact.forces import state_forces  # noqa: E402
from femadh.scene import build_problem  # noqa: E402
from validation.paper1 import scene  # noqa: E402


def sweep(n):
    sc = scene("paper1_fig3", n)
    t0 = time.perf_counter()
    p = build_problem(sc)
    a = trace(p, sc.d_values, branch="approach", tol=sc.tolerance)
    r = trace(p, sc.d_values[::-1], branch="retract", tol=sc.tolerance, start=a.states[-1])
    wall = time.perf_counter() - t0
    f = np.array([state_forces(p, s) for s in a.states])
    iters = sum(s.n_iter for s in a.states + r.states)
    return wall, f[-1, 0], f[:, 2].max(), iters, max(s.residual for s in a.states + r.states)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--full", action="store_true", help="include N = 3200 (minutes)")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args(argv)
    ns = [50, 100, 200, 400, 800, 1600] + ([3200] if args.full else [])
    rows = []
    for n in ns:
        runs = [sweep(n) for _ in range(args.repeat if n <= 400 else 1)]
        best = min(runs, key=lambda x: x[0])
        rows.append((n,) + best)
        print(f"N={n}: {best[0]:.3f} s", flush=True)
    vals = np.array([[r[2], r[3]] for r in rows])
    # Richardson: order from the three finest, extrapolate the finest pair
    p = np.log(np.abs(vals[-3] - vals[-2]) / np.abs(vals[-2] - vals[-1])) / np.log(2)
    ref = vals[-1] + (vals[-1] - vals[-2]) / (2.0**p - 1)
    err = np.abs(vals - ref) / np.abs(ref)
    lines = ["| N | wall time (s) | Newton iterations | max residual (m) | rel. error F_LJ(-5 nm) "
             "| rel. error max F_ex |", "|---|---|---|---|---|---|"]
    for r, e in zip(rows, err):
        lines.append(f"| {r[0]} | {r[1]:.3f} | {r[4]} | {r[5]:.1e} | {e[0]:.1e} | {e[1]:.1e} |")
    txt = "\n".join(lines)
    txt += (f"\n\nReference (Richardson, observed orders {p[0]:.2f} and {p[1]:.2f}): "
            f"F_LJ(-5 nm) = {ref[0]:.8e} N, max F_ex = {ref[1]:.8e} N.\n")
    print(txt)
    out = Path(__file__).resolve().parent / "results" / "benchmark_green.md"
    out.parent.mkdir(exist_ok=True)
    out.write_text("# Green-function sweep: accuracy vs time (validation/benchmark_green.py)\n\n"
                   + txt)


if __name__ == "__main__":
    main()
