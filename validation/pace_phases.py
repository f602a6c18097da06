"""Where a contact run's numerical work goes, phase by phase: every corrector solve, Newton
iteration, LU and Cholesky factorisation (with its size: flops n^3/3 for potrf, 2n^3/3 for
getrf) and the wall time of each phase, attributed to the stack of phases it ran under
(trial k's sweep, its landings and next-node landings, the peak search, the estimate's
members: their states, peak searches, folds, zero-force radii; operator builds).

``python -m validation.pace_phases [--scene paper1_fig4]
[--accuracy 1e-3] [--out] [--json OUT]`` prints one table; one in-process ``femadh.run`` (no figures;
with ``--out`` into a temporary folder) with counting wrappers around the package's own functions, so its
counts are exact and independent of the machine's load (the wrappers add ~1-2 % of time).
"""
import argparse
import collections
import json
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

#: (module, attribute, label): the phases a count is attributed to (the innermost first)
PHASES = [
    ("femadh.runner.contact", "_run", "run"),
    ("femadh.runner.tracing", "trace_steps", "sweep"),
    ("femadh.contact.stepping", "trace_steps", "trace"),
    ("femadh.runner.estimates", "refine_peak", "peak"),
    ("femadh.runner.estimates", "estimate_errors", "estimate"),
    ("femadh.runner.members", "ReducedMember.judged", "member"),
    ("femadh.runner.members", "ReducedMember.rest", "member"),
    ("femadh.runner.members", "deepest_locked", "locked"),
    ("femadh.runner.members", "_peak", "m.peak"),
    ("femadh.runner.members", "_folds", "m.folds"),
    ("femadh.runner.members", "_zero_force_radius", "m.zero"),
    ("femadh.runner.members", "_Member.state", "m.state"),
    ("femadh.contact.landing", "land", "land"),
    ("femadh.contact.landing", "land_next_node", "next_node"),
    ("femadh.contact.snap", "decide", "decide"),
    ("femadh.elastic.green", "GreenOperator.__init__", "operator"),
    ("femadh.io.writers", "ContactWriter.write_state", "write"),
]

STACK = []
COUNTS = collections.defaultdict(collections.Counter)
TIMES = collections.defaultdict(float)


def _key():
    return "/".join(STACK) or "-"


RUNS = collections.Counter()


def _wrap_phase(fn, label):
    def wrapper(*a, **k):
        name = label
        if label == "run":              # trial k of an adaptive run
            RUNS[label] += 1
            name = f"run{RUNS[label]}"
        elif label == "trace":          # a branch's sweep
            name = k.get("branch", "trace")
        STACK.append(name)
        key = _key()
        t0 = time.perf_counter()
        try:
            return fn(*a, **k)
        finally:
            TIMES[key] += time.perf_counter() - t0
            COUNTS[key]["calls"] += 1
            STACK.pop()
    wrapper.__wrapped__ = fn
    return wrapper


def _replace_everywhere(orig, new):
    for mod in list(sys.modules.values()):
        if mod is None or not getattr(mod, "__name__", "").startswith("femadh"):
            continue
        for name, val in list(vars(mod).items()):
            if val is orig:
                setattr(mod, name, new)


def install():
    import importlib

    import numpy as np
    from scipy.linalg import lapack

    import femadh.runner.run  # noqa: F401 (imports the runner's modules)
    for m in ("femadh.runner.members", "femadh.runner.estimates", "femadh.runner.peak",
              "femadh.contact.landing", "femadh.contact.snap", "femadh.contact.stepping",
              "femadh.elastic.green", "femadh.io.writers", "femadh.runner.tracing",
              "femadh.runner.contact", "femadh.contact.stability",
              "femadh.contact.complementarity", "femadh.contact.linalg"):
        importlib.import_module(m)
    for modname, attr, label in PHASES:
        mod = sys.modules[modname]
        if "." in attr:
            cls, meth = attr.split(".")
            c = getattr(mod, cls)
            setattr(c, meth, _wrap_phase(getattr(c, meth), label))
        else:
            orig = getattr(mod, attr)
            _replace_everywhere(orig, _wrap_phase(orig, label))

    import femadh.contact.complementarity as cm
    import femadh.contact.linalg as la
    real_solve = cm.solve_complementarity

    def solve(*a, **k):
        t0 = time.perf_counter()
        st = real_solve(*a, **k)
        c = COUNTS[_key()]
        c["solves"] += 1
        c["newton"] += st.n_iter
        c["solve_ms"] += 1e3 * (time.perf_counter() - t0)
        return st
    _replace_everywhere(real_solve, solve)

    def counted(fn, name, flop):
        def wrapper(a, *args, **kw):
            c = COUNTS[_key()]
            n = np.shape(a)[0] if np.ndim(a) else 0
            c[name] += 1
            c[name + "_gflop"] += flop * n ** 3 / 1e9
            return fn(a, *args, **kw)
        return wrapper
    la._GETRF = counted(la._GETRF, "lu", 2 / 3)
    la._POTRF = counted(la._POTRF, "chol", 1 / 3)
    lapack.dpotrf = counted(lapack.dpotrf, "chol", 1 / 3)
    real_gmres = cm.gmres

    def gmres(*a, **k):
        out = real_gmres(*a, **k)
        COUNTS[_key()]["krylov"] += out[1]
        return out
    cm.gmres = gmres


def run(scene_name, accuracy, out=None):
    """One in-process run of the bundled scene ``scene_name`` at ``accuracy`` (into ``out``
    without figures, or writing nothing); returns (result, wall seconds)."""
    import tempfile

    from femadh.runner.run import run as femadh_run
    from validation.benchmark import scene_at_accuracy

    with tempfile.TemporaryDirectory() as tmp:
        path = scene_at_accuracy(scene_name, accuracy, tmp)
        t0 = time.perf_counter()
        res = femadh_run(str(path), str(Path(tmp) / "out") if out else None, figures=False)
        return res, time.perf_counter() - t0


def table(total):
    cols = ["calls", "solves", "newton", "krylov", "lu", "chol", "lu_gflop", "chol_gflop",
            "solve_ms"]
    lines = ["| phase | wall (s) | " + " | ".join(cols) + " |",
             "|---|---|" + "---|" * len(cols)]
    for key in sorted(set(COUNTS) | set(TIMES)):
        c = COUNTS[key]
        cells = [f"{c[x]:.3g}" if isinstance(c[x], float) else str(c[x]) for x in cols]
        lines.append(f"| {key} | {TIMES.get(key, 0.0):.3f} | " + " | ".join(cells) + " |")
    tot = collections.Counter()
    for c in COUNTS.values():
        tot.update({k: v for k, v in c.items() if k != "calls"})
    lines.append(f"| **all** | {total:.3f} | - | " + " | ".join(
        f"{tot[x]:.3g}" if isinstance(tot[x], float) else str(tot[x]) for x in cols[1:]) + " |")
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", default="paper1_fig4", help="a bundled scene's name")
    ap.add_argument("--out", action="store_true", help="write the run's folder (a temporary one)")
    ap.add_argument("--accuracy", type=float, default=1e-3)
    ap.add_argument("--json")
    args = ap.parse_args(argv)
    install()
    res, wall = run(args.scene, args.accuracy, args.out)
    print(table(wall))
    acc = getattr(res, "accuracy", None) or {}
    print("nodes per trial:", [s.get("nodes") for s in acc.get("steps", [])])
    print("headline:", {k: v for k, v in (res.headline or {}).items()
                        if k in ("max_adhesion_N", "F_LJ_deepest_N", "d_at_max_adhesion_m")})
    print("estimates:", {k: v for k, v in (res.estimates or {}).items()
                         if k in ("max_adhesion_N_error", "F_LJ_deepest_N_error")})
    if args.json:
        Path(args.json).write_text(json.dumps({
            "wall": wall, "counts": {k: dict(v) for k, v in COUNTS.items()},
            "times": dict(TIMES), "headline": res.headline, "estimates": res.estimates,
            "steps": acc.get("steps")}, default=str, indent=1))


if __name__ == "__main__":
    main()
