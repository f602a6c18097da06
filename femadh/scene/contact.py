"""Contact scenes (paper 1): a :class:`Scene` made of frozen parts - the body, the surface
laws, the discretisation, the sweep and the output (:mod:`femadh.scene.parts`, each beside
the tables of its keys) - validated from a scene file's tables in SI units.

Every key is described once, in the parts' tables and here (the scene's name, the study), and
for the laws in their registrations in :mod:`femadh.laws.registry`; ``femadh keys`` prints
them all. The flat attributes of earlier versions (``scene.nodes``, ``scene.sphere``,
``scene.effects``, ...) read the parts.
"""
import copy
import dataclasses
from dataclasses import dataclass, field

from ..materials import IsotropicMaterial
from ..schema import Key, Table
from .instrument import BEAM, INSTRUMENT, read_instrument
from .parts import Body, Discretisation, Laws, Output, Sweep
# the tables and constants keep their old home's names (femadh.scene.contact.SOLVER, ...)
from .parts.body import (LAYER, LAYER_NU_LIMIT, MATERIAL, MATERIALS, SPHERE,  # noqa: F401
                         SUBSTRATE, read_layers, read_materials, read_sphere)
from .parts.discretisation import (DEFAULT_ACCURACY, DELTA, GRID, MESH, METHODS,  # noqa: F401
                                   SOLVER, analysis_radius_m, fe_mesh)
from .parts.laws import GAP, law_dict, read_effects
from .parts.output import OUTPUT
from .parts.sweep import DIRECTIONS, MAX_SEPARATIONS, SWEEP, separations  # noqa: F401
from .reader import BAD, any_bad
from .replacing import Replaceable

SCENE = Table("scene", "The scene's identity.", (
    Key("name", "string", "Name of the scene (output folder default out/<name>)."),))


def _vary(reader, raw, path):
    if not isinstance(raw, dict) or not raw or not all(
            isinstance(v, (str, list)) for v in raw.values()):
        return reader.fail(path, raw, "a table { \"dotted.key\" = \"values\" }, e.g. "
                           "{ \"effects.asperity_gap.sigma\" = \"0.3 nm..2 nm:10\" }")
    return dict(raw)


STUDY = Table("study", "A parameter study over this scene (femadh study sweep SCENE).", (
    Key("vary", "custom", "Dotted scene keys and their values: a comma list with units, "
        "'lo..hi:n' or 'lo..hi:n:log'.", parse=_vary, expect="a table of key = values"),
    Key("zip", "bool", "Pair the lists instead of their product.", default=False),
))

#: the tables of a contact scene file
TOP = ("scene", "sphere", "materials", "substrate", "effects", "solver", "sweep", "output",
       "study", "instrument")
#: every table description, for the reference page (femadh keys)
TABLES = (SCENE, SPHERE, MATERIALS, MATERIAL, SUBSTRATE, LAYER, GAP, SOLVER, DELTA, GRID, MESH,
          SWEEP, OUTPUT, STUDY, INSTRUMENT, BEAM)


class _Flat:
    """A flat attribute of the scene (``scene.nodes``) that is a field of one of its parts
    (``scene.discretisation.nodes``). Reading it reads the part; assigning it (code of earlier
    versions) replaces the part by a copy with that field changed - the part itself never
    changes - and, like before, validates nothing."""

    def __init__(self, part, convert=None):
        self.part, self.convert = part, convert

    def __set_name__(self, owner, name):
        self.name = name

    def __get__(self, obj, owner=None):
        if obj is None:
            return self
        value = getattr(getattr(obj, self.part), self.name)
        return value if self.convert is None else self.convert(value)

    def __set__(self, obj, value):
        part = getattr(obj, self.part)
        if self.name not in {f.name for f in dataclasses.fields(part)}:
            raise AttributeError(f"scene.{self.name} is derived from scene.{self.part}: "
                                 "use scene.replace({'dotted.key': value})")
        setattr(obj, self.part, dataclasses.replace(part, **{self.name: value}))


@dataclass
class Scene(Replaceable):
    """A validated contact scene: five frozen parts, all quantities in SI units.

    Build one from a file (:func:`femadh.load_scene`), from a dict (:meth:`from_dict`), or
    from another with changes (:meth:`replace`): each goes through the same validation, and
    derived values (analysis radius, E*, the laws) are recomputed. ``raw`` keeps the scene's
    own values; ``resolved`` the SI values written to summary.json.

    Attributes
    ----------
    body : Body
        The sphere, the materials, the coatings (:mod:`femadh.scene.parts.body`).
    laws : Laws
        The surface laws and the sigma-gap.
    discretisation : Discretisation
        The elastic model, its grid or mesh, the solver's settings. With ``body``, all that
        the surface operator is built from.
    sweep : Sweep
        The separations, the branches, the instrument.
    output : Output
        The output folder, VTK files.
    study : dict or None
        The scene's [study] table.

    The fields of the parts read as flat attributes too (``scene.nodes`` is
    ``scene.discretisation.nodes``, ``scene.sphere`` is ``scene.body.sphere``, ...).
    """

    name: str
    path: str | None
    body: Body
    laws: Laws
    discretisation: Discretisation
    sweep: Sweep
    output: Output
    study: dict | None = None
    raw: dict = field(repr=False, default_factory=dict)
    #: the ``raw`` of the scene the user gave, where this one is femadh's variant of it (an
    #: adaptive run's trial, :func:`femadh.runner.estimates.variant`): what its run folder
    #: records as the scene's keys (:attr:`as_given`)
    given: dict | None = field(repr=False, compare=False, default=None)

    kind = "contact"

    # the flat attributes of the scenes before the parts
    sphere = _Flat("body")
    e_star = _Flat("body")
    disk = _Flat("body")
    slider = _Flat("body")
    layers = _Flat("body")
    effects = _Flat("laws")
    gap = _Flat("laws")
    topography = _Flat("laws")
    method = _Flat("discretisation")
    nodes = _Flat("discretisation")
    nodes_explicit = _Flat("discretisation")
    analysis_radius = _Flat("discretisation")
    grid = _Flat("discretisation")
    fe_settings = _Flat("discretisation")
    fe_poisson_ratio = _Flat("discretisation")
    tolerance = _Flat("discretisation")
    max_iter = _Flat("discretisation")
    continuation = _Flat("discretisation")
    accuracy = _Flat("discretisation")
    time_limit = _Flat("discretisation")
    route = _Flat("discretisation")
    d_values = _Flat("sweep", list)
    directions = _Flat("sweep")
    instrument = _Flat("sweep")
    output_dir = _Flat("output")
    vtk = _Flat("output")

    @property
    def operator_inputs(self):
        """``(body, discretisation)``: all that the surface operator is built from
        (:func:`femadh.scene.build.operator_from_parts`)."""
        return self.body, self.discretisation

    @property
    def adaptive(self):
        """Whether femadh chooses the grid (Green method, complementarity or smooth laws,
        neither [solver] nodes nor [solver.grid] given)."""
        return (self.method == "green" and self.grid is None and not self.nodes_explicit
                and (self.gap is None or self.gap.contact_model == "complementarity"))

    @property
    def target_accuracy(self):
        """The relative accuracy the run must meet (None: the explicit settings, judged)."""
        if self.accuracy is not None:
            return self.accuracy
        return DEFAULT_ACCURACY if self.adaptive else None

    @classmethod
    def from_dict(cls, data, file=None):
        """Validate a contact scene given as a dict (keys as in the TOML file; numbers for
        dimensional keys are SI in code-built scenes)."""
        from . import scene_from_dict

        sc = scene_from_dict(data, file, bare_numbers=True)
        if not isinstance(sc, cls):
            raise TypeError("the dict describes a meniscus scene, not a contact scene")
        return sc

    @property
    def resolved(self):
        """Plain-dict SI view of the scene (for summary.json; its content hash is the scene's
        id, :func:`femadh.scene.scene_id`: keep its layout, or old runs stop resuming)."""
        return {
            "name": self.name,
            "sphere": {"radius_m": self.sphere.radius, "profile": self.sphere.profile},
            "composite_modulus_Pa": self.e_star,
            "layers": [{"thickness_m": t, "youngs_modulus_Pa": e, "poisson_ratio": nu}
                       for t, e, nu in self.layers],
            "effects": {name: law_dict(e) for name, e in self.effects.items()},
            "asperity_gap": None if self.gap is None else
            {"sigma_m": self.gap.sigma, "contact_model": self.gap.contact_model,
             "adhesion_Pa": self.gap.adhesion},
            "solver": {"method": self.method, "nodes": self.nodes, "grid": self.grid,
                       "analysis_radius_m": self.analysis_radius,
                       "tolerance_m": self.tolerance, "max_iter": self.max_iter,
                       "continuation": self.continuation, "accuracy": self.accuracy,
                       "mesh": None if self.fe_settings is None else {
                           **dataclasses.asdict(self.fe_settings),
                           "poisson_ratio": self.fe_poisson_ratio},
                       # (only when set: the ids of scenes without it stay as they were)
                       **({"route": self.route} if self.route != "auto" else {})},
            "sweep": {"d_m": list(self.d_values), "directions": list(self.directions)},
            "instrument": None if self.instrument is None else self.instrument.as_dict(),
            "output_dir": self.output_dir,
            # (only when used: the ids of scenes without it stay as they were)
            **({"topography": self.topography} if self.topography else {}),
        }


def parse_contact(reader, data, file):
    """Build a contact :class:`Scene` from the parsed TOML ``data``; every error is recorded
    in ``reader`` and raised together by the caller."""
    for name in data:
        if name not in TOP:
            reader.unknown("", name, data[name], list(TOP))
    sc = reader.read(SCENE, data.get("scene"), "scene")
    sphere = read_sphere(reader, data)

    e_star, disk, slider = read_materials(reader, data)
    layers = read_layers(reader, data, disk)
    topography = {}
    gap, effects = read_effects(reader, data.get("effects"), e_star, topography)

    so = reader.read(SOLVER, data.get("solver"), "solver")
    a = analysis_radius_m(reader, so, sphere)
    sw = reader.read(SWEEP, data.get("sweep"), "sweep",
                     missing="a [sweep] table (it is required)")
    d_values = separations(reader, sw, data.get("sweep") or {})
    ou = reader.read(OUTPUT, data.get("output"), "output")
    study = reader.read(STUDY, data["study"], "study") if "study" in data else None
    instrument = read_instrument(reader, data.get("instrument"))

    method = so["method"]
    mesh, fe_nu = None, (disk.poisson_ratio if isinstance(disk, IsotropicMaterial) else 0.3)
    if so["mesh"] is not None and so["mesh"] is not BAD:
        if method != "fe":
            reader.fail("solver.mesh", data["solver"]["mesh"], "no [solver] mesh table unless "
                        "method = \"fe\"")
        elif not any_bad(so["mesh"]):
            mesh, fe_nu = fe_mesh(so["mesh"], fe_nu)
            if layers and so["mesh"]["poisson_ratio"] is not None:
                reader.fail("solver.mesh.poisson_ratio", data["solver"]["mesh"]["poisson_ratio"],
                            "no FE body Poisson ratio in a layered scene: each layer and the "
                            "disk (substrate) carry their own")
    elif method == "fe":
        mesh, fe_nu = fe_mesh(reader.read(MESH, None, "solver.mesh"), fe_nu)
    if layers and gap is not None and gap.contact_model == "hertz-closure":
        reader.fail("effects.asperity_gap.contact_model", "hertz-closure", "'complementarity' "
                    "for a layered substrate: the paper's closure (eq 9) is a Hertz pressure "
                    "of one composite modulus E*")
    if layers and method != "fe":
        reader.fail("solver.method", method, "\"fe\" for a layered substrate ([substrate] "
                    "layers): the Green function is the homogeneous half-space's")
    # off by default: the body's fields cost ~1.2 s to set up and ~20 ms a state
    # (validation/results/fe_pace.md); `femadh render` exports the states a user asks for
    vtk = bool(ou["vtk"])
    if vtk is True and method != "fe":
        reader.fail("output.vtk", vtk, "false unless [solver] method = \"fe\" (the Green "
                    "operator has no interior field to write)")
    _cross_checks(reader, data, gap, effects, so, sw, d_values, sphere, a)
    if reader.errors:
        return None
    name = sc["name"]
    return Scene(
        name=name, path=file,
        body=Body(sphere=sphere, e_star=e_star, disk=disk, slider=slider,
                  layers=layers if layers is not BAD else ()),
        laws=Laws(effects=effects, gap=gap, topography=topography or None),
        discretisation=Discretisation(
            method=method, analysis_radius=a, nodes=so["nodes"],
            nodes_explicit="nodes" in (data.get("solver") or {}),
            tolerance=so["tolerance"], max_iter=so["max_iter"],
            continuation=so["continuation"], fe_poisson_ratio=fe_nu, grid=so["grid"],
            mesh=mesh, accuracy=so["accuracy"], time_limit=so["time_limit"],
            route=so["route"]),
        sweep=Sweep(d_values=d_values, directions=sw["directions"], instrument=instrument),
        output=Output(output_dir=ou["dir"] or f"out/{name}", vtk=vtk),
        study=study, raw=copy.deepcopy(data))


def _cross_checks(reader, data, gap, effects, so, sw, d_values, sphere, a):
    """Rules that tie tables together."""
    grid = so.get("grid")
    if grid is not None and grid is not BAD and not any_bad(grid):
        raw_grid = (data.get("solver") or {}).get("grid")
        if so["method"] != "green":
            reader.fail("solver.grid", raw_grid, "no [solver.grid] unless method = \"green\" "
                        "(the FE body takes uniform surface nodes: [solver] nodes)")
        elif "nodes" in (data.get("solver") or {}):
            reader.fail("solver.grid", raw_grid, "either [solver] nodes (uniform) or "
                        "[solver.grid] (banded), not both")
        elif a is not BAD and grid["band"] > a:
            reader.fail("solver.grid.band", raw_grid.get("band"), f"a band within the "
                        f"analysis radius a = {a * 1e6:.4g} um")
        elif grid["spacing"] > grid["band"]:
            reader.fail("solver.grid.spacing", raw_grid.get("spacing"), "a spacing at most "
                        "the band's radius")
    if so["continuation"] == "arclength":
        if gap is not None and gap.contact_model != "complementarity":
            reader.fail("solver.continuation", "arclength", "'steps' with the "
                        "hertz-closure sigma-gap: arclength continuation traces smooth laws "
                        "and the complementarity sigma-gap only (the closure's contact "
                        "radius is not traced through folds)")
        elif gap is not None and gap.adhesion:
            reader.fail("solver.continuation", "arclength", "'steps' with "
                        "[effects.asperity_adhesion] on the contact set: its range-less "
                        "adhesion holds a node that reached sigma until its pressure falls to "
                        "-P_LJa, so approach and retract part at every node and the "
                        "equilibria are no single curve (model = 'smoothed' can be traced)")
        if not any_bad(sw) and "approach" not in sw["directions"]:
            reader.fail("sweep.directions", list(sw["directions"]), "a list with 'approach' "
                        "for [solver] continuation = 'arclength' (the curve is traced from "
                        "start to stop)")
    if gap is None and d_values is not BAD and d_values and d_values[0] <= 0:
        reader.fail("sweep.start", data["sweep"].get("start"), "a positive separation for a "
                    "smooth sphere (no [effects.asperity_gap]): the sweep starts from the "
                    "undeformed surface, which the tip must not touch")
    if gap not in (None, BAD) and sphere not in (None, BAD):
        # a sigma-gap wider than the sphere, or than the whole sweep, is a unit slip (a bare
        # number typed as metres, "0.8" for 0.8 nm), never a scene: refuse it in one line
        # before anything runs instead of letting every Newton step fail
        raw_sigma = ((data.get("effects") or {}).get("asperity_gap") or {}).get("sigma")
        span = (abs(d_values[0] - d_values[-1]) if d_values is not BAD and d_values
                else None)
        if not gap.sigma < sphere.radius:
            reader.fail("effects.asperity_gap.sigma", raw_sigma, f"a sigma below the sphere "
                        f"radius {sphere.radius:.4g} m (this one is {gap.sigma:.4g} m)")
        elif span and gap.sigma > span:
            reader.fail("effects.asperity_gap.sigma", raw_sigma, f"a sigma within the sweep's "
                        f"range |stop - start| = {span:.4g} m (this one is {gap.sigma:.4g} m)")
    cap = effects.get("capillary")
    if cap is not None and a is not BAD and sphere is not None:
        delta_a = a * a / (2 * sphere.radius)
        if cap.fill_gap >= delta_a:
            reader.fail("solver.analysis_radius", (data.get("solver") or {}).get(
                "analysis_radius", {"delta": "10 nm"}), f"an analysis radius whose gap "
                f"a^2/2R = {delta_a * 1e9:.4g} nm exceeds the condensate's filled gap "
                f"2|r_K| + 2h = {cap.fill_gap * 1e9:.4g} nm, so that the meniscus lies inside "
                f"it (e.g. analysis_radius = {{ delta = \"{2 * cap.fill_gap * 1e9:.3g} nm\" }})")
