"""A fold's separation between its lattice point and the next: the achieved error of a jump
row measured below the lattice both the run and its reference locate folds on.

The stepping locates a fold to its lattice step s = MIN_STEP_FRACTION of the sweep step
(:mod:`femadh.contact.stepping`): the reported d_fold is the last stable state before the
fold, the fold itself lies within one s beyond. Two runs' folds compared on that lattice
differ by whole steps, so an achieved error of one s is known only to +-1 s. Here the
reference's fold is bisected further: the last separation where Newton from the state at the
lattice fold, continued in steps of at most s / 2^k, stays on its branch (converged, stable,
every gap within a quarter of the start's).

``python -m validation.effectivity_folds SCENE H_REF_NM`` (the reference of
validation/accuracy.py's family at that band spacing; results cached in /tmp/eff).
"""
import json
import sys

import numpy as np

import femadh
from femadh.contact import solve_state
from femadh.runner.estimates import variant

from .accuracy import SCENES
from .effectivity import CACHE
from .effectivity_scan import capture

BISECTIONS = 12


def on_branch(problem, prev, d, tol, max_iter):
    """The stable state at d by Newton from ``prev`` (same grid) if it stays on its branch."""
    st = solve_state(problem, d, prev.w, tol=tol, max_iter=max_iter,
                     **({} if prev.active is None else {"active0": prev.active}))
    if not (st.converged and st.stable):
        return None
    if np.any(np.abs(st.w - prev.w) > 0.25 * np.maximum(problem.contour(d) - prev.w, 0)
              + 1e-15):
        return None
    return st


def continuous_folds(scene):
    """[(branch, lattice d_fold, bisected d_fold)] of a run of ``scene``."""
    res, got = capture(scene)
    p, sink, sc = got["problem"], got["sink"], got["scene"]
    out = []
    for branch, d_fold, d_land, before, _after in sink.folds:
        s = d_land - d_fold
        lo, hi, state = d_fold, d_land, before
        for _ in range(BISECTIONS):
            mid = 0.5 * (lo + hi)
            st = on_branch(p, state, mid, sc.tolerance, sc.max_iter)
            if st is None:
                hi = mid
            else:
                lo, state = mid, st
        out.append((branch, d_fold, 0.5 * (lo + hi), abs(s)))
    return res, out


def main(argv=None):
    argv = argv or sys.argv[1:]
    name, h_ref = argv[0], float(argv[1]) * 1e-9
    fam = json.loads((CACHE / f"{name}_plan.json").read_text())
    base = femadh.load_scene(SCENES / f"{name}.toml")
    sc = variant(base, grid={"spacing": h_ref, "band": fam["band"], "grading": fam["grading"]},
                 radius=2 * fam["a"])
    res, folds = continuous_folds(sc)
    for b, lat, cont, s in folds:
        print(f"{b}: lattice {lat!r} m, bisected {cont!r} m, lattice step {s:.4g} m "
              f"({(cont - lat) / s:+.3f} steps)")
    (CACHE / f"{name}_{h_ref * 1e9:.4g}nm_folds.json").write_text(json.dumps(folds))


if __name__ == "__main__":
    main()
