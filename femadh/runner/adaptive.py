"""The adaptive grid: a contact run whose nodes follow the contact and answer to the estimate.

A scene that fixes neither ``[solver] nodes`` nor ``[solver.grid]`` (Green method,
complementarity sigma-gap or smooth laws) gets a banded grid planned from its laws and sweep
(:func:`femadh.discretisation.plan_grid`: the band where the gaps reach the laws' features,
an analysis radius whose tail is negligible), its band spacing capped so that neither it nor
the coarser members of its estimate are lattice-trapped, and then refined by the estimate
until the headline numbers meet ``[solver] accuracy`` (default 1e-3):

    h <- h * clamp((SAFETY * target / error)^(1/ORDER), MIN_FACTOR, MAX_FACTOR)

A failed solve (a node snapping on its own, a stalled continuation, a landing after a fold
that Newton cannot polish) halves h, a contact reaching the analysis radius doubles it, a
feature that left the band widens the band, and members that all fail refine h: each while
the budget (MAX_TRIALS runs, MAX_NODES nodes) lasts. The result says what was
chosen and every trial (``result.accuracy``), or fails naming the accuracy reached, the nodes
it used and about how many the request would need.
"""
import math
import time

import numpy as np

from ..discretisation import GridFamily, plan_grid
from ..discretisation.family import MAX_NODES
from ..discretisation.plan import safe_spacing

#: runs (refinements + 1) an adaptive run may make
MAX_TRIALS = 5
#: the refined spacing aims at this fraction of the target (the order is only estimated)
SAFETY = 0.6
#: assumed convergence order of the headline numbers in the band spacing (local orders
#: 1.2-2.2 on the Fig 3 scene's family; the estimate's envelope order)
ORDER = 1.5
#: limits of one refinement factor of h
MIN_FACTOR, MAX_FACTOR = 0.3, 0.8
#: the accuracy the plan's BAND_NODES are sized for; the fewest nodes across any band
REFERENCE_ACCURACY, MIN_BAND_NODES = 1e-3, 48
#: a feature beyond this fraction of the band radius widens the band
BAND_FILL = 0.97


def _relative(res):
    from .accuracy import _relative as rel

    return rel(res)


def _feature_radius(res, problem_shape, gap):
    """Largest radius (m) where a kept surface profile's gap is at most ``gap``."""
    out = 0.0
    for prof in res.profiles.values():
        for i, (d, w) in enumerate(zip(prof["d_m"], prof["w_m"])):
            nodes = np.asarray(prof["r_m"][i], float) if "r_m" in prof else res.nodes
            h = d + problem_shape(nodes) - w
            close = np.flatnonzero(h <= gap)
            if close.size:
                out = max(out, float(nodes[close[-1]]))
    for c in res.branches.values():
        if len(c.get("r_c_m", ())):
            out = max(out, float(np.max(c["r_c_m"])))
    return out


def _capped(scene, family, spacing):
    """(spacing, operator, problem) with the spacing capped below the trapping-safe one of
    the family (two passes: the ratio is measured on the member itself)."""
    from ..elastic import GreenOperator
    from ..scene import build_problem

    op = problem = None
    for _ in range(3):
        op = GreenOperator(family.member(spacing), scene.e_star)
        problem = build_problem(scene, operator=op)
        safe = safe_spacing(problem)
        if spacing <= safe:
            break
        spacing = 0.98 * safe
    return spacing, op, problem


def run_adaptive(scene, out_dir, *, run, figures=True, progress=None, overwrite=False,
                 resume=False, estimate=True):
    """Run ``scene`` on its adaptive grid (see the module docstring) with ``run``
    (:func:`femadh.runner.run.run`); with ``estimate`` not True, one run on the planned
    member (its accuracy unjudged)."""
    from ..io.progress import phase
    from ..scene import scene_id
    from .estimates import variant

    t0 = time.perf_counter()
    target = scene.target_accuracy
    plan = plan_grid(scene.effects, None if scene.gap is None else scene.gap.sigma,
                     scene.sphere, scene.analysis_radius,
                     scene.d_values, target)
    # the first member: BAND_NODES across the band at 1e-3, coarser for a looser request
    family = plan.family
    h = min(plan.spacing * (target / REFERENCE_ACCURACY) ** (1.0 / ORDER),
            family.band / MIN_BAND_NODES)
    mode = {"overwrite": overwrite, "resume": resume}
    steps, res, trial = [], None, None
    failure = None
    for i in range(MAX_TRIALS):
        try:
            h, op, _ = _capped(scene, family, h)
        except ValueError:
            failure = (f"the grid would need more than {MAX_NODES} nodes (band spacing "
                       f"{h * 1e9:.3g} nm over {family.band * 1e6:.3g} um)")
            break
        trial = variant(scene, grid=family.as_dict(h), radius=family.radius)
        with phase(f"{'refinement ' + str(i) if i else 'grid'} ({op.grid.n} nodes)"):
            res = run(trial, out_dir, figures=False, progress=progress, estimate=estimate,
                      operator=op, folder_id=scene_id(scene), **mode)
        mode = {"overwrite": True, "resume": False}      # later trials replace earlier ones
        grid_e, tail_e = (_relative(res) if res.status == "converged" and estimate is True
                          else (math.nan, math.nan))
        steps.append({"nodes": op.grid.n, "spacing_m": h, "band_m": family.band,
                      "analysis_radius_m": family.radius, "status": res.status,
                      "grid_rel_error": grid_e, "tail_rel_error": tail_e,
                      "wall_time_s": res.wall_time})
        if res.status == "interrupted" or estimate is not True:
            break
        if res.status != "converged":
            err_text = res.error or ""
            if "analysis radius" in err_text:
                # the contact reached the disk's edge: a larger disk, the same band spacing
                family = GridFamily(2 * family.radius, family.band, family.grading)
            else:
                # lattice trapping, a stalled continuation, a landing Newton could not polish
                # after a fold: the discretisation's failures, which a finer member resolves
                h *= 0.5
            steps[-1]["refined_after"] = err_text
            continue
        edge = _feature_radius(res, trial.sphere.shape, plan.feature_gap)
        if edge > BAND_FILL * family.band and family.band < family.radius:
            # the feature left the band: widen it (the spacing stays)
            family = GridFamily(family.radius, min(family.radius, 1.2 * edge / BAND_FILL),
                                family.grading)
            steps[-1]["band_left_m"] = edge
            continue
        judged = len(res.grid.get("members", ()))
        if judged == 0:
            # no coarser member converged (a stalled landing at a meniscus edge, trapping):
            # the grid error is unknown, so the result cannot be called converged; a finer
            # family has finer members
            steps[-1]["members_failed"] = True
            h *= MAX_FACTOR
            continue
        err = grid_e + tail_e
        if err <= target:
            break
        if tail_e > SAFETY * target:
            # the force beyond the disk: a finer spacing cannot help, a larger disk can -
            # unless it would reach the sphere's own size (eq 4's paraboloid is a sphere only
            # for r << R; a small tip keeps its tail as F_tail and this part of the estimate)
            cap = (0.5 if scene.sphere.profile == "sphere" else 1.0) * scene.sphere.radius
            if 2 * family.radius < cap:
                family = GridFamily(2 * family.radius, family.band, family.grading)
                steps[-1]["tail_grew_radius"] = True
                continue
            failure = (f"the force beyond the analysis radius alone is {tail_e:.2g} relative "
                       f"and the radius cannot grow (it would reach the sphere's radius "
                       f"{scene.sphere.radius * 1e9:.4g} nm); the grid part is {grid_e:.2g}")
            break
        factor = (SAFETY * target / err) ** (1.0 / ORDER) if err > 0 else MIN_FACTOR
        h *= min(MAX_FACTOR, max(MIN_FACTOR, factor))
    met = bool(res is not None and res.status == "converged" and estimate is True and steps
               and not steps[-1].get("members_failed")
               and steps[-1]["grid_rel_error"] + steps[-1]["tail_rel_error"] <= target)
    if res is None:
        from .result import ContactResult

        res = ContactResult(scene.name, scene, status="failed")
    last = steps[-1] if steps else {}
    res.accuracy = {"target": target, "met": met, "adaptive": True,
                    "nodes": last.get("nodes"), "spacing_m": last.get("spacing_m"),
                    "band_m": last.get("band_m"),
                    "analysis_radius_m": last.get("analysis_radius_m"), "steps": steps,
                    "feature_gap_m": plan.feature_gap,
                    "wall_time_s": time.perf_counter() - t0}
    if failure and res.status == "converged" or failure and not steps:
        res.status, res.error = "failed", f"accuracy {target:g} not met: {failure}"
    elif not met and res.status == "converged" and estimate is True and \
            last.get("members_failed"):
        res.status = "failed"
        res.error = (f"accuracy {target:g} not judged: no coarser member of the grid family "
                     f"converged after {len(steps)} runs (last: {last['nodes']} nodes, band "
                     f"spacing {last['spacing_m'] * 1e9:.3g} nm); see the warnings")
    elif not met and res.status == "converged" and estimate is True:
        reached = last["grid_rel_error"] + last["tail_rel_error"]
        need = _nodes_needed(family, last["spacing_m"], reached, target)
        res.status = "failed"
        res.error = (f"accuracy {target:g} not met: estimated relative error {reached:.2g} "
                     f"with {last['nodes']} nodes after {len(steps)} runs "
                     f"({res.accuracy['wall_time_s']:.3g} s); the request needs about "
                     f"{need} nodes (budget: {MAX_TRIALS} runs, {MAX_NODES} nodes)")
    res.timings["adaptive_total_s"] = time.perf_counter() - t0
    if out_dir is not None and trial is not None:
        from ..io.run_folder import RunFolder
        from .result import contact_summary as summary

        # the last trial's outputs stay; its summary gains the accuracy record, its figures
        with RunFolder(out_dir, scene_id(scene), scene.name, "amend") as folder:
            if figures and res.status in ("converged", "failed") and res.branches and any(
                    len(next(iter(b.values()))) for b in res.branches.values()):
                from .figures import draw_figures

                # a signal stops the figures at once: the run ends "interrupted"
                with phase("figures"):
                    draw_figures(res, folder)
            folder.write_summary(summary(res))
    return res


def _nodes_needed(family, spacing, reached, target):
    """About how many nodes the family's member meeting ``target`` has (order ORDER)."""
    if not (reached > 0 and math.isfinite(reached)):
        return "an unknown number of"
    h = spacing * (target / reached) ** (1.0 / ORDER)
    return str(family.count(h))
