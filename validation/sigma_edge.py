"""The sigma-gap retract traced in its edge radius (femadh.contact.sigma_edge) on points of the
stiction map, against the runner's equations and values, with a mesh refinement.

``python -m validation.sigma_edge`` writes validation/results/sigma_edge.md. For each point
(the stiction map's scene, validation/scenes/paper1_slider_meniscus.toml, at sigma and
p/psat):

1. a pilot trace on the coarse edge grid (the runner's first-trial spacing) locates the
   pull-off fold c_f and the largest tensile force's edge radius c*;
2. a grid family h0 / sqrt2^j (j = 0..J) of edge grids with node k at c* (one mesh density:
   fixed half-width and grading, :func:`femadh.contact.edge_branch.edge_grid`), analysis
   radius a0 = a_run c* / (0.9 c_f) so that every scaled grid of the traced range holds the
   runner's analysis disk (the force read on the runner's disk: the laws between a_run and
   lam a0 on the undeformed paraboloid taken off, :func:`sigma_edge.tail_between`);
   Richardson from the three finest members (observed order from their differences);
3. the runner's equations at three states of one member (the pull-off fold, the largest
   force, a deep state): an independent ContactProblem on the scaled grid (a Green operator
   built afresh on the scaled nodes, sub-grid capillary step as the scene builder has it),
   its residual max |w - C (P - p_c)|, complementarity, the runner's stability test, and
   the runner's semismooth Newton (solve_complementarity) started from the state: its
   iterations and how far it moves the state;
4. the runner's curve on a fixed grid (a node at c*, the family's mesh density at one h):
   F_ex(d) on a scan of separations around the branch's d* solved by the runner's solver,
   each from the previous state; its largest value against the branch's on the same h.
"""
import math
from pathlib import Path
import sys
import time

import numpy as np

import femadh
from femadh.elastic import GreenOperator, RadialGrid
# the edge grids' half-width and grading (units of h0), the analysis radius's reach, the
# pilot, the family and the guarded Richardson are the edge route's: one home
from femadh.runner.edge_route import GRADING, HALF, LOW, family, pilot, richardson
from femadh.runner.edge_route import trace as _trace

HERE = Path(__file__).resolve().parent
RESULTS = HERE / "results"
SCENE = HERE / "scenes" / "paper1_slider_meniscus.toml"

#: (sigma nm, p/psat, coarse spacing h0 nm: the runner's first-trial band spacing at the
#: point, sigma03_pulloff.md / sigma03_follow.md; the runner's max adhesion (N) and what it is)
POINTS = [
    (0.3, 0.95, 3.665, 8.075837e-4, "this session's CLI run at accuracy 3e-3, converged: "
     "+- 1.17e-6 N (1.45e-3), 2 trials, 1362 s wall at load 7-10, 275 CPU-s"),
    (0.3, 0.05, 1.707, 3.3861e-4, "trial 2 (0.512-nm follow band, its estimate unfinished; "
     "trial 1: 8.8e-3 estimated)"),
    (0.489, 0.15, 5.25, 1.567073e-4, "1772-node trial, converged: +- 1.36e-7 N (8.7e-4); "
     "at the map's sigma 0.48889 nm on a 28.28-um disk, not this point: see the notes"),
]
#: family members h0 / sqrt2^j, j = 0..LEVELS-1
LEVELS = 5
#: what the results say beyond their numbers (appended to the report as it stands)
NOTES = """
## What the method is, and why the edge condition is p_c,k = 0

A state at edge radius c = r_k of the scaled grid r = (c / r_k^0) r^0 (C = lam C^0, one Green
operator for the branch): nodes 0..k held at h = sigma, the rest free, unknowns (w_free, d)
with the multipliers p_c,0..k-1 explicit, n - k equations: the free nodes' equilibrium
K w = P(h) on rows k..n-1. Row k is the edge condition p_c,k = 0. It is the discrete form of
the continuum's (bounded surface forces outside the contact: a contact pressure that does not
vanish at the edge needs a stress singularity, tensile - forbidden, p_c >= 0 - or compressive -
a gap below sigma just outside), and it makes every state a junction of the fixed grid's
branch: node k held with zero multiplier is node k free at the floor, so the state solves the
collocation problem with either contact set - the point where the runner's stepping releases
node k (a micro-fold). The branch is the curve through these junctions, one per c instead of
one per node; the checks above show each is the runner's state on its own grid (residual
below the runner's 1e-19 m, the runner's Newton from it converges at once without moving it,
the runner's stability test passes, complementarity with margin). On a fixed grid the runner's
states between junctions lie below the branch by the lattice sawtooth (tests: 1.3e-3 - 3e-3 on
125 nodes at 7.7-nm spacing; here the fixed-grid scans' largest: 6e-6 - 9e-5 below the branch
on 514-673 nodes).

## Is the branch monotone in c?

Yes at every point where it was traced: the retract's edge radius decreases monotonically from
deep contact to the displacement-controlled pull-off (the fold of d(c), dd/dc = 0, the largest
d), Newton in c never met a turning point of c (15-16 states per branch at 2-8 % steps, 20-22
solves, 4-5 factorisations a solve), and complementarity held on every state (worst multiplier
>= 1.9 % of the largest; every free gap above sigma, the first free node's by ~(h/c)^3/2 as
the continuum's gap (r - c)^3/2 says: down to 3e-7 sigma where c_fold ~ 0.07 um). The largest
tension is interior on the stable side at every traced point (c* = 2.2-2.4 c_fold at the three
points, up to 16 c_fold at sigma = 0.68 nm, p/psat 0.85): it is the max adhesion the runner
reads at d ~ 1-1.5 nm (approach and retract coincide there in the continuum: the same branch;
the runner's two values at d = 1.4 nm, p/psat 0.95, differ by 6e-5). What the continuation
does not do: the points where d(c) has no fold above 0.05 um (the contact shrinks to nothing
without a jump, DMT's side: most of sigma >= 0.68 nm at low and high humidity) - there the
largest force is where the contact vanishes or on the separated branch, not on this one; the
runner converges on all of them today.

One thing to get right: the scaled grid's far field. The meniscus edge sits microns out, in
the graded part, and moves across the scaled grid's coarse nodes as c changes; at a grading of
8 h0 that lattice made the members' differences erratic (orders -4.6 ... 10 in a first map
scan) and moved the fold's edge radius by up to 15 % where d(c) is flat (its d by 3e-3 nm), at
32 h0 the families converge at order 2.00. The family's grading must resolve that edge.

## Against the runner's values

sigma = 0.3 nm, p/psat 0.95: the runner's 8.075837e-4 N (this session, accuracy 3e-3 asked,
estimate 1.45e-3) lies 4.2e-4 below the branch's limit, d at max 1.4418 nm (the branch's
1.4439 nm), jump-out 2.24238 nm (the fold 2.24312 nm; the runner's estimate 4e-3 nm): within
its estimates. p/psat 0.05: 3.3861e-4 N, +5.4e-4 (its trial 1's estimate 8.8e-3; trial 2's
unfinished), jump-out 1.7707 nm (the fold 1.77069 nm). sigma = 0.489 nm, p/psat 0.15: the
runner's converged 1.567073e-4 N +- 1.36e-7 (8.7e-4) is the map's point, sigma = 0.3 + 1.7/9 =
0.48889 nm, on a 28.28-um disk - not this section's sigma = 0.489 nm on the 14.14-um disk
(an earlier version of this paragraph compared them: +1.42e-3, "effectivity 0.6", "the
runner's grid error under-read"). At the map's sigma the branch's limit is 1.56613766e-4 N
(8.23e-4 above this section's: the meniscus edge 0.08 nm above sigma makes the force steep in
sigma, d ln F / d ln sigma = -3.6), plus 1.20e-8 N for the larger disk: the runner lies
5.2e-4 above it, within its estimate (effectivity 1.67), and the sweep's banded grids and
the branch's edge grids converge to that one limit at order 2
(validation/results/sigma_edge_limits.md, `python -m validation.sigma_edge_limits`).

## How it should be wired into the runner

Wired in on branch `edgewire` (femadh/runner/edge_route.py; the map scan above now calls its
pilot, family and Richardson): a run takes the edge route where its adaptive grid would follow
the edge ([solver] route = "auto") or wherever it can ("edge", e.g. the stiction map) and the
pilot finds a fold; the max adhesion and the pull-off come from the family to the scene's
accuracy, the curve is the branch's own states. Not yet done of the plan below: the approach,
the jump-out's landing and the rest of the retract on this route, the retract's states at the
sweep's separations committed into the sink. (The map table above was made with the pilot at
c = 1 um, h = 4 nm; the route's pilot takes c_ref = JKR's radius / 4, ~1 um, h = c_ref / 250.)

The plan as it was written:

- Which scenes: sigma-gap complementarity without eq 20's adhesion, on the Green operator
  (C = lam C^0 holds for the homogeneous half-space only, not for a layered FE body), stepping
  continuation - i.e. exactly those for which `runner/adaptive._follow_trial` now returns a
  follow band (the sigma = 0.3 nm column, sigma = 0.489 nm / p/psat 0.15): the stiction map's
  10 refused or failed points. A pilot (`trace_retract` on a coarse edge grid, < 1 s) decides:
  a fold at finite c -> this path; no fold -> the present one.
- Where: `runner/tracing.trace_steps`, the retract branch. The approach stays as it is (clean
  at these points, sigma03_follow.md) up to its deepest state; the retract starts the edge
  branch at the deepest state's contact radius (`start_state`, or the deepest state's w
  interpolated onto the scaled grid) and marches down in c to the fold
  (`sigma_edge.trace_retract`); the sweep's separations on the stable part are read off by
  `BranchTrace.where_d` (d(c) is monotone between deep contact and the fold) and committed
  with `sink.state` on their scaled grids (fields.csv already carries each state's own r, as
  for the follow band; `SigmaEdgeState.problem` is the runner's ContactProblem of that grid,
  the State's active set nodes 0..k, p_contact = p_c). The jump-out is a Jump at the fold
  (d_fold = fold.d); its landing is `contact.landing.land` from the fold state on the fold's
  scaled grid (with its separated-state fallback), and the rest of the retract is the present
  stepping (no contact left to unzip).
- Headline: max adhesion from `BranchTrace.maximize` on the branch (added to the sink as the
  peak search's fresh states are), not the peak search between grid states.
- Estimate: for this branch the family h, h/sqrt2, h/2 of edge grids with node k at c*
  (fixed half-width 24 h0 and grading 32 h0, analysis radius a_run c* / (0.5 c_fold), the
  force read on the runner's disk by `sigma_edge.tail_between`) and the guarded Richardson of
  `validation/sigma_edge.richardson` (order 2), instead of `runner/members`' coarser members
  (which unzip along their own lattice paths: adaptive_follow.md). The approach's states and
  the jump-in keep the present estimate.
- Budget: a point of the sigma = 0.3 nm column is then the approach (~20-30 s on the follow
  band today, sigma03_follow.md) plus the retract's family (a few seconds): the retract's
  ~500 micro-folds and their landings are gone.
"""


def scene_at(sigma_nm, rel):
    return femadh.load_scene(SCENE).replace({
        "effects.asperity_gap.sigma": f"{sigma_nm} nm",
        "effects.capillary.relative_pressure": rel})


def trace(scene, c_ref, h, h0, a0, a_run, c_fold_hint, c_high):
    """The edge route's trace (:func:`femadh.runner.edge_route.trace`) down to LOW x the
    fold's edge radius ``c_fold_hint``."""
    return _trace(scene, c_ref, h, h0, a0, a_run, LOW * c_fold_hint, c_high)


def check_runner_equations(scene, br, st):
    """The runner's view of a branch state: residual, complementarity, stability, and its
    semismooth Newton from the state (iterations, largest move of w relative to the gaps)."""
    from femadh.contact import ContactProblem, solve_state

    grid = RadialGrid.from_nodes(st.lam * br.nodes0, br.radius(st))
    pb = ContactProblem(GreenOperator(grid, scene.body.e_star), scene.sphere,
                        dict(scene.effects), scene.gap)
    P = pb.pressure(st.h)
    resid = float(np.abs(st.w - pb.C @ (P - st.p_c)).max())
    active = np.arange(br.n) <= br.k
    sol = solve_state(pb, st.d, st.w, tol=scene.tolerance, max_iter=scene.max_iter,
                      active0=active)
    move = float(np.abs(sol.w - st.w).max()) if sol.converged else math.nan
    from femadh.contact.stability import is_stable

    return {"c": st.c, "d": st.d, "residual": resid, "compl": br.complementarity(st),
            "stable": is_stable(pb, st.h, ~active), "runner_iter": sol.n_iter,
            "runner_converged": sol.converged, "move": move,
            "active_same": bool(np.array_equal(sol.active[:br.k], active[:br.k])
                                and not sol.active[br.k + 1:].any()),
            "runner_res": sol.residual}


def fixed_grid_scan(scene, br, res, a_run, span=0.04e-9, n=17):
    """The runner's solver on the fixed grid of ``br`` at lam = 1 (node k at c*, the same
    mesh density), analysis radius cut to the runner's: F_ex on n separations within +-span
    of the branch's d*, each from the previous state (the first from the branch's state
    interpolated). Returns (d, F) arrays and the seconds."""
    from femadh.contact import ContactProblem, solve_state
    from femadh.contact.forces import state_forces

    t0 = time.perf_counter()
    nodes = br.nodes0[br.nodes0 < a_run]
    grid = RadialGrid.from_nodes(nodes, a_run)
    pb = ContactProblem(GreenOperator(grid, scene.body.e_star), scene.sphere,
                        dict(scene.effects), scene.gap)
    best = res.best
    w = np.interp(nodes, best.lam * br.nodes0, best.w)
    ds = best.d + np.linspace(-span, span, n)
    order = np.argsort(np.abs(ds - best.d))
    F = np.full(n, math.nan)
    ws = {}
    for i in order:
        near = min(ws, key=lambda j: abs(ds[j] - ds[i])) if ws else None
        w0 = ws[near] if near is not None else w
        st = solve_state(pb, ds[i], np.minimum(w0, pb.contour(ds[i]) - scene.gap.sigma),
                         tol=scene.tolerance, max_iter=200)
        if not (st.converged and st.stable):
            continue
        ws[i] = st.w
        f_lj, f_el, f_ex = state_forces(pb, st)
        F[i] = f_ex
    return ds, F, time.perf_counter() - t0


def point(sigma_nm, rel, h0_nm, runner_value, runner_note, out):
    scene = scene_at(sigma_nm, rel)
    a_run = scene.discretisation.analysis_radius
    h0 = h0_nm * 1e-9
    # 1. pilot: node k at 1 um, analysis radius a_run (lam >= 1 above 1 um)
    t0 = time.perf_counter()
    pilot_ref = 1e-6
    brp, pil, _ = trace(scene, pilot_ref, h0, h0, 2 * a_run, a_run, 0.5 * pilot_ref,
                        8 * pilot_ref)
    t_pilot = time.perf_counter() - t0
    c_star, c_fold = pil.best.c, pil.fold.c
    a0 = a_run * c_star / (LOW * c_fold)
    out.append(f"\n## sigma = {sigma_nm} nm, p/psat {rel}\n")
    out.append(f"Pilot (h0 = {h0_nm} nm at c = 1 um, {brp.n} nodes, {t_pilot:.2f} s): fold "
               f"c_f = {c_fold * 1e6:.4f} um, largest force at c* = {c_star * 1e6:.4f} um. "
               f"Family: node k at c*, analysis radius a0 = {a0 * 1e6:.2f} um (the runner's "
               f"{a_run * 1e6:.2f} um reached at {LOW} c_f), half-width {HALF} h0, grading "
               f"{GRADING} h0.\n")
    out.append("| h (nm) at c* | nodes | states (solves) | factorisations | wall (s) | "
               "max adhesion (N) | d at max (nm) | c at max (um) | pull-off fold d (nm) | "
               "fold c (um) | worst multiplier / max | worst free gap - sigma (sigma) |")
    out.append("|---|---|---|---|---|---|---|---|---|---|---|---|")
    hs, Fs, runs, total = [], [], [], 0.0
    for j in range(LEVELS):
        h = h0 / math.sqrt(2) ** j
        br, r, wall = trace(scene, c_star, h, h0, a0, a_run, c_fold, 3 * c_star)
        total += wall
        hs.append(h)
        Fs.append(r.max_adhesion)
        runs.append((br, r))
        p, g = r.worst_complementarity
        out.append(f"| {h * 1e9:.4g} | {br.n} | {len(r.states)} ({r.n_solves}) | "
                   f"{r.n_factor} | {wall:.2f} | {r.max_adhesion:.7e} | {r.best.d * 1e9:.5f} | "
                   f"{r.best.c * 1e6:.4f} | {r.fold.d * 1e9:.5f} | {r.fold.c * 1e6:.4f} | "
                   f"{p:.3f} | {g:.3g} |")
        print(f"  sigma {sigma_nm} rel {rel} h {h * 1e9:.3g} nm n {br.n} "
              f"F {r.max_adhesion:.7e} ({wall:.2f} s)", file=sys.stderr)
    p3, ext, err = richardson(hs, Fs)
    pf, extf, errf = richardson(hs, [r.fold.d for _, r in runs])
    out.append("")
    out.append(f"Richardson (three finest, ratio sqrt2): observed order {p3:.2f}, max adhesion "
               f"**{ext:.6e} N**, estimated error of the finest member {err:.2e} N "
               f"(**{err / ext:.1e} relative**); pull-off separation {extf * 1e9:.5f} nm "
               f"(order {pf:.2f}, error {errf * 1e9:.1e} nm). The whole family "
               f"({LEVELS} members, {brp.n}-{runs[-1][0].n} nodes): **{total:.1f} s**, "
               f"the pilot {t_pilot:.2f} s.")
    mid = LEVELS // 2
    ratios = [(Fs[i] - Fs[i + 1]) / (Fs[i + 1] - Fs[i + 2]) for i in range(LEVELS - 2)]
    out.append("Successive difference ratios (sqrt2^p; 1.41 = first order, 2 = second): "
               + ", ".join(f"{x:.3f}" for x in ratios) + ".")
    # the estimate of a coarser triple against its finest member's actual error (the
    # finest triple's extrapolation as the truth): the effectivity a loop stopping there has
    eff = []
    for j in range(LEVELS - 3):
        _, e_j, err_j = richardson(hs[:j + 3], Fs[:j + 3])
        actual = abs(Fs[j + 2] - ext)
        eff.append(f"h = {hs[j + 2] * 1e9:.3g} nm: estimated {err_j / ext:.1e}, actual "
                   f"{actual / ext:.1e} (effectivity {err_j / actual:.2f})")
    out.append("Richardson of the coarser triples (estimate of their finest member against "
               "its error from the finest extrapolation): " + "; ".join(eff) + ".")
    if runner_value is not None:
        out.append(f"The runner: {runner_value:.6e} N ({runner_note}): "
                   f"{(runner_value - ext) / ext:+.2e} relative to the extrapolation.")
    else:
        out.append(f"The runner: {runner_note}.")
    # 3. the runner's equations at three states of the middle member
    br, r = runs[mid]
    deep = r.states[-1]
    out.append(f"\nThe runner's equations on the scaled grids of the member h = "
               f"{hs[mid] * 1e9:.4g} nm ({br.n} nodes; operator built afresh on the scaled "
               f"nodes, sub-grid capillary step):\n")
    out.append("| state | c (um) | d (nm) | residual of eq 6 (m) | worst multiplier / max | "
               "worst free gap - sigma (sigma) | stable (runner's test) | runner's Newton from "
               "it: iterations, converged | largest move of w (m) | contact set kept |")
    out.append("|---|---|---|---|---|---|---|---|---|---|")
    checks = []
    for name, st in (("pull-off fold", r.fold), ("largest force", r.best), ("deepest", deep)):
        ck = check_runner_equations(scene, br, st)
        checks.append(ck)
        out.append(f"| {name} | {ck['c'] * 1e6:.4f} | {ck['d'] * 1e9:.5f} | "
                   f"{ck['residual']:.2e} | {ck['compl'][0]:.3f} | {ck['compl'][1]:.3g} | "
                   f"{ck['stable']} | {ck['runner_iter']}, {ck['runner_converged']} | "
                   f"{ck['move']:.1e} | {ck['active_same']} |")
    # 4. the runner's curve on a fixed grid of the same density
    ds, F, t_scan = fixed_grid_scan(scene, br, r, a_run)
    ok = np.isfinite(F)
    i = int(np.nanargmax(F))
    out.append(f"\nThe runner's solver on the fixed grid of that member (node k at c*, "
               f"{int((br.nodes0 < a_run).sum())} nodes, its analysis radius cut to "
               f"{a_run * 1e6:.2f} um): F_ex at {ok.sum()}/{ds.size} separations within "
               f"+-0.04 nm of the branch's d* ({t_scan:.1f} s): largest **{F[i]:.7e} N** at "
               f"d = {ds[i] * 1e9:.5f} nm; the branch on the same grid family member "
               f"{Fs[mid]:.7e} N ({(F[i] - Fs[mid]) / Fs[mid]:+.1e} relative; the member's "
               f"own error against the extrapolation {(Fs[mid] - ext) / ext:+.1e}).")
    return {"sigma": sigma_nm, "rel": rel, "ext": ext, "err": err, "total": total,
            "checks": checks, "scan": (ds, F), "nodes": [b.n for b, _ in runs],
            "F": Fs, "h": hs, "fold": extf}


#: the map's axes (validation/stiction_map.py's MAP)
MAP_SIGMA = np.linspace(0.3, 2.0, 10)
MAP_REL = np.linspace(0.05, 0.95, 10)
#: the map scan's family: members h0 / sqrt2^j, j < MAP_LEVELS (h0 the route's pilot's)
MAP_LEVELS = 3


def runner_map(path=RESULTS / "stiction_map.md"):
    """The runner's max adhesion / 4 pi R gamma from stiction_map.md's table, by (sigma nm
    rounded to 2 decimals, p/psat rounded to 2), nan where it failed."""
    out, sig = {}, None
    for line in path.read_text().splitlines():
        if line.startswith("| p/psat"):
            sig = [float(x) for x in line.split("|")[2:-1]]
        elif sig and line.startswith("| 0."):
            cells = line.split("|")[1:-1]
            rel = float(cells[0])
            for s_, v in zip(sig, cells[1:]):
                out[round(s_, 2), round(rel, 2)] = float(v)
    return out


def map_point(sigma_nm, rel):
    """One map point as a run of the scene takes the edge route: the route's pilot
    (:func:`femadh.runner.edge_route.pilot`, c_ref from JKR's radius, spacing c_ref / 250:
    ~1 um and ~4 nm here), then MAP_LEVELS members at c* (:func:`~femadh.runner.edge_route.
    family`, no target: all of them) and Richardson from the three finest. Returns a dict
    (or the reason it could not)."""
    scene = scene_at(sigma_nm, rel)
    t0 = time.perf_counter()
    try:
        pil = pilot(scene)
        if pil is None:
            text = (f"no fold at c >= {pilot_low(scene) * 1e6:.3f} um (the contact shrinks "
                    "without a jump)")
            return {"reason": text, "kind": "no fold", "time": time.perf_counter() - t0}
        fam = family(scene, pil, 0.0, max_levels=MAP_LEVELS)
        worst = [min(r.worst_complementarity[0] for _, r in fam.runs),
                 min(r.worst_complementarity[1] for _, r in fam.runs)]
        r = fam.finest[1]
    except Exception as exc:          # the point's reason, kept for the table
        return {"reason": f"{type(exc).__name__}: {exc}"[:160], "kind": "failed",
                "time": time.perf_counter() - t0}
    return {"F": fam.extrapolation, "err": fam.error / fam.extrapolation, "order": fam.order,
            "c_star": pil.c_star, "c_fold": pil.c_fold, "d_star": r.best.d,
            "at_fold": r.at_fold, "nodes": fam.nodes, "worst": worst,
            "time": time.perf_counter() - t0}


def pilot_low(scene):
    """The pilot's smallest edge radius (m)."""
    from femadh.runner.edge_route import PILOT_SPAN, pilot_radius

    return pilot_radius(scene) / PILOT_SPAN


def map_scan(out):
    """The whole stiction map by the edge branch, against the runner's map."""
    ref = runner_map()
    t0 = time.perf_counter()
    rows = []
    for s_ in MAP_SIGMA:
        for rel in MAP_REL:
            r = map_point(round(float(s_), 4), round(float(rel), 2))
            rows.append((float(s_), float(rel), r))
            print(f"  map sigma {s_:.3f} rel {rel:.2f}: "
                  + (f"{r['F']:.6e} ({r['err']:.1e}, {r['time']:.1f} s)" if "F" in r
                     else r["reason"]), file=sys.stderr)
    wall = time.perf_counter() - t0
    scene = scene_at(0.3, 0.95)
    norm = 4 * math.pi * scene.sphere.radius * scene.effects["capillary"].surface_tension
    ok = [r for *_, r in rows if "F" in r]
    out.append("\n## The whole stiction map by the edge branch\n")
    out.append(f"Each point: the edge route's pilot (c_ref = JKR's radius / 4, ~1 um; h = "
               f"c_ref / 250, ~4 nm), then "
               f"{MAP_LEVELS} members h / sqrt2^j at c* and Richardson "
               f"from the three finest (as above). One process: **{wall:.0f} s for "
               f"{len(rows)} points** ({len(ok)} traced; the runner's map: 639.9 s on 2 "
               f"processes, 10 refused or failed). Columns: the branch's max adhesion / "
               f"4 pi R gamma (Richardson), its estimated relative error, the runner's map "
               f"value (3 digits, stiction_map.md) and their relative difference, the "
               f"observed order, c* and the fold's c, whether the largest force is the fold's, "
               f"the worst multiplier / max and free gap - sigma (sigma) on the branch, "
               f"nodes, seconds.\n")
    nofold = [r for *_, r in rows if r.get("kind") == "no fold"]
    failed = [r for *_, r in rows if r.get("kind") == "failed"]
    diffs = [abs(ref.get((round(s_, 2), round(rel, 2)), math.nan) * norm - r["F"]) / r["F"]
             for s_, rel, r in rows if "F" in r]
    diffs = [x for x in diffs if math.isfinite(x)]
    out.append(f"Traced: {len(ok)} points, largest estimated relative error "
               f"{max(r['err'] for r in ok):.1e} (median "
               f"{float(np.median([r['err'] for r in ok])):.1e}), "
               f"{sum(r['time'] for r in ok):.0f} s in all; against the runner's 3-digit "
               f"values where it has one ({len(diffs)} points): largest difference "
               f"{max(diffs):.1e} relative (the table's rounding: up to 5e-4 / value). "
               f"No fold of d(c) above the pilot's smallest edge radius: {len(nofold)} points "
               f"(the contact shrinks to nothing without a jump, DMT's side; the largest "
               f"force is then where the contact vanishes or on the separated branch, which "
               f"this continuation does not trace). Other failures: {len(failed)}.\n")
    out.append("| sigma (nm) | p/psat | branch | est. rel. error | runner | diff | order | "
               "c* (um) | c_fold (um) | max at fold | worst p / max | worst gap | nodes | s |")
    out.append("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for s_, rel, r in rows:
        rv = ref.get((round(s_, 2), round(rel, 2)), math.nan)
        if "F" not in r:
            out.append(f"| {s_:.3f} | {rel:.2f} | {r['reason']} | | {rv:.3f} | | | | | | | | "
                       f"| {r['time']:.1f} |")
            continue
        f = r["F"] / norm
        out.append(f"| {s_:.3f} | {rel:.2f} | {f:.4f} | {r['err']:.1e} | {rv:.3f} | "
                   f"{(rv - f) / f:+.1e} | {r['order']:.2f} | {r['c_star'] * 1e6:.3f} | "
                   f"{r['c_fold'] * 1e6:.3f} | {r['at_fold']} | {r['worst'][0]:.3f} | "
                   f"{r['worst'][1]:.2g} | {r['nodes'][0]}-{r['nodes'][-1]} | "
                   f"{r['time']:.1f} |")
    return rows


def main():
    import os

    load = os.getloadavg()
    out = ["# The sigma-gap retract traced in its edge radius (issue 21, goal 1; branch "
           "`sigedge`)", "",
           f"`python -m validation.sigma_edge` (module femadh/contact/sigma_edge.py). Machine: "
           f"2 cores shared with other sessions, load (1/5/15 min) {load[0]:.1f} / "
           f"{load[1]:.1f} / {load[2]:.1f} at the start; one BLAS thread. Times are wall "
           f"seconds of this process under that load (counts are exact)."]
    rows = []
    for args in POINTS:
        rows.append(point(*args, out))
    out.append("\n## Summary\n")
    out.append("| sigma (nm) | p/psat | max adhesion, Richardson (N) | estimated relative error "
               "| family's time (s) | nodes | the runner now |")
    out.append("|---|---|---|---|---|---|---|")
    now = {0.95: "1362 s wall / 275 CPU-s (1.45e-3; accuracy 3e-3 asked)",
           0.05: "1100 s (8.8e-3)",
           0.15: "469 s (1.4e-2); 1473 s to 8.7e-4"}
    for r in rows:
        out.append(f"| {r['sigma']} | {r['rel']} | {r['ext']:.6e} | {r['err'] / r['ext']:.1e} "
                   f"| {r['total']:.1f} | {r['nodes'][0]}-{r['nodes'][-1]} | "
                   f"{now[r['rel']]} |")
    if "--points-only" not in sys.argv:
        map_scan(out)
    out.append(NOTES)
    RESULTS.mkdir(exist_ok=True)
    text = "\n".join(out) + "\n"
    (RESULTS / "sigma_edge.md").write_text(text)
    print(text)


if __name__ == "__main__":
    main()
