"""What a contact run's figures cost to draw: each figure of the Fig 3 and Fig 4 scenes, in a
process that has imported matplotlib and warmed its fonts (as the figure worker,
femadh/runner/figures.py, has when a run hands it its result), the median of ``--repeat``
draws, with the number of artists the figure holds and the PNG's size.

    python -m validation.figure_pace [--repeat 5] [--out validation/results/figure_pace.md]

The runs are solved once (their default accuracy, with error estimates: the force curve's
inset states the largest adhesion with its error); only the drawing is timed. The six panels
are timed twice: drawn from nothing (as a script's run draws them) and "prepared", as the
figure worker draws them (:func:`femadh.io.plots.prepare` laid the figure out while the run
solved; its own time is stated beside). The load of the
machine at the start is in the table (2 cores shared: compare medians taken at one load).
"""
import argparse
import os
from pathlib import Path
import statistics
import tempfile
import time

SCENES = ("paper1_fig3", "paper1_fig4")


def _artists(fn, res, path):
    """The number of artists of the figure ``fn`` draws (counted as it is saved)."""
    from femadh.io import plots

    counted = []
    real = plots._save

    def count(fig, p, dpi=100):
        counted.append(len(fig.findobj()))
        real(fig, p, dpi)
    plots._save = count
    try:
        fn(res, path)
    finally:
        plots._save = real
    return counted[0] if counted else None


def _ticks_made(fn, *args):
    """How many matplotlib Tick objects ``fn(*args)`` makes."""
    import matplotlib.axis as maxis

    made, real = [0], maxis.Tick.__init__

    def count(self, *a, **k):
        made[0] += 1
        real(self, *a, **k)
    maxis.Tick.__init__ = count
    try:
        fn(*args)
    finally:
        maxis.Tick.__init__ = real
    return made[0]


def measure(repeat=5, keep=None):
    """Rows (scene, figure, median wall s, min s, max s, median CPU s, artists, Tick objects
    made while drawing, PNG kB); ``keep``: a folder to copy the PNGs into (to look at them).
    The six panels drawn from nothing and prepared alternate, draw by draw (a machine whose
    load drifts shifts both alike)."""
    import femadh
    from femadh.io import plots

    root = Path(__file__).resolve().parents[1]
    plots.warm_up()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name in SCENES:
            res = femadh.run(femadh.load_scene(root / "validation" / "scenes" / f"{name}.toml"),
                             progress=False)
            draw = {"force_curve.png": plots.force_curve,
                    "profiles_and_forces.png": plots.paper1_panels}
            for fig in plots.figure_names(res):
                fn = draw[fig]
                path = Path(tmp) / f"{name}-{fig}"
                n = _artists(fn, res, path)          # (also the first, untimed draw)
                variants = {fig: None}
                if fig == "profiles_and_forces.png":
                    # as the figure worker draws it: laid out (plots.prepare) while the run
                    # solved; only the rest is left when the result arrives
                    variants[f"{fig}, prepared"] = plots.prepare
                times = {v: ([], [], []) for v in variants}
                for _ in range(repeat):
                    for v, prep in variants.items():
                        ts, cpu, pre = times[v]
                        if prep is not None:
                            c0 = time.process_time()
                            prep()
                            pre.append(time.process_time() - c0)
                        t0, c0 = time.perf_counter(), time.process_time()
                        fn(res, path)
                        ts.append(time.perf_counter() - t0)
                        cpu.append(time.process_time() - c0)
                for v, prep in variants.items():
                    ts, cpu, pre = times[v]
                    if prep is not None:
                        prep()
                    ticks = _ticks_made(fn, res, path)
                    label = v + (f" (prepare(): {statistics.median(pre):.3f} s CPU before)"
                                 if pre else "")
                    rows.append((name, label, statistics.median(ts), min(ts), max(ts),
                                 statistics.median(cpu), n, ticks,
                                 path.stat().st_size / 1024))
                if keep:
                    Path(keep).mkdir(parents=True, exist_ok=True)
                    (Path(keep) / path.name).write_bytes(path.read_bytes())
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--out", default=None, help="write the markdown table here")
    ap.add_argument("--keep", default=None, help="copy the PNGs into this folder")
    a = ap.parse_args(argv)
    load = os.getloadavg()[0]
    rows = measure(a.repeat, a.keep)
    lines = [f"Figures drawn in a warmed process, median of {a.repeat} draws "
             f"(load average at start {load:.2f} on 2 cores).", "",
             "| scene | figure | median (s) | min (s) | max (s) | CPU median (s) | artists "
             "| ticks made drawing | PNG (kB) |", "|---|---|---|---|---|---|---|---|---|"]
    lines += [f"| {s} | {f} | {m:.3f} | {lo:.3f} | {hi:.3f} | {c:.3f} | {n} | {k} | {kb:.0f} |"
              for s, f, m, lo, hi, c, n, k, kb in rows]
    text = "\n".join(lines) + "\n"
    print(text)
    if a.out:
        Path(a.out).write_text(text)


if __name__ == "__main__":
    main()
