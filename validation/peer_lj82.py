"""Peer benchmark: the Adhesion package's Lj82 law on a paraboloid of R = 100 z0, mu = 1 and 3.

``python -m validation.peer_lj82`` writes results/peer_lj82.md: at requested accuracies 3e-3
and 1e-4, the load-controlled pull-off, its error against a converged reference (spacing
0.0125 ell), the estimated error and the solve time. The law is
``Adhesion.Interactions.Lj82`` (Adhesion/Interactions/VdW82.py of
github.com/ContactEngineering/Adhesion), as :class:`femadh.laws.Lj82`. The peer's own numbers
are quoted from an earlier run of ours (the package is not installed here).
"""
import os
import statistics
import time
import warnings
from pathlib import Path

from femadh.laws import Lj82
from femadh.studies.regime import EDGE_GRADING, lj_sphere

RESULTS = Path(__file__).resolve().parent / "results"
Z0, W = 1e-9, 0.05          # z0 (m) and work of adhesion (J/m^2); R = 100 z0
REFERENCE_SPACING = 0.0125  # spacing / ell of the converged reference (its error ~1e-6)
GOALS = {(1.0, 3e-3): 0.020, (3.0, 3e-3): 0.25, (1.0, 1e-4): 0.3, (3.0, 1e-4): 1.5}
#: the benchmark's number: the accuracy is asked of the load-controlled pull-off (the other
#: quantities are reported by lj_sphere with their estimates, not judged)
JUDGED = ("pull_off",)
#: timings per row (the median is reported)
REPEATS = 21
PEER = {1.0: "36 s for +0.30 %, 187 s for -0.12 %", 3.0: "513 s for +2.7 %"}


def run():
    law = Lj82(W, Z0)
    rows = []
    for mu in (1.0, 3.0):
        ref = lj_sphere(mu, radius=100 * Z0, law=law, spacing=REFERENCE_SPACING)
        for acc in (3e-3, 1e-4):
            times, cpu = [], []
            for _ in range(REPEATS):
                t0, c0 = time.perf_counter(), time.process_time()
                p = lj_sphere(mu, radius=100 * Z0, law=law, accuracy=acc, judged=JUDGED)
                times.append(time.perf_counter() - t0)
                cpu.append(time.process_time() - c0)
            true = abs(p.pull_off - ref.pull_off) / ref.pull_off
            rows.append((mu, acc, p, ref, true, statistics.median(times),
                         statistics.median(cpu)))
    return rows


def main():
    warnings.simplefilter("ignore")
    RESULTS.mkdir(exist_ok=True)
    rows = run()
    load = os.getloadavg()[0]
    lines = ["| μ | requested | pull-off / πRw | reference | achieved error | within "
             "[request/30, request] | estimated error | effectivity | nodes | spacing / ell | "
             f"solve time (s, median of {REPEATS}) | cpu (s) | grading / ell | goal (s) | met |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for mu, acc, p, ref, true, dt, cpu in rows:
        est = p.relative_error("pull_off")
        goal = GOALS[(mu, acc)]
        band = acc / 30 <= true <= acc
        lines.append(f"| {mu:g} | {acc:g} | {p.pull_off:.6f} | {ref.pull_off:.6f} | {true:.2e} | "
                     f"{'yes' if band else 'no'} | "
                     f"{est:.2e} | {est / true if true else float('inf'):.2f} | {p.nodes} | "
                     f"{p.resolution.spacing:.3g} | {dt:.3f} | {cpu:.3f} | "
                     f"{p.resolution.edge_grading or EDGE_GRADING:.3g} | {goal:g} | "
                     f"{'yes' if dt <= goal else 'no'} |")
    t = {(mu, acc): dt for mu, acc, _, _, _, dt, _ in rows}
    ratios = "; ".join(f"μ = {mu:g}: 3e-3 / 1e-4 = {t[(mu, 3e-3)] / t[(mu, 1e-4)]:.2f}"
                       for mu in (1.0, 3.0))
    text = f"""# Peer problem: Lj82 paraboloid, R = 100 z0 (validation/peer_lj82.py)

Law: `Adhesion.Interactions.Lj82(w, z0)` = `VDW82(c_sr = w z0^8/3, hamaker = 16 pi w z0^2)`,
V(h) = w [(z0/h)^8/3 - 4 (z0/h)^2/3] (file Adhesion/Interactions/VdW82.py of
ContactEngineering/Adhesion), implemented as `femadh.laws.Lj82`; z0 = 1 nm, w = 0.05 J/m^2,
R = 100 z0, E* from the Tabor parameter. Approach-retract through both folds; the pull-off is
the load-controlled one (largest tension on the curve), and the accuracy is asked of it
(`judged=("pull_off",)`; the other quantities are reported with their estimates, not
judged). Reference: band spacing {REFERENCE_SPACING} ell. Times are wall times of
`lj_sphere(..., accuracy=...)` (median of {REPEATS}; each includes the coarser member used for
the estimate) on a shared 2-core machine, one BLAS thread, load average {load:.1f} when the
table was written (the goals are for a quiet machine); cpu is the process time of the same
calls (median), less sensitive to the load.

{chr(10).join(lines)}

On a loaded machine the times scale with the load; the ratio of a row's time to the 1e-4 row
of the same μ in this run is not: {ratios}. The counts are the numbers: every row is
traced with the grid following the contact edge (both μ are bistable): the contact branch by
Newton in its edge radius on a grid whose nodes move with the edge
(femadh.studies.smooth_sphere.trace_edge_point) down to the jump-out fold, the approach branch
by Newton in its centre gap from the jump-out separation to the jump-in fold, then the
contact branch up past the landing. Both branches keep their last LU factorisation for the
next solve within 1 % of its state (chord steps while it contracts the residual tenfold),
the march predicts each state by a parabola through the last three, and the states meet the
residual 1e-4 x accuracy x z0 (3e-16 m at 3e-3: no headline quantity moves by more than
3e-8 relative against 1e-19 m). 3e-3 starts at the edge family's cap 0.133 ell (its coarser
member at 0.167: beyond ~0.15 ell the pull-off leaves the spacing^2 line, 1.3e-3 off at 0.25
and 4.8e-3 at 0.3 for μ = 3) and, the accuracy being asked of the pull-off alone, with both
grids' grading length from the pull-off's measured error model C spacing^2 (2 ell / G)^1.5
at half the request (femadh.studies.regime.pull_off_grading): 0.77 ell at 3e-3 (2 ell at
1e-4, where the band spacing sets the error). The approach branch runs on the centre band
[0, 4 ell] also at μ = 1 (on the DMT side of bistability, where the arclength trace's band
is fixed over the contact edge's travel): 65 nodes instead of 82.

Before this change (main at ca75e7c; both members of one 3e-3 request, all LU
factorisations counted): μ = 1: 98 solves, 139 factorisations, 391 Newton iterations; μ = 3:
98, 172, 470. Now μ = 1: 90, 107, 211; μ = 3: 93, 128, 244. Back to back in one process
(interleaved, median of 21 each, load ~5, cpu time): μ = 1 29.4 -> 16.7 ms (0.54 x), μ = 3
33.1 -> 20.4 ms; the coordinator's quiet-machine 28 ms at μ = 1 before. Earlier (main at
449d272): μ = 1 54 ms quiet (99 nodes, achieved 3.0e-4).

Peer (ContactMechanics/Adhesion, our earlier run, not re-run here): μ = 1: {PEER[1.0]};
μ = 3: {PEER[3.0]}.
"""
    (RESULTS / "peer_lj82.md").write_text(text)
    print(text)


if __name__ == "__main__":
    import argparse

    # no arguments: --help says what it writes instead of running it
    argparse.ArgumentParser(prog="python -m validation.peer_lj82",
                            description=__doc__.split("\n\n")[0]).parse_args()
    main()
