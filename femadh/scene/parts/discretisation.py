"""The discretisation of a contact scene ([solver]): the elastic model and its grid or mesh,
and how the equilibria are solved, with the tables that describe their keys.

With the body (:mod:`.body`) it is everything the surface operator is built from
(:func:`femadh.scene.build.operator_from_parts`), so the pair's content hash is the key a
study reuses operators by.
"""
from dataclasses import dataclass

from ...schema import Key, Table
from ..reader import BAD
from .frozen import FrozenMap, frozen_map

METHODS = ("green", "fe")
#: relative accuracy of the headline numbers an adaptive run meets unless the scene asks
DEFAULT_ACCURACY = 1e-3


def _analysis_radius(reader, raw, path):
    """A length, or { delta = length } with delta = a^2 / 2R (paper 1 sec 4): returned as
    ("radius", a) or ("delta", delta); the sphere turns delta into a radius."""
    if isinstance(raw, dict):
        v = reader.read(DELTA, raw, path)
        return BAD if v["delta"] is BAD else ("delta", v["delta"])
    v = reader.value(Key("analysis_radius", "length", "", lo=0.0), raw, path)
    return BAD if v is BAD else ("radius", v)


DELTA = Table("solver.analysis_radius", "The analysis radius by its gap a^2/2R.", (
    Key("delta", "length", "Gap of the undeformed sphere at the analysis radius, a^2/(2R) "
        "(paper 1 sec 4 uses 10 nm).", lo=0.0),))

MESH = Table("solver.mesh", "FE mesh of the half-space (method = 'fe').", (
    Key("outer_factor", "number", "Far boundary radius over the analysis radius.",
        default=1e4, lo=1.0, hi=1e7, hi_closed=True),
    Key("growth", "number", "Element size growth with distance from the loaded surface.",
        default=0.25, lo=0.0, hi=2.0, hi_closed=True),
    Key("surface_fraction", "number", "Surface element size over the node spacing.",
        default=0.5, lo=0.0, hi=1.0, hi_closed=True),
    Key("far_field", "choice", "Data on the far arc: the Boussinesq field (error O(a^2/L^2)) "
        "or 'fixed' (O(a/L)).", default="boussinesq", choices=("boussinesq", "fixed")),
    Key("poisson_ratio", "number", "Poisson ratio of the FE body (default: the disk's, else "
        "0.3).", default=None, lo=-1.0, hi=0.5),
))

GRID = Table("solver.grid", "A banded radial grid (Green method): uniform spacing on the "
             "band [0, band] where the surfaces come close, the spacing growing by about "
             "spacing per grading length beyond it. Without [solver] nodes or [solver.grid], "
             "femadh plans this grid itself and refines it until the error estimate meets "
             "[solver] accuracy.", (
    Key("spacing", "length", "Node spacing h in the band.", lo=0.0),
    Key("band", "length", "Outer radius of the band of uniform spacing.", lo=0.0),
    Key("grading", "length", "Length over which the spacing beyond the band grows by h.",
        lo=0.0),
    Key("follow", "length", "Half-width of a fine band that follows the contact edge during "
        "a stepping sweep (the grid is exchanged as the edge moves, the state carried over); "
        "the band [0, band] is then where the edge may travel. Default: a static band.",
        default=None, lo=0.0),
))

SOLVER = Table("solver", "Discretisation and solver.", (
    Key("method", "choice", "Elastic half-space: exact Green function or condensed finite "
        "elements.", default="green", choices=METHODS),
    Key("nodes", "integer", "Radial nodes N, uniform on the analysis disk: an explicit "
        "discretisation that turns the adaptive grid off (without it the Green method plans "
        "a banded grid and refines it to [solver] accuracy; the FE method and the paper's "
        "closure use 200).", default=200, lo=8, lo_closed=True, hi=20000, hi_closed=True),
    Key("analysis_radius", "custom", "The analysed disk: a length, or { delta = length } "
        "with delta = a^2/2R.", default={"delta": "10 nm"}, parse=_analysis_radius,
        expect="a length, or a table { delta = length }"),
    Key("tolerance", "length", "Residual of eq 6/10 every state meets.",
        default="1e-10 nm", lo=0.0),
    Key("max_iter", "integer", "Newton iterations per solve.", default=40, lo=1,
        lo_closed=True, hi=10000, hi_closed=True),
    Key("continuation", "choice", "'steps' in d, or 'arclength' through the folds (smooth "
        "laws and the complementarity sigma-gap).", default="steps",
        choices=("steps", "arclength")),
    Key("accuracy", "number", "Relative accuracy asked of the headline numbers (largest "
        "adhesion, forces at the deepest separation): femadh refines the grid and the "
        "analysis radius until its error estimate meets it, or says it cannot. Default "
        "1e-3 for the adaptive grid; with explicit [solver] nodes and no accuracy, the "
        "nodes are used as given and the estimate is reported.", default=None, lo=0.0,
        hi=0.1, hi_closed=True),
    Key("time_limit", "time", "Wall time after which the run stops cleanly (every completed "
        "state kept, status 'time limit', exit code 6; --resume continues it), e.g. "
        "\"10 min\". Also `femadh run --time-limit`. Not part of the scene's identity.",
        default=None, lo=0.0),
    Key("route", "choice", "How a sigma-gap complementarity scene's retract is solved: "
        "'auto' - traced in its edge radius (femadh/runner/edge_route.py: the max adhesion "
        "and the pull-off with their errors from a family of edge grids; the approach by "
        "the sweep, the retract's states at the sweep's separations, its jump-out landed) "
        "where the adaptive grid would follow the contact edge, or its first static member "
        "is trapped there by a meniscus step just above sigma, and a pilot finds the "
        "pull-off fold, else the sweep; 'edge' - the edge route wherever the pilot finds a "
        "fold; 'peak' - as 'edge' but the max adhesion and the pull-off alone (no approach, "
        "no states at the sweep's separations: a study that reads only these, e.g. a "
        "stiction map); 'grid' - always the sweep. A scene the route cannot carry (eq 20 "
        "adhesion, FE or coated body, arclength, an instrument, [solver] nodes or "
        "[solver.grid]) keeps the sweep whatever its route.", default="auto",
        choices=("auto", "edge", "peak", "grid")),
    Key("grid", "custom", "An explicit banded grid, see [solver.grid].", default=None,
        parse=lambda r, raw, path: None if raw is None else r.read(GRID, raw, path),
        expect="a table (see [solver.grid])"),
    Key("mesh", "custom", "FE mesh settings (method = 'fe'), see [solver.mesh].",
        default=None, parse=lambda r, raw, path: None if raw is None else r.read(MESH, raw, path),
        expect="a table (see [solver.mesh])"),
))

#: the tables of the discretisation, in the order of the reference page
TABLES = (SOLVER, DELTA, GRID, MESH)
#: the [solver.mesh] keys that are FESettings fields (poisson_ratio is the FE body's nu)
MESH_SETTINGS = ("outer_factor", "growth", "surface_fraction", "far_field")


@dataclass(frozen=True)
class Discretisation:
    """How the scene is discretised and solved, SI units.

    Attributes
    ----------
    method : str
        "green" (the exact half-space Green function, paper 1 eq 3) or "fe" (condensed finite
        elements).
    analysis_radius : float
        Radius a (m) of the analysed disk.
    nodes : int
        Radial nodes N, uniform on [0, a] (unless ``grid``).
    nodes_explicit : bool
        Whether [solver] nodes was given (off: the Green method plans an adaptive grid).
    grid : FrozenMap or None
        An explicit banded grid {spacing, band, grading} (m).
    mesh : FrozenMap or None
        The FE mesh settings (:data:`MESH_SETTINGS`), None for the Green method.
    fe_poisson_ratio : float
        nu of the FE half-space (the disk's, else 0.3; with E* alone only the FE
        discretisation error depends on it).
    tolerance : float
        Residual (m) of paper 1 eq (6)/(10) every state meets.
    max_iter : int
        Newton iterations per solve.
    continuation : str
        "steps" in d, or "arclength" through the folds.
    accuracy : float or None
        Relative accuracy asked of the headline numbers.
    time_limit : float or None
        Wall time (s) after which a run stops cleanly (not in the scene's id).
    route : str
        "auto", "edge", "peak" or "grid": how a sigma-gap retract is solved
        (:mod:`femadh.runner.edge_route`).
    """

    method: str
    analysis_radius: float
    nodes: int
    nodes_explicit: bool
    tolerance: float
    max_iter: int
    continuation: str
    fe_poisson_ratio: float
    grid: FrozenMap | None = None
    mesh: FrozenMap | None = None
    accuracy: float | None = None
    time_limit: float | None = None
    route: str = "auto"

    def __post_init__(self):
        object.__setattr__(self, "grid", frozen_map(self.grid))
        object.__setattr__(self, "mesh", frozen_map(self.mesh))

    @property
    def fe_settings(self):
        """The FE mesh settings (a new :class:`~femadh.elastic.fe.FESettings` each time, so
        that nobody changes the scene's through it), or None for the Green method."""
        if self.mesh is None:
            return None
        from ...elastic.fe.settings import FESettings

        return FESettings(**self.mesh)


def fe_mesh(mesh, nu_default):
    """The FE mesh settings of a [solver.mesh] table (as :data:`MESH_SETTINGS` values) and the
    FE body's Poisson ratio (the table's, else ``nu_default``). The settings are checked by
    building them once (FESettings raises for values outside its ranges)."""
    from ...elastic.fe.settings import FESettings

    settings = {k: mesh[k] for k in MESH_SETTINGS}
    FESettings(**settings)
    nu = mesh["poisson_ratio"] if mesh["poisson_ratio"] is not None else nu_default
    return settings, float(nu)


def analysis_radius_m(reader, so, sphere):
    """The analysis radius a (m) of a [solver] table, from delta = a^2/2R if given so."""
    import math

    ar = so["analysis_radius"]
    if ar is BAD or sphere is None:
        return BAD
    kind, v = ar
    a = math.sqrt(2.0 * sphere.radius * v) if kind == "delta" else v
    # the surface laws act where the sphere is near the flat: the paraboloid (eq 4) is the
    # sphere only for r << R, the exact cap ends at r = R
    if not a < sphere.radius:
        return reader.fail("solver.analysis_radius", v if kind == "radius" else {"delta": v},
                           f"an analysis radius below the sphere radius {sphere.radius:g} m "
                           f"(this one is {a:.3g} m)")
    return a
