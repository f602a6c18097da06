"""Peer benchmark: the Adhesion package's Lj82 law on a paraboloid of R = 100 z0, mu = 1 and 3.

``python -m validation.peer_lj82`` writes results/peer_lj82.md: at requested accuracies 3e-3
and 1e-4, the load-controlled pull-off, its error against a converged reference (band spacing
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
from femadh.studies.regime import lj_sphere

RESULTS = Path(__file__).resolve().parent / "results"
Z0, W = 1e-9, 0.05          # z0 (m) and work of adhesion (J/m^2); R = 100 z0
REFERENCE_SPACING = 0.0125  # band spacing / ell of the converged reference
GOALS = {(1.0, 3e-3): 0.020, (3.0, 3e-3): 0.25, (1.0, 1e-4): 0.3, (3.0, 1e-4): 1.5}
#: the benchmark's number: the accuracy is asked of the load-controlled pull-off (the other
#: quantities are reported by lj_sphere with their estimates, not judged)
JUDGED = ("pull_off",)
#: timings per row (the median is reported)
REPEATS = 3
PEER = {1.0: "36 s for +0.30 %, 187 s for -0.12 %", 3.0: "513 s for +2.7 %"}


def run():
    law = Lj82(W, Z0)
    rows = []
    for mu in (1.0, 3.0):
        ref = lj_sphere(mu, radius=100 * Z0, law=law, spacing=REFERENCE_SPACING)
        for acc in (3e-3, 1e-4):
            times = []
            for _ in range(REPEATS):
                t0 = time.perf_counter()
                p = lj_sphere(mu, radius=100 * Z0, law=law, accuracy=acc, judged=JUDGED)
                times.append(time.perf_counter() - t0)
            true = abs(p.pull_off - ref.pull_off) / ref.pull_off
            rows.append((mu, acc, p, ref, true, statistics.median(times)))
    return rows


def main():
    warnings.simplefilter("ignore")
    RESULTS.mkdir(exist_ok=True)
    rows = run()
    load = os.getloadavg()[0]
    lines = ["| μ | requested | pull-off / πRw | reference | achieved error | within "
             "[request/30, request] | estimated error | effectivity | nodes | spacing / ell | "
             "solve time (s, median of 3) | goal (s) | met |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for mu, acc, p, ref, true, dt in rows:
        est = p.relative_error("pull_off")
        goal = GOALS[(mu, acc)]
        band = acc / 30 <= true <= acc
        lines.append(f"| {mu:g} | {acc:g} | {p.pull_off:.6f} | {ref.pull_off:.6f} | {true:.2e} | "
                     f"{'yes' if band else 'no'} | "
                     f"{est:.2e} | {est / true if true else float('inf'):.2f} | {p.nodes} | "
                     f"{p.resolution.spacing:.3g} | {dt:.3f} | {goal:g} | "
                     f"{'yes' if dt <= goal else 'no'} |")
    t = {(mu, acc): dt for mu, acc, _, _, _, dt in rows}
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
table was written (the goals are for a quiet machine).

{chr(10).join(lines)}

On a loaded machine the times scale with the load; the ratio of a row's time to the 1e-4 row
of the same μ in this run is not: {ratios}. The 1e-4 rows' algorithm is unchanged by the
pull-off-only request (same spacing and nodes as before), and took 0.224 s (μ = 1) and 1.027 s
(μ = 3) on a quiet machine (the earlier table): the 3e-3 rows at these ratios are the
estimates for a quiet machine until it is re-measured there.

Peer (ContactMechanics/Adhesion, our earlier run, not re-run here): μ = 1: {PEER[1.0]};
μ = 3: {PEER[3.0]}. femadh before the lean solver and the lattice cap (same table, same
machine): μ = 1: 0.238 s (3e-3), 0.339 s (1e-4); μ = 3: 1.784 s (3e-3), 7.169 s (1e-4).
Before the accuracy was asked of the pull-off alone, every request on the JKR side (μ = 3)
started at 0.05 ell: a coarser member above 0.075 elastocohesive lengths sees lattice wiggles
at the flat jump-out fold (the fixed-grip pull-off there is 1.7e-3 off at 0.133 ell, 1.9 %
at 0.2), so 3e-3 was over-resolved (1.7e-5 achieved, 374 nodes, 1.02 s on a quiet machine)
and cost as much as 1e-4. The largest tension is a smooth maximum of the curve: the lattice
cap does not bound its spacing, and 3e-3 starts at 0.133 ell (the cap of the family's
asymptotic range, MAX_SPACING / 1.5). Its estimate comes from a member at 0.2 ell that is
not yet asymptotic (error ratio 6.0 for a spacing ratio 1.5, where order 2 gives 2.25):
effectivity ~4, conservative.
"""
    (RESULTS / "peer_lj82.md").write_text(text)
    print(text)


if __name__ == "__main__":
    main()
