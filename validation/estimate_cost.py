"""What the error estimate costs, and where its time goes: the adaptive rows of
validation/accuracy.py, each run with the estimate's reductions off ("before": every member
solves the deepest state and four states around each zero-force crossing, and its fold
decisions run to max_iter), on as session 7 left them ("after") and with session 8's
("kink": a member's windowed peak search that misses stops at the window's edge and the kink
model searches the rest of the bracket; a member state Newton ends on a saddle is landed)
and with session 9's ("factor": a member's states on a grid of fewer than
femadh.runner.peak.MEMBER_FACTOR_MIN_NODES nodes factorise their own Jacobian instead of
inheriting a nearby state's factorisation),
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

from femadh.runner import estimates, members, peak

from .accuracy import CASES, SCENES, _adaptive, _timed

RESULTS = Path(__file__).resolve().parent / "results"
#: the settings compared: module flags of femadh.runner.members / estimates
SETTINGS = {"before": {"ZERO_FORCE_PAIR_FIRST": False, "LOCKED_DEEPEST_ONLY": False,
                       "FOLD_DECISION_STALL": False, "KINK_PEAK": False,
                       "LAND_SADDLE": False},
            "after": {"ZERO_FORCE_PAIR_FIRST": True, "LOCKED_DEEPEST_ONLY": True,
                      "FOLD_DECISION_STALL": True, "KINK_PEAK": False, "LAND_SADDLE": False},
            # session 8: a window that misses stops at its edge and the kink model searches
            # the rest of the bracket; a member state on a saddle is landed
            "kink": {"ZERO_FORCE_PAIR_FIRST": True, "LOCKED_DEEPEST_ONLY": True,
                     "FOLD_DECISION_STALL": True, "KINK_PEAK": True, "LAND_SADDLE": True,
                     "MEMBER_FACTOR_MIN_NODES": 0},
            # session 9: a small member's states factorise their own Jacobian instead of
            # inheriting a factorisation from a state a fraction of a grid step away
            "factor": {"ZERO_FORCE_PAIR_FIRST": True, "LOCKED_DEEPEST_ONLY": True,
                       "FOLD_DECISION_STALL": True, "KINK_PEAK": True, "LAND_SADDLE": True,
                       "MEMBER_FACTOR_MIN_NODES": peak.MEMBER_FACTOR_MIN_NODES}}
for _s in ("before", "after"):
    SETTINGS[_s]["MEMBER_FACTOR_MIN_NODES"] = 0
PARTS = ("deepest", "peak grid states", "peak search", "folds", "zero force", "edge-placed")


@contextlib.contextmanager
def _setting(flags):
    saved = {}
    flags = dict(flags)
    xtol = flags.pop("member_peak_xtol", None)
    if xtol is not None:
        # what-if only (not a setting of femadh): the members' peak searches at another
        # tolerance in d, the fine run's own search unchanged
        orig = estimates.reduced_member

        def reduced(*a, **kw):
            from femadh.runner import peak
            old, peak.PEAK_XTOL_FRACTION = peak.PEAK_XTOL_FRACTION, xtol
            try:
                return orig(*a, **kw)
            finally:
                peak.PEAK_XTOL_FRACTION = old
        saved[(estimates, "reduced_member")] = orig
        estimates.reduced_member = reduced
    for k, v in flags.items():
        mod = members if hasattr(members, k) else peak if hasattr(peak, k) else estimates
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
    import femadh.contact.stepping as cs
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
            # the sweep's work since the last estimate: this trial's sweep (and the state
            # carried to its grid)
            sweep = dict(cnt.c["sweep"])
            cnt.reset()
            cnt.c["sweep"].update(sweep)
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
    patch(cs, "solve_complementarity", solves)       # the sweep's and a traced step's
    patch(cl, "land", counted("landings"))
    patch(pk, "peak_adhesion", lambda f: _peak_counted(f, cnt))
    patch(pk, "kink_peak", counted("kink searches", "peak search"))
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
    import femadh.runner.peak as pk

    def g(problem, prev, best, nxt, scene, within=None, reuse=False, **kw):
        cnt.enter("peak search")
        cnt.add("windowed searches" if within is not None else "whole-bracket searches")
        try:
            return f(problem, prev, best, nxt, scene, within=within, reuse=reuse, **kw)
        except pk.WindowMiss:
            cnt.add("windows stopped at their edge")
            raise
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
    ap.add_argument("--what-if-member-xtol", type=float, default=None, metavar="F",
                    help="add a third setting: 'after' with the members' peak searches at "
                    "tolerance F of the bracket (femadh.runner.peak.PEAK_XTOL_FRACTION, 1e-4; "
                    "a measurement, not a setting femadh has)")
    args = ap.parse_args(argv)
    if args.what_if_member_xtol is not None:
        SETTINGS["what-if"] = {**SETTINGS["after"],
                               "member_peak_xtol": args.what_if_member_xtol}
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
             "last trial's estimate (the one the ratio judges), both members together."]
    if "what-if" in SETTINGS:
        lines += ["", "\"what-if\": \"after\" with the members' peak searches at "
                  f"{args.what_if_member_xtol:g} of their bracket in d instead of "
                  "PEAK_XTOL_FRACTION (femadh.runner.peak, 1e-4) - a measurement of what "
                  "that part of the estimate costs, not a setting femadh has."]
    names = list(SETTINGS)
    arrow = " → ".join(names)
    lines += ["", "## Time", "",
              "Newton iterations: the members' (every part below) over the sweep's (the last "
              "trial's, with the state carried to its grid); a member's iteration is on "
              "fewer nodes than the sweep's, so this ratio is an upper bound of the work's "
              "ratio that the load does not move.", "",
              f"| scene | request | nodes | solve (s) | estimate (s) {arrow} | "
              f"estimate / solve {arrow} | Newton iterations estimate / sweep {arrow} |",
              "|---|---|---|---|---|---|---|"]
    for name, acc, out in rows:
        a = out["after"]
        lines.append(f"| {name} | {acc:g} | {a[3]} | {_med([x[2] for x in a[0]]):.3f} | "
                     + " → ".join(f"{_med([x[1] for x in out[n][0]]):.3f}" for n in names)
                     + " | "
                     + " → ".join(f"{_med([x[0] for x in out[n][0]]):.2f}" for n in names)
                     + " | "
                     + " → ".join(f"{_sum(out[n][1], 'iterations')}/"
                                  f"{out[n][1]['sweep']['iterations']}" for n in names)
                     + " |")
    keys = ("states", "fresh states", "solves", "iterations", "factorisations", "folds",
            "landings", "windowed searches", "windows stopped at their edge",
            "whole-bracket searches", "kink searches")
    lines += ["", f"## Work by part ({arrow})", "",
              "| scene | request | part | " + " | ".join(keys) + " |",
              "|---|---|---|" + "---|" * len(keys)]

    def cell(vals):
        return " → ".join(str(v) for v in vals) if len(set(vals)) > 1 else str(vals[0])
    for name, acc, out in rows:
        cs = [out[n][1] for n in names]
        for part in PARTS:
            if not any(any(c[part].values()) for c in cs):
                continue
            lines.append(f"| {name} | {acc:g} | {part} | "
                         + " | ".join(cell([c[part][k] for c in cs]) for k in keys) + " |")
        lines.append(f"| {name} | {acc:g} | **all** | "
                     + " | ".join(cell([_sum(c, k) for c in cs]) for k in keys) + " |")
    lines += ["", "## What the estimate says", "",
              "Headline numbers compared bit for bit with \"before\"; the estimated errors "
              "that moved are listed.", ""]
    for name, acc, out in rows:
        hb = out["before"][2]
        for n in names[1:]:
            ha = out[n][2]
            head = [k for k in hb if not k.endswith("_error") and not _same(hb[k], ha.get(k))]
            err = [k for k in hb if k.endswith("_error") and not _same(hb[k], ha.get(k))]
            lines.append(f"- {name} {acc:g}, {n}: headline "
                         f"{'identical' if not head else head}; "
                         + ("estimates identical" if not err else "estimates moved: "
                            + ", ".join(f"{k} {hb[k]:.6g} → {ha[k]:.6g}" for k in err)))
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
