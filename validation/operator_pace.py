"""The Green operator's own CPU inside the goal-2 runs (issue 21): every GreenOperator a run
builds, its assembly (the compliance C) and its inversion (K = C^-1), in CPU seconds of this
process, beside the whole run's CPU.

    python -m validation.operator_pace [--repeat 3]

Runs paper1_fig3 at [solver] accuracy = 1e-4 and paper1_fig4 at 1e-3 (the bundled scenes
with that accuracy, outputs in a temporary folder, figures off) ``--repeat`` times each,
alternating, and prints per run: operators built (nodes), assembly, inversion, run CPU and
the max adhesion; then the medians (results: validation/results/greenop.md). Run it from
the root of the tree whose femadh is to be timed (one BLAS thread: set below before numpy
loads, unless OPENBLAS_NUM_THREADS is already set); compare trees by running it in each,
alternating.
"""
import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
from pathlib import Path  # noqa: E402
import statistics  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402

import femadh  # noqa: E402
from femadh.elastic import green, operator  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
RUNS = (("paper1_fig3", 1e-4), ("paper1_fig4", 1e-3))


def _positive(text):
    n = int(text)
    if n < 1:
        raise argparse.ArgumentTypeError(f"{text} is not a positive count")
    return n


def _instrument(log):
    """Wrap GreenOperator's assembly and SurfaceOperator's inversion to add their CPU to
    ``log`` (dict with "nodes", "assembly", "inversion"); returns the undo."""
    init, stiff = green.GreenOperator.__init__, operator.SurfaceOperator.stiffness

    def timed_init(self, grid, e_star):
        t = time.process_time()
        init(self, grid, e_star)
        log["assembly"] += time.process_time() - t
        log["nodes"].append(grid.n)

    def timed_stiffness(self):
        fresh = self._stiffness is None
        t = time.process_time()
        K = stiff.fget(self)
        if fresh and isinstance(self, green.GreenOperator):
            log["inversion"] += time.process_time() - t
        return K
    green.GreenOperator.__init__ = timed_init
    operator.SurfaceOperator.stiffness = property(timed_stiffness)

    def undo():
        green.GreenOperator.__init__ = init
        operator.SurfaceOperator.stiffness = stiff
    return undo


def one(name, accuracy, tmp):
    """(log, run CPU (s), max adhesion (N)) of one run of scene ``name`` at ``accuracy``."""
    scene = femadh.load_scene(ROOT / "validation" / "scenes" / f"{name}.toml").replace(
        {"solver.accuracy": accuracy})
    log = {"nodes": [], "assembly": 0.0, "inversion": 0.0}
    undo = _instrument(log)
    try:
        t = time.process_time()
        res = femadh.run(scene, Path(tmp) / f"out-{name}", figures=False, overwrite=True)
        cpu = time.process_time() - t
    finally:
        undo()
    return log, cpu, res.headline["max_adhesion_N"]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=_positive, default=3, help="runs of each scene (>= 1)")
    args = ap.parse_args(argv)
    print(f"femadh from {Path(femadh.__file__).parent}; load {os.getloadavg()[0]:.2f}")
    rows = {name: [] for name, _ in RUNS}
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(args.repeat):
            for name, acc in RUNS:
                log, cpu, fmax = one(name, acc, tmp)
                rows[name].append((log["assembly"], log["inversion"], cpu))
                print(f"{name} at {acc:g}: operators {log['nodes']} assembly "
                      f"{log['assembly']:.3f} s inversion {log['inversion']:.3f} s run CPU "
                      f"{cpu:.3f} s max adhesion {fmax!r} N", flush=True)
    for name, acc in RUNS:
        a, i, c = (statistics.median(x) for x in zip(*rows[name]))
        print(f"median {name} at {acc:g}: assembly {a:.3f} s inversion {i:.3f} s operator "
              f"{a + i:.3f} s run CPU {c:.3f} s")
    print(f"load {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
