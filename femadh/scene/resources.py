"""What a scene needs beyond valid keys: its optional dependencies and its memory, checked
before anything is computed (``femadh check`` and every run)."""
import importlib.util
import os

from ..errors import DependencyError, SceneError

#: dense N x N float64 arrays a Green contact run holds at once (compliance, stiffness, the
#: symmetric S, the stability certificate's R^-1 and its cumulated squares, the corrector's
#: Jacobian and factorisations, the carried state's factor, a landing's Hessian copies).
#: Measured (tracemalloc, peak traced memory of a whole Fig 4 run on a fixed grid over
#: 8 N^2 bytes): 11.0 at N = 2624 (the peak in the corrector's LU step), 13.7 at N = 1312
#: (in a landing's descent; the states' O(N) arrays weigh more there), with or without the
#: estimate's members; 8 understated it by 27-42 %
GREEN_ARRAYS = 11
#: FE: degrees of freedom per surface node at the default mesh (measured: 22k DOFs at N = 200),
#: and the dense condensation block (free DOFs x N) that dominates the memory
FE_DOFS_PER_NODE = 110
#: a scene may use at most this fraction of the machine's memory
MEMORY_FRACTION = 0.8


def physical_memory():
    """Bytes of RAM of this machine (None where the OS does not say)."""
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):
        return None


def memory_estimate(scene):
    """Bytes a contact scene's operator and solver hold (a lower bound), and what dominates."""
    n = scene.nodes
    if scene.grid is not None:
        from ..discretisation import GridFamily

        g = scene.grid
        n = GridFamily(scene.analysis_radius, g["band"], g["grading"]).count(g["spacing"])
    dense = GREEN_ARRAYS * 8.0 * n * n
    if scene.method == "fe":
        fe = 8.0 * FE_DOFS_PER_NODE * n * n * (0.5 / scene.fe_settings.surface_fraction) ** 2
        return dense + fe, f"{n} nodes: the FE condensation and {GREEN_ARRAYS} dense N x N arrays"
    return dense, f"{n} nodes: {GREEN_ARRAYS} dense N x N arrays"


def _missing(modules):
    return [m for m in modules if importlib.util.find_spec(m) is None]


def check_resources(scene):
    """Raise DependencyError for a missing optional dependency, SceneError for a size whose
    memory estimate exceeds the machine."""
    if scene.kind == "contact":
        need = {"fe": ("skfem", "gmsh", "meshio")}.get(scene.method, ())
        if scene.vtk:
            need = tuple(need) + ("meshio",)
        missing = _missing(need)
        if missing:
            raise DependencyError(
                f"{scene.path or scene.name}: [solver] method = '{scene.method}' needs "
                f"{', '.join(missing)}, which is not installed: pip install 'femadh[fe]'")
        mem, what = memory_estimate(scene)
        total = physical_memory()
        if total and mem > MEMORY_FRACTION * total:
            raise SceneError(scene.path, "solver.nodes", scene.nodes,
                             f"a size this machine can hold: {what} need about "
                             f"{mem / 2**30:.3g} GiB of its {total / 2**30:.3g} GiB")
    else:
        need = ("skfem",) if {"fe", "no-film"} & set(scene.methods) else ()
        missing = _missing(need + (("meshio",) if scene.vtk else ()))
        if missing:
            raise DependencyError(
                f"{scene.path or scene.name}: the meniscus methods or VTK output need "
                f"{', '.join(missing)}, which is not installed: pip install femadh")


#: Run-time model of a contact state on the Green (or condensed FE) operator:
#: t = STATE_N2 N^2 + STATE_N3 N^3 seconds per swept state (chord steps are N^2, the
#: occasional factorisation N^3). Measured on the CI machine class (2 cores, OpenBLAS on one
#: thread): the Fig 3 scene with uniform nodes, 72 states, --no-estimate, solve time / states
#: (validation of the model: 1.9 / 10.3 / 36.6 / 184 ms per state at N = 200 / 400 / 800 /
#: 1600; the two coefficients fitted to 800 and 1600, the model gives 1.9 / 8.0 ms at 200 /
#: 400; N = 3200, 3 states: 3.5 s measured, 6.2 s modelled). Remeasure: time femadh.run of
#: that scene at those N with estimate=False and divide solve_s by the states.
STATE_N2, STATE_N3 = 4.25e-8, 1.84e-11
#: a floor per state (Python overhead, the writers): 1.7 ms measured at N = 100
STATE_FLOOR = 1.7e-3
#: the first state is solved from a flat surface (an energy descent when Newton fails):
#: counted as this many states
FIRST_STATE = 3.0
#: FE operator build (condensation), seconds per surface node at the default mesh: 0.23 s at
#: N = 60, 0.90 s at N = 200 (linear in N to within 20 %)
FE_OPERATOR_PER_NODE = 4.5e-3
#: error estimate: the coarser members (N/2, N/4) and the peak search, relative to the run
#: (N^2-N^3 scaling: 1/4..1/8 + 1/16..1/64, the peak search ~10 states)
ESTIMATE_STATES = 10
#: a scene estimated beyond this many seconds (30 min) is refused unless the user insists
#: (--force)
MAX_REASONABLE_S = 1800.0
#: accuracy targets below this cannot be met within the node budget: the error falls like
#: h^1.5, 1e-3 needs ~600 nodes (README, "Accuracy"), so 1e-5 would need ~13 000 (budget:
#: femadh.runner.estimates.MAX_NODES = 3200)
MIN_REACHABLE_ACCURACY = 1e-5


#: meniscus scenes: seconds per p/psat point and method, measured on the bundled
#: paper2_ethanol_100nm scene (8 points, 16 elements; a loaded 2-core machine): FE 42 ms (it
#: scales with the elements: its estimate solves the meniscus again on half of them),
#: shooting 160 ms, no-film 19 ms, circular (closed form) < 0.2 ms
MENISCUS_POINT_S = {"fe": 2.6e-3, "shooting": 0.16, "no-film": 0.019, "circular": 2e-4}


def meniscus_time(scene):
    """Seconds a meniscus scene takes (the rates above) and what it counts."""
    per = sum(MENISCUS_POINT_S.get(m, 0.16) * (scene.elements if m == "fe" else 1)
              for m in scene.methods)
    n = len(scene.p_ratios) * len(scene.liquids) * len(scene.radii)
    return n * per, f"{n} p/psat points x {len(scene.methods)} methods"


def _state_time(n):
    return max(STATE_FLOOR, STATE_N2 * n * n + STATE_N3 * n ** 3)


def time_estimate(scene, first_nodes=None):
    """Seconds a contact run of the scene takes on this machine class, and the words that
    say what it counts. A rough figure, from the rates above: measured against the bundled
    scenes (idle 2-core machine) Fig 3 adaptive 1 s estimated / 0.5 s real, Fig 3 FE 1 s /
    2.2 s, uniform N = 400 1.0 s / 1.3 s; scenes whose sweep folds and jumps take many more
    solves per state (Fig 4: 1 s / 8.5 s, the mu = 2 arclength trace <1 s / 1.7 s) - an
    order of magnitude at most, which is what the refusal of absurd scenes needs.
    ``first_nodes``: an adaptive scene's first member as planned
    (:func:`femadh.runner.adaptive.planned_first_nodes`; else ~300, Fig 4's at 1e-3)."""
    n = scene.nodes
    if scene.grid is not None or getattr(scene, "adaptive", False):
        if scene.grid is not None:
            from ..discretisation import GridFamily

            g = scene.grid
            n = GridFamily(scene.analysis_radius, g["band"], g["grading"]).count(g["spacing"])
        else:
            n = first_nodes or 300      # the first member (~285-540 nodes on Fig 4)
    states = len(scene.d_values) * len(scene.directions)
    t_state = _state_time(n)
    t = (states + FIRST_STATE) * t_state
    if scene.method == "fe":
        t += FE_OPERATOR_PER_NODE * n
    members = (_state_time(n // 2) + _state_time(n // 4)) * (states + FIRST_STATE)
    t_est = t + members + ESTIMATE_STATES * t_state
    what = f"{states} states of {n} nodes"
    if getattr(scene, "adaptive", False) or scene.accuracy:
        what += ", the first grid of an accuracy run (refinements cost more)"
    return t_est, what


def check_cost(scene, force=False, first_nodes=None):
    """Refuse (SceneError) a contact scene whose estimated run time is beyond reason, or
    whose accuracy target the node budget cannot reach, unless ``force``. ``first_nodes``:
    (nodes, coarsest) of an adaptive scene's first member as planned
    (:func:`femadh.runner.adaptive.planned_first_nodes`): a request whose coarsest start
    exceeds the node budget is refused here, as the run would refuse it before any solve."""
    if force:
        return
    if scene.kind != "contact":
        t, what = meniscus_time(scene)
        if t > MAX_REASONABLE_S:
            raise SceneError(scene.path, "meniscus.relative_pressure", f"{len(scene.p_ratios)} "
                             "values", f"a scene that runs in reasonable time: {what} take "
                             f"about {_hms(t)} on this machine class; fewer points, or --force "
                             "to run it anyway")
        return
    if scene.accuracy is not None and scene.accuracy < MIN_REACHABLE_ACCURACY:
        from ..estimate.refine import BANDED_MAX_NODES, UNIFORM_MAX_NODES

        # the budget of the grid the request runs on: the adaptive (banded) family's, or the
        # uniform accuracy mode's where the scene gives its nodes (it said 3200 for both)
        budget = BANDED_MAX_NODES if getattr(scene, "adaptive", False) else UNIFORM_MAX_NODES
        raise SceneError(scene.path, "solver.accuracy", scene.accuracy,
                         f"a relative accuracy >= {MIN_REACHABLE_ACCURACY:g}: finer targets "
                         f"need more nodes than the budget ({budget}) allows (use --force to "
                         "try)")
    if first_nodes is not None:
        from ..estimate.refine import BANDED_MAX_NODES

        if first_nodes[1] > BANDED_MAX_NODES:
            raise SceneError(scene.path, "solver.accuracy", scene.target_accuracy,
                             f"an accuracy the node budget reaches: the adaptive grid's "
                             f"first member alone would need about {first_nodes[1]} nodes "
                             f"(budget {BANDED_MAX_NODES}); a looser accuracy")
    t, what = time_estimate(scene, first_nodes and first_nodes[0])
    if t > MAX_REASONABLE_S:
        key, value = ("solver.nodes", scene.nodes) if scene.grid is None else (
            "solver.grid", scene.grid)
        raise SceneError(scene.path, key, value,
                         f"a scene that runs in reasonable time: {what} take about "
                         f"{_hms(t)} on this machine class (femadh check estimates it); "
                         "fewer nodes or separations, or --force to run it anyway")


def _hms(t):
    if t < 1:
        return "<1 s"
    if t < 90:
        return f"{t:.0f} s"
    if t < 5400:
        return f"{t / 60:.0f} min"
    return f"{t / 3600:.1f} h"
