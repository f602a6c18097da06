"""Run a scene: build the problem, trace its branches, stream results to disk, draw figures."""
from dataclasses import dataclass, field
import sys
import time
import warnings

import numpy as np

from .._version import __version__
from ..contact import Jump, State, Sweep, trace
from ..contact.forces import state_forces
from ..errors import ConvergenceError, MeshResolutionWarning
from ..io.writers import SIGN_NOTE, RunWriter, write_json
from ..scene import Scene, build_problem, load_scene


#: surface-force stiffness over single-node stiffness above which a run warns
STIFFNESS_WARNING = 0.5


@dataclass
class RunResult:
    """What :func:`run` returns.

    Attributes
    ----------
    scene : Scene
    problem : ContactProblem
    sweeps : dict[str, Sweep]
        ``"approach"`` / ``"retract"`` branches, each with its states and jumps.
    status : str
        ``"converged"`` or ``"failed"`` (then ``error`` holds the message).
    wall_time : float
        Seconds for the whole run, output included.
    out_dir : str or None
    """

    scene: Scene
    problem: object
    sweeps: dict = field(default_factory=dict)
    status: str = "converged"
    error: str | None = None
    wall_time: float = 0.0
    out_dir: str | None = None
    stiffness_ratio: float = 0.0

    def curve(self, branch):
        """Arrays d, h0, F_LJ, F_el, F_ex, r_c (SI) of one branch."""
        states = self.sweeps[branch].states
        f = np.array([state_forces(self.problem, s) for s in states]).reshape(-1, 3)
        return {"d": np.array([s.d for s in states]), "h0": np.array([s.h0 for s in states]),
                "F_LJ": f[:, 0], "F_el": f[:, 1], "F_ex": f[:, 2],
                "r_c": np.array([s.r_c for s in states])}

    @property
    def jumps(self):
        return [j for sw in self.sweeps.values() for j in sw.jumps]


def _progress_bar(total, label, enabled):
    if not enabled:
        return None
    try:
        from tqdm import tqdm
    except ImportError:
        return None
    return tqdm(total=total, desc=label, unit="step", leave=False, file=sys.stderr)


def run(scene, out_dir=None, *, write=True, figures=True, progress=None):
    """Solve a scene's force-separation sweep.

    Parameters
    ----------
    scene : Scene or str or Path
        A loaded scene or the path of its TOML file.
    out_dir : str, optional
        Output folder (default: the scene's ``[output] dir``).
    write : bool
        Stream curve/diagnostics/fields csv and summary.json to ``out_dir``.
    figures : bool
        Draw the Fig 3-style panels (PNG) after the sweep.
    progress : bool, optional
        Progress bar on stderr; default: only when stderr is a terminal.

    Returns
    -------
    RunResult
        Also when a step fails to converge: then ``status == "failed"``, ``error`` says where,
        and every state computed before it is in the result and on disk.
    """
    if not isinstance(scene, Scene) and not hasattr(scene, "p_ratios"):
        scene = load_scene(scene)
    if hasattr(scene, "p_ratios"):  # a [meniscus] scene (paper 2)
        from .meniscus import run_meniscus

        return run_meniscus(scene, out_dir, write=write, figures=figures)
    t0 = time.perf_counter()
    if progress is None:
        progress = sys.stderr.isatty()
    say = (lambda msg: print(msg, file=sys.stderr)) if progress else None
    problem = build_problem(scene, progress=say)
    ratio, h_at, soft, k_node = problem.surface_force_stiffness()
    if ratio > STIFFNESS_WARNING:
        warnings.warn(
            f"{scene.path or scene.name}: the surface forces' stiffness -dP/dh = {soft:.3g} Pa/m "
            f"at h = {h_at * 1e9:.3g} nm is {ratio:.2f} x the stiffness of one surface node "
            f"({k_node:.3g} Pa/m): single nodes can snap on their own and the result depends on "
            f"the mesh. Use [solver] nodes >= {int(scene.nodes * ratio / STIFFNESS_WARNING) + 1}.",
            MeshResolutionWarning, stacklevel=2)
    result = RunResult(scene, problem, out_dir=(out_dir or scene.output_dir) if write else None)
    result.stiffness_ratio = ratio
    writer = RunWriter(result.out_dir, problem, vtk=scene.vtk) if write else None
    d = scene.d_values
    plan = []
    if "approach" in scene.directions:
        plan.append(("approach", d))
        if "retract" in scene.directions:
            plan.append(("retract", d[::-1]))
    else:
        plan.append(("retract", d))
    if scene.continuation == "arclength":
        _run_arclength(scene, problem, result, writer, progress)
        plan = []
    start = None
    try:
        for branch, d_vals in plan:
            bar = _progress_bar(len(d_vals) - 1, f"{scene.name} {branch}", progress)
            on_state = (lambda s, b=branch: writer.write_state(b, s)) if writer else None
            try:
                sweep = trace(problem, d_vals, branch=branch, tol=scene.tolerance, start=start,
                              max_iter=scene.max_iter, on_state=on_state,
                              progress=(lambda k, bar=bar: bar.update(1)) if bar else None)
            finally:
                if bar:
                    bar.close()
            result.sweeps[branch] = sweep
            start = sweep.states[-1]
    except ConvergenceError as exc:
        result.status, result.error = "failed", str(exc)
        partial = getattr(exc, "sweep", None)
        if partial is not None and partial.states:
            result.sweeps[partial.branch] = partial
    result.wall_time = time.perf_counter() - t0
    if writer:
        writer.close()
        write_json(f"{result.out_dir}/summary.json", _summary(result))
        if figures and result.sweeps:
            from ..io.plots import paper1_panels
            paper1_panels(result, f"{result.out_dir}/fig3_panels.png")
    return result


def _curve_state(problem, d, w, stable):
    """A State for a point of an arclength curve (smooth laws: no contact pressure)."""
    h = problem.contour(d) - w
    n = w.size
    res = float(np.max(np.abs(w - problem.C @ problem.pressure(h))))
    return State(d, w, h, {k: e.pressure(h) for k, e in problem.effects.items()}, np.zeros(n),
                 np.zeros(n, bool), 0.0, 0, res, True, stable)


def _run_arclength(scene, problem, result, writer, progress):
    """Trace the scene's equilibrium curve by arclength; write its paths as branches.

    The whole curve (unstable states included) goes to equilibrium_curve.csv; the
    displacement-controlled approach and retract paths, with their jumps, go to curve.csv as
    with the stepping solver. On failure the part of the curve traced so far is written.
    """
    from ..contact.arclength import trace_curve

    d = scene.d_values
    step = abs(d[1] - d[0])
    bar = _progress_bar(100, f"{scene.name} arclength", progress)
    last = [0]

    def tick(frac):
        k = int(100 * frac)
        if bar and k > last[0]:
            bar.update(k - last[0])
            last[0] = k
    curve = None
    try:
        curve = trace_curve(problem, d[0], d[-1], tol=scene.tolerance, scale=step, ds=1.0,
                            ds_max=1.0, progress=tick)
    except ConvergenceError as exc:
        result.status, result.error = "failed", str(exc)
        curve = getattr(exc, "curve", None)
    finally:
        if bar:
            bar.close()
    if curve is None:
        return
    if writer:
        writer.write_equilibrium_curve(curve.points,
                                       [_curve_state(problem, p.d, p.w, p.stable)
                                        for p in curve.points])
    if result.status != "converged":
        return
    for branch in scene.directions:
        sweep = Sweep(branch, n_solves=curve.n_solves)
        before = None
        for kind, dk, wk in curve.branch(branch):
            st = _curve_state(problem, dk, wk, True)
            if kind == "fold":
                before = st
                continue        # the fold state is the jump's 'before', not a grid state
            if kind == "land":
                sweep.jumps.append(Jump(branch, dk, dk, 0.0, before, st))
            sweep.states.append(st)
            if writer:
                writer.write_state(branch, st)
        sweep.wall_time = curve.wall_time
        result.sweeps[branch] = sweep


def _summary(result):
    scene = result.scene
    jumps = [{"branch": j.branch, "d_fold_m": j.d_fold, "d_land_m": j.d_land,
              "resolution_m": j.resolution,
              "F_ex_before_N": state_forces(result.problem, j.before)[2],
              "F_ex_after_N": state_forces(result.problem, j.after)[2],
              "h0_before_m": j.before.h0, "h0_after_m": j.after.h0} for j in result.jumps]
    branches = {}
    for b, sw in result.sweeps.items():
        c = result.curve(b)
        k = int(np.argmax(c["F_ex"]))
        branches[b] = {"n_states": len(sw.states), "n_solves": sw.n_solves,
                       "wall_time_s": sw.wall_time, "max_F_ex_N": float(c["F_ex"][k]),
                       "d_at_max_F_ex_m": float(c["d"][k]),
                       "all_converged": all(s.converged for s in sw.states),
                       "all_stable": all(s.stable for s in sw.states)}
    return {"femadh_version": __version__, "scene_file": scene.path,
            "status": result.status, "error": result.error, "sign_convention": SIGN_NOTE,
            "scene": scene.resolved, "branches": branches, "jumps": jumps,
            "surface_force_stiffness_over_node_stiffness": result.stiffness_ratio,
            "operator": {"name": result.problem.operator.name,
                         "timings_s": getattr(result.problem.operator, "timings", {}),
                         "n_dofs": getattr(result.problem.operator, "n_dofs", None)},
            "wall_time_s": result.wall_time}
