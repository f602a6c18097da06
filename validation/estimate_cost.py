"""What the error estimate costs, and where its time goes: the adaptive rows of
validation/accuracy.py, each run with the estimate's reductions off ("before": every member
solves the deepest state and four states around each zero-force crossing) and on ("after"),
counting the members' work by part - states, corrector solves, Newton iterations,
factorisations, folds, landings, peak searches (windowed and over the whole bracket) and the
fresh states they solve - and timing the estimate against the sweep it judges (median of
``--repeat`` runs).

``python -m validation.estimate_cost [--repeat 3] [--only NAME]`` writes
validation/results/estimate_cost.md (~2 min on two cores, one BLAS thread; the load is
printed in the file: the ratios are the numbers, the seconds move with the load).

The counts come from wrapping the solver entries the members call (the same functions, only
counted); the headline numbers and their estimates of both settings are compared, so a
reduction that changed what the estimate says would show.
"""
import argparse
import collections
import contextlib
import math
import os
from pathlib import Path
import statistics

from femadh.runner import estimates, members

from .accuracy import CASES, SCENES, _adaptive, _timed

RESULTS = Path(__file__).resolve().parent / "results"
#: the settings compared: module flags of femadh.runner.members / estimates
SETTINGS = {"before": {"ZERO_FORCE_PAIR_FIRST": False, "LOCKED_DEEPEST_ONLY": False},
            "after": {"ZERO_FORCE_PAIR_FIRST": True, "LOCKED_DEEPEST_ONLY": True}}
PARTS = ("deepest", "peak grid states", "peak search", "folds", "zero force", "edge-placed")


@contextlib.contextmanager
def _setting(flags):
    saved = {}
    for k, v in flags.items():
        mod = members if hasattr(members, k) else estimates
        saved[(mod, k)] = getattr(mod, k)
        setattr(mod, k, v)
    try:
        yield
    finally:
        for (mod, k), v in saved.items():
            setattr(mod, k, v)


class Counter:
    """Counts of the members' work by part, for the last estimate of a run (the adaptive
    loop's earlier trials are counted and dropped when the next estimate starts)."""

    def __init__(self):
        self.part = ["sweep"]
        self.last = None
        self.reset()

    def reset(self):
        self.c = collections.defaultdict(collections.Counter)

    def enter(self, part):
        self.part.append(part)

    def leave(self):
        self.part.pop()

    def add(self, key, n=1):
        self.c[self.part[-1]][key] += n


@contextlib.contextmanager
def counting():
    """Wrap the entries the members call so that their work is counted by part."""
    import femadh.contact.complementarity as cc
    import femadh.contact.landing as cl
    import femadh.runner.peak as pk

    cnt = Counter()
    patches = []

    def patch(mod, name, wrapper):
        patches.append((mod, name, getattr(mod, name)))
        setattr(mod, name, wrapper(getattr(mod, name)))

    def in_part(part):
        def wrap(f):
            def g(*a, **kw):
                cnt.enter(part)
                try:
                    return f(*a, **kw)
                finally:
                    cnt.leave()
            return g
        return wrap

    def solves(f):
        def g(*a, **kw):
            st = kw.get("stats")
            if st is None:
                st = kw["stats"] = {}
            before = {k: st.get(k, 0) for k in ("solves", "iterations", "factorisations")}
            out = f(*a, **kw)
            for k, v in before.items():
                cnt.add(k, st.get(k, 0) - v)
            return out
        return g

    def counted(key, part=None):
        def wrap(f):
            def g(*a, **kw):
                if part:
                    cnt.enter(part)
                cnt.add(key)
                try:
                    return f(*a, **kw)
                finally:
                    if part:
                        cnt.leave()
            return g
        return wrap

    def estimate(f):
        def g(*a, **kw):
            cnt.reset()
            cnt.enter("estimate")
            try:
                return f(*a, **kw)
            finally:
                cnt.leave()
                cnt.last = cnt.c
        return g

    def member_state(f):
        def g(self, branch, snaps, k):
            fresh = (branch, k) not in self.cache
            last = k == len(snaps) - 1 and branch == "approach"
            part = cnt.part[-1]
            if part == "member" and last:
                part = "deepest"
            cnt.enter(part)
            try:
                if fresh:
                    cnt.add("states")
                return f(self, branch, snaps, k)
            finally:
                cnt.leave()
        return g

    patch(cc, "solve_complementarity", solves)
    patch(cl, "solve_complementarity", solves)       # a landing's polish (its own import)
    patch(cl, "land", counted("landings"))
    patch(pk, "peak_adhesion", lambda f: _peak_counted(f, cnt))
    patch(pk, "state_between", counted("fresh states"))
    patch(members, "_peak", in_part("peak grid states"))
    patch(members, "_lattice_fold", counted("folds", "folds"))
    patch(members, "_step_folds", counted("folds", "folds"))
    patch(members, "_zero_force_radius", in_part("zero force"))
    patch(members._Member, "state", member_state)
    # estimates imported these by name; runner.contact imports estimate_errors at call time
    patch(estimates, "reduced_member", in_part("member"))
    patch(estimates, "deepest_locked", in_part("edge-placed"))
    patch(estimates, "estimate_errors", estimate)
    try:
        yield cnt
    finally:
        for mod, name, f in reversed(patches):
            setattr(mod, name, f)


def _peak_counted(f, cnt):
    def g(problem, prev, best, nxt, scene, within=None, reuse=False):
        cnt.enter("peak search")
        cnt.add("windowed searches" if within is not None else "whole-bracket searches")
        try:
            return f(problem, prev, best, nxt, scene, within=within, reuse=reuse)
        finally:
            cnt.leave()
    return g


def _sum(c, key, parts=PARTS):
    return sum(c[p][key] for p in parts)


def run_case(name, accuracy, setting, repeat):
    """[(ratio estimate / solve, estimate s, solve s)] over the repeats, the last run's
    counts and headline."""
    base = __import__("femadh").load_scene(SCENES / f"{name}.toml")
    times = []
    with _setting(SETTINGS[setting]):
        # the counts from one more run with the counting wrappers (not timed: they cost)
        with counting() as cnt:
            res, _t = _timed(_adaptive(base, accuracy))
        counts, hl, nodes = cnt.last, dict(res.headline), res.grid.get("nodes")
        for _ in range(repeat):
            res, _t = _timed(_adaptive(base, accuracy))
            t = res.timings
            times.append((t["error_estimate_s"] / t["solve_s"], t["error_estimate_s"],
                          t["solve_s"]))
            assert res.grid.get("nodes") == nodes
    return times, counts, hl, nodes


def _med(xs):
    return statistics.median(xs)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--only", help="the scenes whose name contains this (no file written)")
    args = ap.parse_args(argv)
    load0 = os.getloadavg()
    rows = []
    for name, (_n, requests, _h, _q) in CASES.items():
        if args.only and args.only not in name:
            continue
        for acc in requests:
            if name == "paper1_fig3" and acc < 3e-4:
                continue        # 1e-4: its 867-node sweep alone is ~2 s a run
            out = {}
            for setting in SETTINGS:
                out[setting] = run_case(name, acc, setting, args.repeat)
            rows.append((name, acc, out))
            b, a = out["before"], out["after"]
            print(name, acc, "ratio", round(_med([x[0] for x in b[0]]), 3), "->",
                  round(_med([x[0] for x in a[0]]), 3), flush=True)
    load1 = os.getloadavg()
    lines = ["# What the error estimate costs (validation/estimate_cost.py)", "",
             __doc__.split("\n\n")[0].replace("\n", " "), "",
             f"Load (1/5/15-minute averages) at the start {load0[0]:.2f}/{load0[1]:.2f}/"
             f"{load0[2]:.2f}, at the end {load1[0]:.2f}/{load1[1]:.2f}/{load1[2]:.2f} "
             f"on 2 cores; one BLAS thread; median of {args.repeat} runs. Counts are the "
             "last trial's estimate (the one the ratio judges), both members together.", "",
             "## Time", "",
             "| scene | request | nodes | solve (s) | estimate (s) before → after | "
             "estimate / solve before → after |", "|---|---|---|---|---|---|"]
    for name, acc, out in rows:
        b, a = out["before"], out["after"]
        lines.append(f"| {name} | {acc:g} | {a[3]} | {_med([x[2] for x in a[0]]):.3f} | "
                     f"{_med([x[1] for x in b[0]]):.3f} → {_med([x[1] for x in a[0]]):.3f} | "
                     f"{_med([x[0] for x in b[0]]):.2f} → {_med([x[0] for x in a[0]]):.2f} |")
    keys = ("states", "fresh states", "solves", "iterations", "factorisations", "folds",
            "landings", "windowed searches", "whole-bracket searches")
    lines += ["", "## Work by part (before → after)", "",
              "| scene | request | part | " + " | ".join(keys) + " |",
              "|---|---|---|" + "---|" * len(keys)]
    for name, acc, out in rows:
        cb, ca = out["before"][1], out["after"][1]
        for part in PARTS:
            if not any(cb[part].values()) and not any(ca[part].values()):
                continue
            cells = [f"{cb[part][k]} → {ca[part][k]}" if cb[part][k] != ca[part][k]
                     else f"{ca[part][k]}" for k in keys]
            lines.append(f"| {name} | {acc:g} | {part} | " + " | ".join(cells) + " |")
        tb = {k: _sum(cb, k) for k in keys}
        ta = {k: _sum(ca, k) for k in keys}
        lines.append(f"| {name} | {acc:g} | **all** | " + " | ".join(
            f"{tb[k]} → {ta[k]}" if tb[k] != ta[k] else f"{ta[k]}" for k in keys) + " |")
    lines += ["", "## What the estimate says (before → after)", "",
              "Headline numbers of both settings are compared bit for bit; the estimated "
              "errors that moved are listed.", ""]
    for name, acc, out in rows:
        hb, ha = out["before"][2], out["after"][2]
        head = [k for k in hb if not k.endswith("_error") and not _same(hb[k], ha.get(k))]
        err = [k for k in hb if k.endswith("_error") and not _same(hb[k], ha.get(k))]
        lines.append(f"- {name} {acc:g}: headline {'identical' if not head else head}; "
                     + ("estimates identical" if not err else "estimates moved: " + ", ".join(
                         f"{k} {hb[k]:.6g} → {ha[k]:.6g}" for k in err)))
    text = "\n".join(lines) + "\n"
    print(text)
    if not args.only:
        (RESULTS / "estimate_cost.md").write_text(text)
        print(f"written: {RESULTS / 'estimate_cost.md'}")


def _same(x, y):
    if isinstance(x, float) and isinstance(y, float) and math.isnan(x) and math.isnan(y):
        return True
    return x == y


if __name__ == "__main__":
    main()
