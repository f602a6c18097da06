"""Contact scenes (paper 1): the sphere, the materials, the effects (gap laws and the sigma-gap),
the solver and the sweep, validated into a :class:`Scene` in SI units.

Every key is described once in the tables below (and, for the laws, in their registrations in
:mod:`femadh.laws.registry`); ``femadh keys`` prints them all.
"""
import copy
from dataclasses import asdict, dataclass, field
import math

from ..contact.constraints import CONTACT_MODELS, AsperityGap
from ..indenter import PROFILES, Sphere
from ..laws.registry import BuildContext, registry
from ..materials import IsotropicMaterial, composite_modulus
from ..schema import Key, Table
from .instrument import BEAM, INSTRUMENT, read_instrument
from .reader import BAD, any_bad
from .replacing import Replaceable
from .topography import resolve as resolve_topography

METHODS = ("green", "fe")
#: relative accuracy of the headline numbers an adaptive run meets unless the scene asks
DEFAULT_ACCURACY = 1e-3
DIRECTIONS = ("approach", "retract")
#: the largest number of separations a sweep may list
MAX_SEPARATIONS = 100000


def _directions(reader, raw, path):
    if (not isinstance(raw, list) or not raw or any(x not in DIRECTIONS for x in raw)
            or len(set(raw)) != len(raw)):
        return reader.fail(path, raw, "a list drawn from ['approach', 'retract']")
    return tuple(raw)


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

SCENE = Table("scene", "The scene's identity.", (
    Key("name", "string", "Name of the scene (output folder default out/<name>)."),))

SPHERE = Table("sphere", "The rigid sphere (slider, tip, asperity), paper 1 eq (4).", (
    Key("radius", "length", "Sphere radius R (paper 1: 2 mm slider, 1 um in Fig 6).", lo=0.0),
    Key("profile", "choice", "'paraboloid': b = d + r^2/2R (eq 4); 'sphere': the exact cap.",
        default="paraboloid", choices=PROFILES),
))

MATERIAL = Table("materials.disk", "An isotropic elastic solid.", (
    Key("youngs_modulus", "pressure", "Young's modulus E.", lo=0.0),
    Key("poisson_ratio", "number", "Poisson ratio nu.", lo=-1.0, hi=0.5),
))

MATERIALS = Table("materials", "Elastic constants: disk and slider (composite modulus E* of "
                  "eq 2) or E* itself.", (
    Key("disk", "custom", "{ youngs_modulus, poisson_ratio } of the disk (flat).",
        default=None, parse=lambda r, raw, path: _material(r, raw, path),
        expect="a table { youngs_modulus, poisson_ratio }"),
    Key("slider", "custom", "{ youngs_modulus, poisson_ratio } of the sphere; omitted: rigid.",
        default=None, parse=lambda r, raw, path: _material(r, raw, path),
        expect="a table { youngs_modulus, poisson_ratio }"),
    Key("composite_modulus", "pressure", "E* directly, instead of disk/slider.", default=None,
        lo=0.0),
))

GAP = Table("effects.asperity_gap", "The minimum gap sigma set by compressed asperities, "
            "paper 1 eq (8): h >= sigma.", (
    Key("sigma", "length", "Spacing of the mean planes in contact (Figs 3/4: 1 and 0.5 nm).",
        lo=0.0),
    Key("contact_model", "choice", "'complementarity': h >= sigma, p_c >= 0, p_c (h - sigma) "
        "= 0, exact; 'hertz-closure': the paper's Hertz-shaped contact pressure (eq 9) with "
        "the contact radius a continuous unknown.", default="complementarity",
        choices=CONTACT_MODELS),
))

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
    Key("grid", "custom", "An explicit banded grid, see [solver.grid].", default=None,
        parse=lambda r, raw, path: None if raw is None else r.read(GRID, raw, path),
        expect="a table (see [solver.grid])"),
    Key("mesh", "custom", "FE mesh settings (method = 'fe'), see [solver.mesh].",
        default=None, parse=lambda r, raw, path: None if raw is None else r.read(MESH, raw, path),
        expect="a table (see [solver.mesh])"),
))

SWEEP = Table("sweep", "The separations d of the sphere tip above the undeformed mean plane.", (
    Key("start", "length", "First separation."),
    Key("stop", "length", "Last separation."),
    Key("step", "length", "Step between separations.", lo=0.0),
    Key("directions", "custom", "Branches to trace: approach (start -> stop) and/or retract.",
        default=["approach", "retract"], parse=_directions,
        expect="a list drawn from ['approach', 'retract']"),
))

OUTPUT = Table("output", "Outputs.", (
    Key("dir", "string", "Output folder (default out/<scene name>).", default=None),
    Key("vtk", "bool", "VTK volume and surface files of every state as it converges (FE only; "
        "default false: `femadh render RUN_DIR --state K` writes and draws the states you ask "
        "for from fields.csv).", default=None),
))

#: the largest Poisson ratio the FE body takes (its mixed formulation eliminates the pressure
#: with a finite lambda; equal to femadh.elastic.fe.operator.NU_LIMIT, tested)
LAYER_NU_LIMIT = 0.49999

LAYER = Table("substrate.layers", "One bonded elastic layer (an element of the layers list, "
              "top first).", (
    Key("thickness", "length", "Layer thickness t.", lo=0.0),
    Key("youngs_modulus", "pressure", "Young's modulus E of the layer.", lo=0.0),
    Key("poisson_ratio", "number", "Poisson ratio nu of the layer (nearly incompressible "
        f"layers up to {LAYER_NU_LIMIT}: the FE body switches to a mixed formulation above "
        "0.45).", lo=-1.0, hi=LAYER_NU_LIMIT, hi_closed=True),
))


def _layers(reader, raw, path):
    """The layer stack: a non-empty list of LAYER tables, top first, as (t, E, nu) tuples."""
    if not isinstance(raw, list) or not raw:
        return reader.fail(path, raw, "a non-empty list of tables { thickness, youngs_modulus, "
                           "poisson_ratio }, top layer first")
    out = []
    for i, item in enumerate(raw):
        v = reader.read(LAYER, item, f"{path}.{i}")
        out.append(BAD if any_bad(v) else
                   (v["thickness"], v["youngs_modulus"], v["poisson_ratio"]))
    return BAD if any_bad(*out) else tuple(out)


SUBSTRATE = Table("substrate", "Coatings: bonded elastic layers on the disk material "
                  "([materials] disk is the substrate half-space below them). Needs "
                  "[solver] method = 'fe': the Green function is the homogeneous half-space's. "
                  "The sphere's own compliance ([materials] slider; omitted: rigid) is added "
                  "as its half-space Green function on the same nodes. E* (eq 2) stays the bare "
                  "disk/slider pair's: the JKR/DMT reference curves show the uncoated contact "
                  "and the asperity laws use it.", (
    Key("layers", "custom", "The layers, top first: [{ thickness = \"5 nm\", youngs_modulus "
        "= \"200 GPa\", poisson_ratio = 0.25 }, ...].", default=(), parse=_layers,
        expect="a list of tables { thickness, youngs_modulus, poisson_ratio }, top first"),
))


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


def _material(reader, raw, path):
    if raw is None:
        return None
    v = reader.read(MATERIAL, raw, path)
    if any_bad(v):
        return BAD
    return IsotropicMaterial(v["youngs_modulus"], v["poisson_ratio"])


@dataclass
class Scene(Replaceable):
    """A validated contact scene, all quantities in SI units.

    Build one from a file (:func:`femadh.load_scene`), from a dict (:meth:`from_dict`), or
    from another with changes (:meth:`replace`): each goes through the same validation, and
    derived values (analysis radius, E*, the laws) are recomputed. ``raw`` keeps the scene's
    own values; ``resolved`` the SI values written to summary.json.
    """

    name: str
    path: str | None
    sphere: Sphere
    e_star: float
    effects: dict
    gap: AsperityGap | None
    method: str
    nodes: int
    analysis_radius: float
    tolerance: float
    max_iter: int
    fe_settings: object | None
    d_values: list
    directions: tuple
    output_dir: str
    fe_poisson_ratio: float = 0.3
    vtk: bool = False
    continuation: str = "steps"
    disk: IsotropicMaterial | None = None
    slider: IsotropicMaterial | None = None
    layers: tuple = ()
    study: dict | None = None
    accuracy: float | None = None
    grid: dict | None = None
    nodes_explicit: bool = True
    topography: dict | None = None
    instrument: object = None        # femadh.instrument.Spring, or None (a rigid drive)
    time_limit: float | None = None  # s; how long a run may take (not in ``resolved``)
    raw: dict = field(repr=False, default_factory=dict)

    kind = "contact"

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
        """Plain-dict SI view of the scene (for summary.json)."""
        return {
            "name": self.name,
            "sphere": {"radius_m": self.sphere.radius, "profile": self.sphere.profile},
            "composite_modulus_Pa": self.e_star,
            "layers": [{"thickness_m": t, "youngs_modulus_Pa": e, "poisson_ratio": nu}
                       for t, e, nu in self.layers],
            "effects": {name: _law_dict(e) for name, e in self.effects.items()},
            "asperity_gap": None if self.gap is None else
            {"sigma_m": self.gap.sigma, "contact_model": self.gap.contact_model,
             "adhesion_Pa": self.gap.adhesion},
            "solver": {"method": self.method, "nodes": self.nodes, "grid": self.grid,
                       "analysis_radius_m": self.analysis_radius,
                       "tolerance_m": self.tolerance, "max_iter": self.max_iter,
                       "continuation": self.continuation, "accuracy": self.accuracy,
                       "mesh": None if self.fe_settings is None else {
                           **asdict(self.fe_settings), "poisson_ratio": self.fe_poisson_ratio}},
            "sweep": {"d_m": list(self.d_values), "directions": list(self.directions)},
            "instrument": None if self.instrument is None else self.instrument.as_dict(),
            "output_dir": self.output_dir,
            # (only when used: the ids of scenes without it stay as they were)
            **({"topography": self.topography} if self.topography else {}),
        }


def _law_dict(law):
    out = {}
    for k, v in asdict(law).items():
        out[k] = v if isinstance(v, (int, float, str, type(None))) else repr(v)
    return out


def parse_contact(reader, data, file):
    """Build a contact :class:`Scene` from the parsed TOML ``data``; every error is recorded
    in ``reader`` and raised together by the caller."""
    for name in data:
        if name not in TOP:
            reader.unknown("", name, data[name], list(TOP))
    sc = reader.read(SCENE, data.get("scene"), "scene")
    sp = reader.read(SPHERE, data.get("sphere"), "sphere")
    if "sphere" not in data:
        reader.fail("sphere", None, "a [sphere] table (it is required)")
    sphere = None if any_bad(sp) else Sphere(sp["radius"], sp["profile"])

    e_star, disk, slider = _read_materials(reader, data)
    layers = _read_layers(reader, data, disk)
    topography = {}
    gap, effects = _read_effects(reader, data.get("effects"), e_star, topography)

    so = reader.read(SOLVER, data.get("solver"), "solver")
    a = _analysis_radius_m(reader, so, sphere)
    sw = reader.read(SWEEP, data.get("sweep"), "sweep")
    if "sweep" not in data:
        reader.fail("sweep", None, "a [sweep] table (it is required)")
    d_values = _separations(reader, sw, data.get("sweep") or {})
    ou = reader.read(OUTPUT, data.get("output"), "output")
    study = reader.read(STUDY, data["study"], "study") if "study" in data else None
    instrument = read_instrument(reader, data.get("instrument"))

    method = so["method"]
    fe_settings, fe_nu = None, (disk.poisson_ratio if isinstance(disk, IsotropicMaterial)
                                else 0.3)
    if so["mesh"] is not None and so["mesh"] is not BAD:
        if method != "fe":
            reader.fail("solver.mesh", data["solver"]["mesh"], "no [solver] mesh table unless "
                        "method = \"fe\"")
        elif not any_bad(so["mesh"]):
            fe_settings, fe_nu = _fe_settings(so["mesh"], fe_nu)
            if layers and so["mesh"]["poisson_ratio"] is not None:
                reader.fail("solver.mesh.poisson_ratio", data["solver"]["mesh"]["poisson_ratio"],
                            "no FE body Poisson ratio in a layered scene: each layer and the "
                            "disk (substrate) carry their own")
    elif method == "fe":
        fe_settings, fe_nu = _fe_settings(reader.read(MESH, None, "solver.mesh"), fe_nu)
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
    return Scene(name=name, path=file, sphere=sphere, e_star=e_star, effects=effects, gap=gap,
                 method=method, nodes=so["nodes"], analysis_radius=a,
                 tolerance=so["tolerance"], max_iter=so["max_iter"], fe_settings=fe_settings,
                 d_values=d_values, directions=sw["directions"],
                 output_dir=ou["dir"] or f"out/{name}", fe_poisson_ratio=fe_nu, vtk=vtk,
                 continuation=so["continuation"], disk=disk, slider=slider,
                 layers=layers if layers is not BAD else (), study=study,
                 accuracy=so["accuracy"], grid=so["grid"],
                 nodes_explicit="nodes" in (data.get("solver") or {}),
                 instrument=instrument, topography=topography or None,
                 time_limit=so["time_limit"],
                 raw=copy.deepcopy(data))


def _read_materials(reader, data):
    mt = reader.read(MATERIALS, data.get("materials"), "materials")
    if "materials" not in data:
        reader.fail("materials", None, "a [materials] table (it is required)")
        return BAD, None, None
    if any_bad(mt):
        return BAD, None, None
    if mt["composite_modulus"] is not None:
        if mt["disk"] is not None or mt["slider"] is not None:
            reader.fail("materials.composite_modulus", data["materials"]["composite_modulus"],
                        "either composite_modulus or disk/slider, not both")
            return BAD, None, None
        return mt["composite_modulus"], None, None
    if mt["disk"] is None:
        reader.fail("materials.disk", None, "a table { youngs_modulus, poisson_ratio } (or "
                    "materials.composite_modulus)")
        return BAD, None, None
    return composite_modulus(mt["disk"], mt["slider"]), mt["disk"], mt["slider"]


def _read_layers(reader, data, disk):
    """The [substrate] layers (top first) as (t, E, nu) tuples; () without the table."""
    if "substrate" not in data:
        return ()
    v = reader.read(SUBSTRATE, data["substrate"], "substrate")
    layers = v["layers"]
    if layers is BAD:
        return BAD
    if not layers:
        reader.fail("substrate.layers", None, "a non-empty list of layers (or no [substrate] "
                    "table)")
        return BAD
    if disk is None and "materials" in data and isinstance(data["materials"], dict) \
            and "composite_modulus" in data["materials"]:
        reader.fail("materials.composite_modulus", data["materials"]["composite_modulus"],
                    "disk (and slider) materials in a layered scene: the layers lie on the "
                    "disk, and the sphere's compliance is added separately")
    return layers


def _read_effects(reader, table, e_star, topography):
    """The sigma-gap and the laws the [effects.*] tables name (through the law registry);
    an asperity section's ``topography`` is resolved into ``topography`` (scene/topography)."""
    if table is None or not isinstance(table, dict) or not table:
        reader.fail("effects", table, "at least one surface force effect, e.g. "
                    "[effects.lennard_jones]")
        return None, {}
    reg = registry()
    allowed = ["asperity_gap"] + list(reg)
    for name in table:
        if name not in allowed:
            reader.unknown("effects", name, table[name], allowed)
    gap = None
    if "asperity_gap" in table:
        g = reader.read(GAP, table["asperity_gap"], "effects.asperity_gap")
        if not any_bad(g):
            gap = AsperityGap(g["sigma"], g["contact_model"])
    if "asperity_adhesion" in table and "asperity_gap" not in table:
        reader.fail("effects.asperity_adhesion", table["asperity_adhesion"], "an "
                    "[effects.asperity_gap] as well: eq 20 acts over the sigma-gap contact "
                    "region")
        return gap, {}
    if "asperity_contact" in table and "asperity_gap" in table:
        reader.fail("effects.asperity_contact", table["asperity_contact"], "no "
                    "[effects.asperity_gap]: the Greenwood-Williamson model replaces the hard "
                    "sigma-gap")
    effects, adhesion = {}, 0.0
    ctx = BuildContext(e_star if e_star is not BAD else math.nan,
                       None if gap is None else gap.sigma)
    for name, entry in reg.items():
        if name not in table:
            continue
        raw = resolve_topography(reader, table[name], f"effects.{name}", entry.table,
                                 topography)
        if raw is BAD:
            continue
        values = reader.read(entry.table, raw, f"effects.{name}")
        if any_bad(values) or e_star is BAD:
            continue
        built = entry.build(values, ctx)
        effects.update(built.laws)
        adhesion += built.gap_adhesion
    if gap is not None and adhesion:
        gap = AsperityGap(gap.sigma, gap.contact_model, adhesion)
    if gap is not None and gap.contact_model == "hertz-closure":
        if "asperity_adhesion" in effects:
            reader.fail("effects.asperity_adhesion.model", "smoothed", "'contact-set' with "
                        "contact_model = 'hertz-closure' (the closure applies eq 20 over "
                        "r < r_c exactly)")
        if "lj" not in effects:
            reader.fail("effects.asperity_gap.contact_model", gap.contact_model,
                        "'complementarity' unless [effects.lennard_jones] is present")
    # (a bare sigma-gap without laws is Hertz contact, A = 0: a valid limit)
    if not effects and gap is None and not reader.errors:
        reader.fail("effects", sorted(table), "at least one surface force effect, e.g. "
                    "[effects.lennard_jones]")
    return gap, effects


def _analysis_radius_m(reader, so, sphere):
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


def _separations(reader, sw, raw):
    if any_bad(sw):
        return BAD
    start, stop, step, dirs = sw["start"], sw["stop"], sw["step"], sw["directions"]
    if "approach" in dirs and not stop < start:
        reader.fail("sweep.stop", raw.get("stop"), f"a separation below start "
                    f"({raw.get('start')}) for an approach")
        return BAD
    if dirs == ("retract",) and not stop > start:
        reader.fail("sweep.stop", raw.get("stop"), f"a separation above start "
                    f"({raw.get('start')}) for a retract-only sweep")
        return BAD
    n_steps = abs(stop - start) / step
    if n_steps < 1:
        reader.fail("sweep.step", raw.get("step"), f"a step no longer than the sweep "
                    f"|stop - start| = {abs(stop - start):.6g} m")
        return BAD
    if n_steps > MAX_SEPARATIONS:
        reader.fail("sweep.step", raw.get("step"), f"a step giving at most "
                    f"{MAX_SEPARATIONS} separations (this one gives {n_steps:.3g})")
        return BAD
    k = round(n_steps)
    if abs(n_steps - k) > 1e-6:
        reader.fail("sweep.step", raw.get("step"), f"a step that divides |stop - start| = "
                    f"{abs(stop - start):.6g} m into whole steps")
        return BAD
    sign = -1.0 if stop < start else 1.0
    return [start + sign * i * step for i in range(k + 1)]


def _fe_settings(mesh, nu_default):
    from ..elastic.fe.operator import FESettings

    nu = mesh["poisson_ratio"] if mesh["poisson_ratio"] is not None else nu_default
    return FESettings(mesh["outer_factor"], mesh["growth"], mesh["surface_fraction"],
                      mesh["far_field"]), float(nu)


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
