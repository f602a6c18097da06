"""The sigma-gap corrector's pace: paper 1 Fig 3 (sigma = 1 nm) and Fig 4 (sigma = 0.5 nm),
the complementarity model on the adaptive grid, run end to end (sweeps, error-estimate
members, peak refinement) at their defaults and at tighter accuracies, with the work the
correctors did counted beside the time - this checkout against an earlier one.

Each row is one run in a fresh process of ``femadh.runner.run.run`` (no output folder, no
figures) with counters wrapped around the package's own functions:

- solves: calls of ``solve_complementarity`` (continuation trial steps, landings, the peak's
  fresh states, every member's);
- iterations: their Newton iterations (``State.n_iter``);
- Krylov: the GMRES iterations of the corrector's Newton steps and tangents (the
  iterations ``linalg.gmres`` reports, as imported by ``contact.complementarity``);
- LU / Cholesky: every dense factorisation (``scipy.linalg.lu_factor``, LAPACK ``dpotrf``:
  the Newton systems, the Krylov preconditioner and the stability tests alike);
- cpu: the process's user + system seconds, solve and estimate: the run's own timings (wall);
- nodes: the final member's; accuracy met or not; the largest adhesion with its estimate.

``python -m validation.newton_pace [--before PATH] [--cases fig3,fig4,fig4@1e-3,...]
[--time-limit S]`` writes validation/results/newton_pace.md; ``--before`` is a checkout of an
earlier femadh (e.g. ``git archive <commit> | tar -x -C DIR``), run on the same scenes. A
run that reaches ``--time-limit`` is reported as such (its counts are those up to then).
"""
import argparse
import json
import os
from pathlib import Path
import resource
import subprocess
import sys
import time

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
RESULTS = HERE / "results"
SCENES = {"fig3": "paper1_fig3.toml", "fig4": "paper1_fig4.toml"}
DEFAULT_CASES = ("fig3", "fig3@1e-4", "fig4", "fig4@1e-3", "fig4@1e-4")


def _child(scene_file, accuracy, time_limit):
    """Run one case in this process with the counters on; print one json line."""
    import collections

    import scipy.linalg as sla
    from scipy.linalg import lapack

    counts = collections.Counter()

    def counted(fn, key):
        def wrapper(*a, **k):
            counts[key] += 1
            return fn(*a, **k)
        return wrapper
    sla.lu_factor = counted(sla.lu_factor, "lu")
    lapack.dpotrf = counted(lapack.dpotrf, "cholesky")
    import femadh.contact.complementarity as cm
    import femadh.contact.landing as landing
    import femadh.contact.stepping as stepping
    real = cm.solve_complementarity

    def solve(*a, **k):
        st = real(*a, **k)
        counts["solves"] += 1
        counts["iterations"] += st.n_iter
        return st
    for mod in (cm, stepping, landing):
        mod.solve_complementarity = solve
    real_gmres = getattr(cm, "gmres", None)
    if real_gmres is not None:
        def gmres(*a, **k):
            out = real_gmres(*a, **k)
            counts["krylov"] += out[1]
            return out
        cm.gmres = gmres
    try:
        from femadh.runner.run import run
    except ImportError:                 # an earlier femadh (--before): run() lived here
        from femadh.runner.contact import run
    from femadh.scene import apply_overrides, load_scene, scene_from_dict

    scene = load_scene(scene_file)
    if accuracy is not None:
        raw = apply_overrides(scene.raw, {})
        raw.setdefault("solver", {})["accuracy"] = accuracy
        scene = scene_from_dict(raw, scene.path, bare_numbers=True)
    t0, r0 = time.perf_counter(), resource.getrusage(resource.RUSAGE_SELF)
    res = run(scene, None, figures=False, progress=False, time_limit=time_limit)
    r1 = resource.getrusage(resource.RUSAGE_SELF)
    hl, acc = res.headline, getattr(res, "accuracy", None) or {}
    print(json.dumps({
        "status": res.status, "wall_s": time.perf_counter() - t0,
        "cpu_s": (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime),
        "solve_s": res.timings.get("solve_s"), "estimate_s": res.timings.get("estimate_s"),
        "nodes": acc.get("nodes"), "met": acc.get("met"), "runs": len(acc.get("steps", [])),
        "max_adhesion_N": hl.get("max_adhesion_N"),
        "max_adhesion_N_error": hl.get("max_adhesion_N_error"),
        "jump_in_d_m": hl.get("jump_in_d_m"), "jump_out_d_m": hl.get("jump_out_d_m"),
        **counts}))


def run_case(code, case, time_limit):
    """One case (``fig4@1e-3``) with the femadh at ``code`` in a fresh process."""
    name, _, acc = case.partition("@")
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env.update(OPENBLAS_NUM_THREADS="1", PYTHONPATH=str(code))
    args = [sys.executable, str(Path(__file__).resolve()), "--child",
            str(HERE / "scenes" / SCENES[name]), acc or "-", str(time_limit)]
    p = subprocess.run(args, capture_output=True, text=True, env=env, cwd=str(code))
    line = [x for x in p.stdout.splitlines() if x.startswith("{")]
    if p.returncode != 0 or not line:
        return {"status": f"error: {p.stderr.strip().splitlines()[-1] if p.stderr else p.returncode}"}
    return json.loads(line[-1])


def _load():
    try:
        return os.getloadavg()[0]
    except OSError:
        return float("nan")


def _fmt(x, spec):
    return "-" if x is None else format(x, spec)


def table(rows):
    head = ("| case | code | status | nodes (runs) | max adhesion (µN) | solves | iterations "
            "| Krylov | LU | Cholesky | cpu (s) | wall (s): solve + estimate | load |\n"
            "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n")
    out = []
    for case, label, r, load in rows:
        F, e = r.get("max_adhesion_N"), r.get("max_adhesion_N_error")
        adh = "-" if F is None else f"{F * 1e6:.5g} ± {e * 1e6:.2g}" if e else f"{F * 1e6:.5g}"
        met = "" if r.get("met") is None else (" met" if r["met"] else " not met")
        out.append(f"| {case} | {label} | {r.get('status')}{met} | {_fmt(r.get('nodes'), '')} "
                   f"({_fmt(r.get('runs'), '')}) | {adh} | {_fmt(r.get('solves'), '')} | "
                   f"{_fmt(r.get('iterations'), '')} | {_fmt(r.get('krylov'), '')} | "
                   f"{_fmt(r.get('lu'), '')} | "
                   f"{_fmt(r.get('cholesky'), '')} | {_fmt(r.get('cpu_s'), '.2f')} | "
                   f"{_fmt(r.get('wall_s'), '.2f')}: {_fmt(r.get('solve_s'), '.2f')} + "
                   f"{_fmt(r.get('estimate_s'), '.2f')} | {load:.1f} |")
    return head + "\n".join(out) + "\n"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--before", help="a checkout of an earlier femadh to run beside this one")
    ap.add_argument("--cases", default=",".join(DEFAULT_CASES),
                    help="comma-separated: fig3, fig4, with @accuracy (default: %(default)s)")
    ap.add_argument("--time-limit", type=float, default=600.0,
                    help="seconds one run may take before it stops (default %(default)s)")
    ap.add_argument("--child", nargs=3, help=argparse.SUPPRESS)
    ap.add_argument("--out", default=str(RESULTS / "newton_pace.md"))
    args = ap.parse_args(argv)
    if args.child:
        scene, acc, limit = args.child
        _child(scene, None if acc == "-" else float(acc), float(limit))
        return 0
    codes = [("this", ROOT)] + ([("before", Path(args.before).resolve())] if args.before
                                else [])
    rows = []
    for case in args.cases.split(","):
        for label, code in codes:
            load = _load()
            r = run_case(code, case, args.time_limit)
            rows.append((case, label, r, load))
            print(case, label, json.dumps(r), flush=True)
    text = ("# The sigma-gap corrector's pace\n\n"
            "`python -m validation.newton_pace"
            + (" --before PATH" if args.before else "") + "`: each row one run end to end "
            "(sweeps, the estimate's members, the peak's refinement) in a fresh process, one "
            "BLAS thread; counts over the whole run (see the script's docstring). The load "
            "is the machine's 1-minute load average when the row started (2 cores): "
            "wall times above a load of 2 are inflated, counts are not.\n\n" + table(rows))
    out = Path(args.out)
    if out.exists() and "\n## Notes" in out.read_text():
        # the hand-written reading of an earlier table is kept below the new one
        text += out.read_text()[out.read_text().index("\n## Notes"):]
    out.write_text(text)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
