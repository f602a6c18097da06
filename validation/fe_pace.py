"""FE at the Green function's pace: paper 1 Fig 3 (sigma = 1 nm, N = 200 uniform nodes,
approach and retract, error estimates included) run as a user runs it, FE against the Green
function on the same scene, with the parts each run records and the headline beside them.

Rows (each the median of ``--repeat`` runs of ``femadh run SCENE --out DIR --overwrite
--quiet``, process start to exit):

- Green: ``paper1_fig3_fe.toml`` with ``[solver] method = "green"``;
- FE, operator cache cold: a fresh FEMADH_OPERATOR_CACHE each run (the mesh cache warm, as
  after ``femadh mesh`` or any earlier run of the scene);
- FE, operator cache warm: the condensed operator read from the cache;
- FE with ``[output] vtk = true``: every state's volume and surface VTK streamed;
- ``femadh render`` of one state of a run without VTK (the state exported on demand);
- optionally (``--before PATH``: a checkout of an earlier femadh) the same FE scene there.

The FE and Green headline numbers must agree within their estimated errors (checked, and the
table says so). ``python -m validation.fe_pace [--repeat 3] [--before PATH]`` writes
validation/results/fe_pace.md.
"""
import argparse
import json
import os
from pathlib import Path
import statistics
import subprocess
import sys
import tempfile
import time

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
RESULTS = HERE / "results"
FE_SCENE = HERE / "scenes" / "paper1_fig3_fe.toml"


def _scene(tmp, name, method="fe", vtk=False):
    text = FE_SCENE.read_text()
    if method == "green":
        text = text.replace('method = "fe"', 'method = "green"')
    if vtk:
        text += "vtk = true\n"            # [output] is the file's last table
    path = tmp / f"{name}.toml"
    path.write_text(text)
    return path


def _env(**extra):
    env = {k: v for k, v in os.environ.items()
           if k not in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS",
                        "FEMADH_MESH_PATH")}
    env.update(extra)
    return env


def timed(args, cwd=ROOT, env=None):
    t0 = time.perf_counter()
    p = subprocess.run([sys.executable, "-m", "femadh", *args], capture_output=True, text=True,
                       cwd=cwd, env=env or _env())
    wall = time.perf_counter() - t0
    if p.returncode != 0:
        raise RuntimeError(f"femadh {' '.join(args)}: {p.stderr.strip()}")
    return wall


def run_once(scene, out, *, cold=False, cwd=ROOT, flags=()):
    """One timed run: (wall time, its summary)."""
    extra = {}
    if cold:
        extra["FEMADH_OPERATOR_CACHE"] = tempfile.mkdtemp(prefix="femadh-cold-")
    elif "FEMADH_OPERATOR_CACHE" in os.environ:
        extra["FEMADH_OPERATOR_CACHE"] = os.environ["FEMADH_OPERATOR_CACHE"]
    w = timed(["run", str(scene), "--out", str(out), "--overwrite", "--quiet", *flags],
              cwd=cwd, env=_env(**extra))
    return w, json.loads((out / "summary.json").read_text())


def measure_rounds(configs, repeat):
    """Every configuration once per round, ``repeat`` rounds after one warm-up round: on a
    shared machine the load drifts over minutes, so each configuration is compared with the
    first (the Green run) of the same round. Returns per configuration the median wall time,
    the median of each recorded part, the median ratio to the first configuration's wall
    time and run time in the same round, and the last summary."""
    walls = {k: [] for k in configs}
    parts = {k: {} for k in configs}
    ratios = {k: [] for k in configs}
    run_ratios = {k: [] for k in configs}
    summ = {}
    first = next(iter(configs))
    for rnd in range(repeat + 1):
        this = {}
        for k, (scene, out, kw) in configs.items():
            this[k] = run_once(scene, out, **kw)
        if rnd == 0:
            continue                       # the warm-up round fills the caches
        for k, (w, sm) in this.items():
            walls[k].append(w)
            summ[k] = sm
            for name, v in sm.get("timings_s", {}).items():
                parts[k].setdefault(name, []).append(v)
            ratios[k].append(w / this[first][0])
            run_ratios[k].append(sm["timings_s"]["total_s"]
                                 / this[first][1]["timings_s"]["total_s"])
    med = statistics.median
    return {k: (med(walls[k]), {n: med(v) for n, v in parts[k].items()}, med(ratios[k]),
                med(run_ratios[k]), summ[k]) for k in configs}


def _head(summ):
    hl = summ["headline"]
    return hl["max_adhesion_N"], hl.get("max_adhesion_N_error", float("nan"))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--before", help="a checkout of an earlier femadh to time the FE scene in")
    args = ap.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix="femadh-pace-"))
    os.environ.setdefault("FEMADH_OPERATOR_CACHE", str(tmp / "operators"))
    load0 = os.getloadavg()[0]
    green = _scene(tmp, "green", "green")
    fe = _scene(tmp, "fe")
    fe_vtk = _scene(tmp, "fe_vtk", vtk=True)
    configs = {
        "Green (same scene, method = green)": (green, tmp / "green", {}),
        "FE, operator cache cold": (fe, tmp / "fe_cold", {"cold": True}),
        "FE, operator cache warm (the default after one run)": (fe, tmp / "fe", {}),
        "Green, `--no-figures`": (green, tmp / "green_nf", {"flags": ("--no-figures",)}),
        "FE, warm, `--no-figures`": (fe, tmp / "fe_nf", {"flags": ("--no-figures",)}),
        "FE, warm, `[output] vtk = true` (every state's VTK)": (fe_vtk, tmp / "fe_vtk", {}),
    }
    if args.before:
        configs[f"FE before this change ({Path(args.before).name}: VTK of every state, zlib, "
                "no operator cache)"] = (FE_SCENE, tmp / "before", {"cwd": Path(args.before)})
    measured = measure_rounds(configs, args.repeat)
    lines = []
    for label, (wall, parts, ratio, run_ratio, summ) in measured.items():
        F, e = _head(summ)
        fmt = (lambda k: f"{parts[k]:.2f}" if k in parts else "-")
        lines.append(f"| {label} | {wall:.2f} | {ratio:.2f}x | {fmt('total_s')} | "
                     f"{run_ratio:.2f}x | {fmt('operator_s')} | {fmt('solve_s')} | "
                     f"{fmt('estimate_s')} | {fmt('figures_s')} | {F * 1e6:.4f} ± "
                     f"{e * 1e6:.2g} µN |")
        print(lines[-1], flush=True)
    results = {k: v[4] for k, v in measured.items()}
    g_summ = results["Green (same scene, method = green)"]
    # render of one state of a run without VTK: its export on demand
    run_dir = tmp / "fe"
    timed(["run", str(fe), "--out", str(run_dir), "--overwrite", "--quiet"],
          env=_env(FEMADH_OPERATOR_CACHE=os.environ["FEMADH_OPERATOR_CACHE"]))
    renders = []
    for _ in range(args.repeat):
        for f in [*run_dir.glob("vtk/*"), *run_dir.glob("*.pvd")]:
            f.unlink()                     # each render exports its state afresh
        renders.append(timed(["render", str(run_dir), "--png", str(tmp / "r.png")],
                             env=_env(FEMADH_OPERATOR_CACHE=os.environ["FEMADH_OPERATOR_CACHE"])))
    # accuracy: FE and Green headline within their estimates
    Fg, eg = _head(g_summ)
    Ff, ef = _head(results["FE, operator cache warm (the default after one run)"])
    agree = abs(Ff - Fg) <= eg + ef
    text = [
        "# FE at the Green function's pace (validation/fe_pace.py)", "",
        f"Paper 1 Fig 3 (`validation/scenes/paper1_fig3_fe.toml`: sigma = 1 nm, N = 200 "
        "uniform nodes, 36 separations each way, error estimates on), `femadh run SCENE --out "
        "DIR --overwrite --quiet`, process start to exit, median of "
        f"{args.repeat} rounds (every row once per round, after a warm-up round); one BLAS "
        "thread; 2-core machine shared with other jobs (1-minute load "
        f"{load0:.2f} at the start, {os.getloadavg()[0]:.2f} at the end). Ratio: the median "
        "over rounds of the row's wall time over the Green run's in the same round (the load "
        "drifts over minutes); run ratio: the same for the run alone (summary.json "
        "`total_s`: operator, sweeps with their csv rows, estimates; no interpreter start, "
        "no figures). The FE run's estimate includes its FE-vs-Green run on the same "
        "nodes.", "",
        "| run | wall (s) | ratio | run (s) | run ratio | operator | solve | estimates | "
        "figures | max adhesion ± estimated error |",
        "|---|---|---|---|---|---|---|---|---|---|", *lines, "",
        f"`femadh render RUN_DIR` on the FE run (no VTK written by the run: the state is "
        f"exported from fields.csv, the body factorised once): {statistics.median(renders):.2f}"
        " s wall.", "",
        f"Accuracy: FE {Ff * 1e6:.4f} ± {ef * 1e6:.2g} µN, Green {Fg * 1e6:.4f} ± "
        f"{eg * 1e6:.2g} µN: |difference| = {abs(Ff - Fg) * 1e6:.2g} µN "
        f"{'within' if agree else 'OUTSIDE'} the sum of their estimates "
        f"({(ef + eg) * 1e6:.2g} µN).", "",
        "Where an FE run's time went before (main at aac63f4, this scene, profiled): writing "
        "a zlib-compressed VTU of every state 5.6 s of 9.8 s under profiling (zlib alone "
        "3.6 s, 80 ms of a state's ~95 ms), the operator 1.2-2.0 s (mesh 0.07, assembly 0.6, "
        "factorisation 0.24, condensation 1.0 s in one measurement). Per state, the volume field "
        "costs 7 ms (full-field solve) + 7 ms (stress projection) + 8 ms (uncompressed "
        "write, 1.8 MB) + 2 ms (fsync); setting the body up for fields costs ~1.2 s "
        "(mesh, assembly, factorisation, projector). Hence: the condensed operator is cached "
        "by content, the body is built only when fields are asked for, and a run writes VTK "
        "only with `[output] vtk = true` (uncompressed) - `femadh render` exports the states "
        "a user asks for.", ""]
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "fe_pace.md").write_text("\n".join(text))
    print("\n".join(text))
    if not agree:
        sys.exit("FE and Green disagree beyond their estimates")


if __name__ == "__main__":
    main()
