"""Accuracy on demand: ``[solver] accuracy = 1e-3`` asks the headline numbers (the largest
adhesion, the forces at the deepest separation) to a relative accuracy. femadh runs the scene,
estimates the errors (:mod:`femadh.runner.estimates`), and refines - more nodes where the grid
dominates, a larger analysis radius where the tail beyond it does, more nodes where a node
would snap alone - until the estimate meets the target, within a budget (the refine-until-met
loop of :mod:`femadh.estimate.refine`); the result says what was chosen and every step
(``result.accuracy``), or fails saying the target was not met."""
import math

from ..scene import scene_id
from ..estimate.refine import Budget, refine_until_met
from .estimates import MAX_NODES, MAX_REFINEMENTS, judged_errors, variant

#: the failure kind (``result.failure_kind``) a larger disk resolves: the contact reached
#: the analysis radius (a doubles, N doubles: the spacing stays)
REFINE_RADIUS = "analysis_radius"
#: the failure kinds more nodes resolve: a node snapping on its own (lattice trapping), a
#: largest adhesion beyond Derjaguin-Bradley's bound (too coarse for the surface forces)
REFINE_NODES = ("trapping", "bound")


def run_to_accuracy(scene, out_dir, *, run, figures=True, progress=None, overwrite=False,
                    resume=False):
    """Run ``scene`` (with ``run``, :func:`femadh.runner.run.run`) on ever finer grids
    until its estimated error meets ``scene.accuracy``; see the module docstring."""

    from ..io.progress import phase

    target = scene.accuracy
    budget = Budget(MAX_REFINEMENTS, MAX_NODES)
    mode = {"overwrite": overwrite, "resume": resume}
    records = []

    def attempt(setting):
        nodes, delta = setting
        trial = variant(scene, nodes=nodes, delta=delta)
        i = len(records)
        # claimed under the user's scene: --resume and --overwrite recognise the folder
        # whichever trial it holds
        with phase(f"{'refinement ' + str(i) if i else 'grid'} (N = {nodes})"):
            res = run(trial, out_dir, figures=figures, progress=progress, estimate=True,
                      folder_id=scene_id(scene), **mode)
        mode.update(overwrite=True, resume=False)    # later trials replace earlier ones
        grid, tail = judged_errors(res) if res.status == "converged" else (math.inf, 0.0)
        records.append({"nodes": nodes, "analysis_radius_m": trial.analysis_radius,
                        "status": res.status, "grid_rel_error": grid,
                        "tail_rel_error": tail, "wall_time_s": res.wall_time})
        why = None if res.status == "converged" else (res.error or res.status)
        return res, grid + tail, why

    def refine(setting, res, error, why):
        nodes, delta = setting
        if why is not None:
            # the failure's kind (its exception's type), never its words, picks the remedy
            kind = res.failure_kind
            if kind == REFINE_RADIUS:
                return 2 * nodes, 4 * delta
            if kind in REFINE_NODES:
                return 2 * nodes, delta
            return None                     # a failure refinement does not address
        grid, tail = records[-1]["grid_rel_error"], records[-1]["tail_rel_error"]
        if tail > target / 3:
            delta *= 4                      # a doubles; keep the spacing
            nodes *= 2
        if grid > 2 * target / 3:
            nodes = int(min(4 * nodes, math.ceil(nodes * max(2.0, 1.2 * grid
                                                                 / (2 * target / 3)))))
        return nodes, delta

    first = (scene.nodes, scene.analysis_radius**2 / (2 * scene.sphere.radius))
    out = refine_until_met(first, attempt, refine, target, budget,
                           nodes=lambda s, r, nxt: nxt[0])
    res, steps = out.result, records
    met = out.met
    res.accuracy = {"target": target, "met": met, "nodes": steps[-1]["nodes"],
                    "analysis_radius_m": steps[-1]["analysis_radius_m"], "steps": steps}
    if not met and res.status == "converged":
        res.status, res.failure_kind = "failed", "accuracy"
        res.error = (f"accuracy {target:g} not met: estimated relative error "
                     f"{steps[-1]['grid_rel_error'] + steps[-1]['tail_rel_error']:.2g} with "
                     f"N = {steps[-1]['nodes']} (the budget: N <= {budget.max_nodes}, "
                     f"{budget.max_refinements} refinements)")
    if out_dir is not None:
        from ..io.run_folder import RunFolder
        from .result import contact_summary as summary

        # the last trial's outputs stay; only its summary gains the accuracy record
        with RunFolder(out_dir, scene_id(scene), scene.name, "amend",
                       given=scene.as_given) as folder:
            folder.write_summary(summary(res))
    return res
