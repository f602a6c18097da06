"""What a contact unzipping node by node costs the stepping: solves, Newton iterations,
factorisations, landings and wall of the sweep (issue 21; validation/results/snap_cost.md).

``python -m validation.snap_cost`` rebuilds the stiction map's sigma = 0.489 nm, p/psat 0.15
point's first trial (the 2-mm slider + meniscus, validation/scenes/paper1_slider_meniscus.toml
from 4 nm, the adaptive loop's first member, 532 nodes) and runs its sweep without the error
estimate, counting the work of the corrector (every :func:`solve_complementarity`) and of the
landings (:func:`femadh.contact.landing.land`), per branch; the retract unzips 85 nodes in its
grid step 1.2 -> 1.4 nm. ``--off``: the path before issue 21's snap work;
``--compare``: the descent's landing beside every next-node landing and the whole budget
beside every decision cut short. A minute or two on a quiet machine; the counts are exact,
the times depend on the load (printed).
"""
import argparse
import os
import time

import femadh
from femadh.contact import complementarity, landing, snap, stepping

HERE = os.path.dirname(os.path.abspath(__file__))
SCENE = os.path.join(HERE, "scenes", "paper1_slider_meniscus.toml")


class Counter:
    """Counts every corrector solve and landing of a sweep (wrapping the module names)."""

    def __init__(self):
        self.work = {}
        self.landings, self.land_time = 0, 0.0
        self._orig = (stepping.solve_complementarity, landing.solve_complementarity,
                      stepping.land, snap.solve_complementarity)

    def __enter__(self):
        solve, _, land, _ = self._orig

        def counted_solve(*a, **k):
            stats = k.pop("stats", None)
            # (a caller's iteration history, which the fold decision reads, is kept)
            own = {"history": stats["history"]} if stats and "history" in stats else {}
            st = solve(*a, stats=own, **k)
            for key, v in own.items():
                if key == "history":
                    continue
                self.work[key] = self.work.get(key, 0) + v
                if stats is not None:
                    stats[key] = stats.get(key, 0) + v
            return st

        def counted_land(*a, **k):
            t0 = time.perf_counter()
            try:
                return land(*a, **k)
            finally:
                self.landings += 1
                self.land_time += time.perf_counter() - t0

        stepping.solve_complementarity = counted_solve
        landing.solve_complementarity = counted_solve
        snap.solve_complementarity = counted_solve
        stepping.land = counted_land
        return self

    def __exit__(self, *exc):
        (stepping.solve_complementarity, landing.solve_complementarity, stepping.land,
         snap.solve_complementarity) = self._orig

    def row(self):
        w = self.work
        return (w.get("solves", 0), w.get("iterations", 0), w.get("factorisations", 0),
                self.landings, self.land_time)


class Compare:
    """Runs the energy-descent landing next to every landing the corrector found from the
    disk a node or two further (:func:`landing.land_next_node`) and records how far apart
    they are: (d, contact nodes of each, max |w_next - w_descent| (m), energies (J)); and
    the whole-budget corrector next to every fold decision cut short in a cycle
    (:func:`snap.decide`): (d, converged, iterations)."""

    def __init__(self):
        self.rows = []
        self._orig = stepping.land_next_node

    def __enter__(self):
        orig = self._orig

        def compared(problem, d, state, sign, *, tol, **k):
            st = orig(problem, d, state, sign, tol=tol, **k)
            if st is not None:
                ref = landing.land(problem, d, state.w, tol=tol, max_iter=40)
                self.rows.append((d, int(st.active.sum()), int(ref.active.sum()),
                                  float(abs(st.w - ref.w).max()), ref.converged and ref.stable,
                                  problem.energy(st.w, d), problem.energy(ref.w, d)))
            return st

        stepping.land_next_node = compared
        decide = self._decide = snap.decide

        def checked(problem, d, w_pred, tol, budget, act, factor, work):
            n0 = work.get("decisions_cycling", 0)
            new = decide(problem, d, w_pred, tol, budget, act, factor, work)
            if work.get("decisions_cycling", 0) > n0:
                # a decision cut short in a cycle: the whole budget must fail as well
                full = complementarity.solve_complementarity(
                    problem, d, w_pred, tol=tol, max_iter=budget, active0=act,
                    factor=factor)
                self.cycles.append((d, full.converged, full.n_iter))
            return new

        self.cycles = []
        snap.decide = checked
        return self

    def __exit__(self, *exc):
        stepping.land_next_node = self._orig
        snap.decide = self._decide


def first_trial_problem(sigma="0.488888888889 nm", rel=0.15, start="4 nm"):
    """The map point's scene and the ContactProblem of its adaptive loop's first member."""
    from femadh.discretisation import plan_grid
    from femadh.runner import adaptive
    from femadh.runner.estimates import variant
    from femadh.scene import build_problem

    scene = femadh.load_scene(SCENE).replace({
        "effects.asperity_gap.sigma": sigma, "effects.capillary.relative_pressure": rel,
        "sweep.start": start})
    target = scene.target_accuracy
    plan = plan_grid(scene.effects, scene.gap.sigma, scene.sphere, scene.analysis_radius,
                     scene.d_values, target)
    tr = adaptive.first_trial(scene, plan, target)
    trial = variant(scene, grid=tr.grid(), radius=tr.family.radius)
    return trial, build_problem(trial, operator=tr.operator)


def sweep(scene, problem, window=None):
    """Trace the scene's branches; per branch (solves, iterations, factorisations, landings,
    landing wall, sweep wall, jumps, lattice snaps, the sweep's work dict, sweep cpu) and
    the states' (d, contact nodes, w)."""
    from femadh.runner.tracing import branch_plan

    rows, start, states = {}, None, {}
    for branch, d_vals in branch_plan(scene):
        with Counter() as c:
            t0, c0 = time.perf_counter(), time.process_time()
            sw = stepping.trace_steps(problem, d_vals, branch=branch, tol=scene.tolerance,
                                      start=start, max_iter=scene.max_iter)
            wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        rows[branch] = c.row() + (wall, len(sw.jumps), sw.work.get("lattice_snaps", 0),
                                  dict(sw.work), cpu)
        states[branch] = [(s.d, int(s.active.sum()), s.w) for s in sw.states]
        start = sw.states[-1]
    return rows, states


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rel", type=float, default=0.15)
    ap.add_argument("--sigma", default="0.488888888889 nm")
    ap.add_argument("--off", action="store_true",
                    help="the path before issue 21's snap work (SNAP_RHYTHM, "
                    "NEXT_NODE_LANDING, CYCLE_PROBE_ITER off)")
    ap.add_argument("--compare", action="store_true",
                    help="run the descent landing next to every next-node landing")
    args = ap.parse_args()
    if args.off:
        snap.SNAP_RHYTHM = snap.NEXT_NODE_LANDING = False
        snap.CYCLE_PROBE_ITER = 0
    print("load:", os.getloadavg())
    scene, problem = first_trial_problem(args.sigma, args.rel)
    print(f"nodes {problem.grid.n}")
    if args.compare:
        with Compare() as cmp:
            rows, states = sweep(scene, problem)
        print(f"decisions cut short in a cycle: {len(cmp.cycles)}; the whole budget "
              f"converged at {sum(c[1] for c in cmp.cycles)} of them")
        for r in cmp.rows:
            print(f"compare d {r[0] * 1e9:.6f} nm: nodes {r[1]} vs descent {r[2]}, "
                  f"max|dw| {r[3]:.3g} m, descent ok {r[4]}, E {r[5]:.12e} vs {r[6]:.12e}")
    else:
        rows, states = sweep(scene, problem)
    for b, r in rows.items():
        print(f"{b}: solves {r[0]} iterations {r[1]} factorisations {r[2]} landings {r[3]} "
              f"({r[4]:.1f} s) wall {r[5]:.1f} s cpu {r[9]:.1f} s jumps {r[6]} snaps {r[7]}")
        print("   work", r[8])
    for b, s in states.items():
        print(b, [(round(d * 1e9, 3), m) for d, m, _ in s])
    print("load:", os.getloadavg())


if __name__ == "__main__":
    main()
