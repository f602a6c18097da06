"""What a scene needs beyond valid keys: its optional dependencies and its memory, checked
before anything is computed (``femadh check`` and every run)."""
import importlib.util
import os

from ..errors import DependencyError, SceneError

#: dense N x N float64 arrays a Green contact problem holds at once (compliance, stiffness,
#: S and its symmetric part, a factorisation and its Hessian copies)
GREEN_ARRAYS = 8
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
