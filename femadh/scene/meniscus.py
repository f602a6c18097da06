"""``[meniscus]`` scenes (paper 2): validated into a :class:`MeniscusScene`.

    [meniscus]
    tip_radius = "100 nm"            # or a list: ["10 nm", "100 nm", "1 um"]
    separation = "contact"           # solids touching (D = -2h); or a solid-solid gap length
    liquid = "ethanol"               # built-in name, a list of names, or a table
    temperature = "298.15 K"
    isotherm = { model = "gab", monolayer = "0.46 nm", c = 15, k = 0.7 }
    relative_pressure = [0.05, 0.1]  # or { start = 0.01, stop = 0.99, num = 50 }
    methods = ["fe", "shooting", "circular", "no-film"]
    elements = 16                    # FE elements of the meridian
"""
import copy
from dataclasses import dataclass, field

import numpy as np

from ..meniscus.isotherms import default_isotherm
from ..meniscus.liquids import LIQUIDS
from ..meniscus.methods import METHODS
from ..schema import Key, Table
from .liquids import read_liquid
from .reader import BAD, any_bad, quantity
from .replacing import Replaceable

#: the most p/psat points a scene may ask for (each is a meniscus solve per liquid, radius and
#: method; 1e5 already takes minutes)
MAX_POINTS = 100000


def _radii(reader, raw, path):
    items = raw if isinstance(raw, list) else [raw]
    if not items:
        return reader.fail(path, raw, "a length or a non-empty list of lengths")
    out = [quantity(reader, v, f"{path}[{i}]" if isinstance(raw, list) else path, "length")
           for i, v in enumerate(items)]
    if any(x is BAD for x in out):
        return BAD
    for i, x in enumerate(out):
        if not 1e-10 <= x <= 1.0:   # a meniscus needs a tip larger than its molecules
            return reader.fail(f"{path}[{i}]" if isinstance(raw, list) else path, items[i],
                               "a tip radius between 0.1 nm and 1 m")
    return out


def _separation(reader, raw, path):
    if raw == "contact":
        return None
    x = quantity(reader, raw, path, "length", positive=False)
    if x is not BAD and x < 0:
        return reader.fail(path, raw, "'contact' or a solid-solid gap >= 0")
    return x


def _liquids(reader, raw, path):
    items = raw if isinstance(raw, list) else [raw]
    if not items:
        return reader.fail(path, raw, "a liquid name, a liquid table, or a non-empty list")
    out = [read_liquid(reader, v, path) for v in items]
    return BAD if any(x is BAD for x in out) else out


RANGE = Table("meniscus.relative_pressure", "Evenly spaced p/psat.", (
    Key("start", "number", "First p/psat.", lo=0.0, hi=1.0),
    Key("stop", "number", "Last p/psat.", lo=0.0, hi=1.0),
    Key("num", "integer", "Number of points.", lo=2, lo_closed=True, hi=MAX_POINTS,
        hi_closed=True),
))


def _p_ratios(reader, raw, path):
    if isinstance(raw, dict):
        v = reader.read(RANGE, raw, path)
        return BAD if any_bad(v) else [float(x) for x in np.linspace(v["start"], v["stop"],
                                                                      v["num"])]
    if (not isinstance(raw, list) or not raw or len(raw) > MAX_POINTS
            or any(isinstance(x, bool) or not isinstance(x, (int, float)) or not 0 < x < 1
                   for x in raw)):
        return reader.fail(path, raw, "a list of numbers in (0, 1), or { start, stop, num } "
                           f"inside (0, 1) with num <= {MAX_POINTS}")
    return [float(x) for x in raw]


def _methods(reader, raw, path):
    if not isinstance(raw, list) or not raw or any(x not in METHODS for x in raw):
        return reader.fail(path, raw, f"a list drawn from {list(METHODS)}")
    return tuple(raw)


MENISCUS = Table("meniscus", "Capillary meniscus with an adsorbed film between a sphere and a "
                 "flat (paper 2), swept in p/psat.", (
    Key("tip_radius", "custom", "Solid sphere radius R, or a list of them.", parse=_radii,
        expect="a length or a list of lengths"),
    Key("separation", "custom", "'contact' (D = -2h, paper 2 Fig 2b) or a solid-solid gap.",
        default="contact", parse=_separation, expect="'contact' or a length >= 0"),
    Key("liquid", "custom", "A built-in liquid (water, ethanol, n-butanol, n-pentanol), a "
        "table { name, surface_tension, molar_volume }, or a list of them.", parse=_liquids,
        expect="a liquid name, a liquid table, or a list of them"),
    Key("temperature", "temperature", "Temperature (Kelvin equation, paper 2 eq 6).",
        default="298.15 K", lo=0.0),
    Key("isotherm", "isotherm", "Adsorption isotherm { model = gab | bet | polynomial | "
        "tabulated | none, ... }; default: each built-in liquid's representative GAB "
        "isotherm.", default="default"),
    Key("relative_pressure", "custom", "p/psat values: a list, or { start, stop, num }.",
        parse=_p_ratios, expect="a list of numbers in (0, 1), or { start, stop, num }"),
    Key("methods", "custom", "Solvers: fe (1D finite elements), shooting (ODE), circular "
        "(toroidal approximation), no-film (exact, bare solids).", default=list(METHODS),
        parse=_methods, expect=f"a list drawn from {list(METHODS)}"),
    Key("elements", "integer", "FE elements of the meridian.", default=16, lo=2,
        lo_closed=True, hi=4096, hi_closed=True),
))

OUTPUT = Table("output", "Outputs.", (
    Key("dir", "string", "Output folder (default out/<scene name>; a relative path is taken "
        "from the current folder, as --out is, not from the scene file's).", default=None),
    Key("vtk", "bool", "VTK surfaces of revolution of the FE menisci.", default=True),
))

TABLES = (MENISCUS, RANGE, OUTPUT)


@dataclass
class MeniscusScene(Replaceable):
    name: str
    path: str | None
    radii: list
    separation: float | None
    liquids: list
    temperature: float
    isotherms: dict          # liquid name -> isotherm (or None)
    p_ratios: list
    methods: tuple
    elements: int
    output_dir: str
    vtk: bool = True
    study: dict | None = None
    raw: dict = field(repr=False, default_factory=dict)

    kind = "meniscus"

    @property
    def resolved(self):
        return {"name": self.name, "tip_radii_m": self.radii,
                "separation_m": "contact" if self.separation is None else self.separation,
                "liquids": [{"name": lq.name, "surface_tension_N_per_m": lq.surface_tension,
                             "molar_volume_m3_per_mol": lq.molar_volume,
                             "source": lq.source} for lq in self.liquids],
                "temperature_K": self.temperature,
                "isotherms": {k: None if v is None else {**v.__dict__}
                              for k, v in self.isotherms.items()},
                "p_ratios": self.p_ratios, "methods": list(self.methods),
                "elements": self.elements, "output_dir": self.output_dir}


def parse_meniscus(reader, data, file):
    """Build a MeniscusScene from the parsed TOML ``data`` (errors recorded in ``reader``)."""
    from .contact import SCENE

    from .contact import STUDY

    if "instrument" in data:
        reader.fail("instrument", data["instrument"], "no [instrument] in a meniscus scene: it "
                    "computes the meniscus force at fixed geometry, with no contact curve for a "
                    "spring to follow (give the contact scene an [effects.capillary] and the "
                    "instrument there)")
    for name in data:
        if name not in ("scene", "meniscus", "output", "study", "instrument"):
            reader.unknown("", name, data[name], ["meniscus", "output", "scene", "study"])
    sc = reader.read(SCENE, data.get("scene"), "scene")
    m = reader.read(MENISCUS, data.get("meniscus"), "meniscus")
    ou = reader.read(OUTPUT, data.get("output"), "output")
    study = reader.read(STUDY, data["study"], "study") if "study" in data else None
    isotherms = {}
    if m["liquid"] is not BAD and m["isotherm"] is not BAD:
        for lq in m["liquid"]:
            if m["isotherm"] == "default":
                if lq.name not in LIQUIDS:
                    reader.fail("meniscus.isotherm", None, f"an isotherm table for the user "
                                f"liquid {lq.name!r} (or model = 'none')")
                    continue
                isotherms[lq.name] = default_isotherm(lq.name)
            else:
                isotherms[lq.name] = m["isotherm"]
    if reader.errors:
        return None
    name = sc["name"]
    return MeniscusScene(name, file, m["tip_radius"], m["separation"], m["liquid"],
                         m["temperature"], isotherms, m["relative_pressure"], m["methods"],
                         m["elements"], ou["dir"] or f"out/{name}", ou["vtk"], study,
                         copy.deepcopy(data))
