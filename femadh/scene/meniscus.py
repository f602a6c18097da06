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
from dataclasses import dataclass, field

import numpy as np

from ..meniscus.isotherms import default_isotherm
from ..meniscus.liquids import LIQUIDS
from ..meniscus.solve import METHODS
from .liquids import read_isotherm, read_liquid
from .reader import Reader, scene_name


@dataclass
class MeniscusScene:
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
    raw: dict = field(repr=False, default_factory=dict)

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


def parse_meniscus(top, file):
    """Build a MeniscusScene from the top-level _Reader of a scene file."""
    top.used |= {"scene", "meniscus", "output"}
    top.done({"scene", "meniscus", "output"})
    name = scene_name(top, file)
    m = Reader(file, top.table_at("meniscus"), "meniscus")
    radii_raw = m.raw("tip_radius")
    radii_list = radii_raw if isinstance(radii_raw, list) else [radii_raw]
    radii = []
    for i, v in enumerate(radii_list):
        sub = Reader(file, {"tip_radius": v}, "meniscus")
        radii.append(sub.quantity("tip_radius", "length"))
    sep_raw = m.raw("separation", "contact")
    separation = None if sep_raw == "contact" else m.quantity("separation", "length",
                                                              positive=False)
    if separation is not None and separation < 0:
        raise m.error("separation", sep_raw, "'contact' or a solid-solid gap >= 0")
    liq_raw = m.raw("liquid")
    liquids = [read_liquid(m, v) for v in (liq_raw if isinstance(liq_raw, list) else [liq_raw])]
    temperature = m.quantity("temperature", "temperature", default="298.15 K")
    iso_raw = m.raw("isotherm", None)
    isotherms = {}
    for lq in liquids:
        if iso_raw is None:
            if lq.name not in LIQUIDS:
                raise m.error("isotherm", None, f"an isotherm table for the user liquid "
                              f"{lq.name!r} (or model = 'none')")
            isotherms[lq.name] = default_isotherm(lq.name)
        else:
            isotherms[lq.name] = read_isotherm(m, iso_raw)
    pr = m.raw("relative_pressure")
    if isinstance(pr, dict):
        r = Reader(file, pr, "meniscus.relative_pressure")
        start, stop, num = r.raw("start"), r.raw("stop"), r.integer("num", 2)
        r.done()
        p_ratios = list(np.linspace(start, stop, num)) if all(
            isinstance(v, (int, float)) for v in (start, stop)) else None
    else:
        p_ratios = pr if isinstance(pr, list) else None
    if not p_ratios or any(isinstance(x, bool) or not isinstance(x, (int, float))
                           or not 0 < x < 1 for x in p_ratios):
        raise m.error("relative_pressure", pr, "a list of numbers in (0, 1), or "
                      "{ start, stop, num } inside (0, 1)")
    methods = m.raw("methods", list(METHODS))
    if not isinstance(methods, list) or not methods or any(x not in METHODS for x in methods):
        raise m.error("methods", methods, f"a list drawn from {list(METHODS)}")
    elements = m.integer("elements", 2, 16)
    m.done()
    ou = Reader(file, top.table_at("output", {}), "output")
    out_dir = ou.raw("dir", f"out/{name}")
    vtk = ou.raw("vtk", True)
    if not isinstance(vtk, bool):
        raise ou.error("vtk", vtk, "true or false")
    ou.done()
    return MeniscusScene(name, file, radii, separation, liquids, temperature, isotherms,
                         [float(x) for x in p_ratios], tuple(methods), elements, out_dir, vtk,
                         top.table)
