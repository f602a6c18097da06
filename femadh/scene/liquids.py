"""Scene readers of the liquid vocabulary shared by contact and meniscus scenes: a liquid (a
built-in name or a table) and an adsorption isotherm (a table with a model)."""
from ..meniscus.isotherms import BET, GAB, Polynomial, Tabulated
from ..meniscus.liquids import LIQUIDS, Liquid
from .reader import Reader


def read_liquid(m, v):
    if isinstance(v, str):
        if v not in LIQUIDS:
            raise m.error("liquid", v, f"one of {sorted(LIQUIDS)} or a table "
                          "{ surface_tension, molar_volume }")
        return LIQUIDS[v]
    if not isinstance(v, dict):
        raise m.error("liquid", v, "a liquid name or a table")
    t = Reader(m.file, v, "meniscus.liquid")
    lq = Liquid(t.raw("name", "user liquid"), t.quantity("surface_tension", "surface_energy"),
                t.quantity("molar_volume", "molar_volume"), source="scene file")
    t.done()
    return lq


def read_isotherm(m, v):
    if not isinstance(v, dict):
        raise m.error("isotherm", v, "a table with model = gab | bet | polynomial | tabulated "
                      "| none")
    t = Reader(m.file, v, "meniscus.isotherm")
    model = t.choice("model", ("gab", "bet", "polynomial", "tabulated", "none"))
    if model == "none":
        iso = None
    elif model in ("gab", "bet"):
        tm = t.quantity("monolayer", "length")
        c = t.raw("c")
        if isinstance(c, bool) or not isinstance(c, (int, float)) or not c > 0:
            raise t.error("c", c, "a positive number")
        if model == "gab":
            k = t.raw("k")
            if isinstance(k, bool) or not isinstance(k, (int, float)) or not 0 < k < 1:
                raise t.error("k", k, "a number in (0, 1)")
            iso = GAB(tm, float(c), float(k), "scene file")
        else:
            iso = BET(tm, float(c), "scene file")
    elif model == "polynomial":
        co = t.raw("coefficients")
        if not isinstance(co, list) or not co:
            raise t.error("coefficients", co, "a list of lengths, lowest order first")
        iso = Polynomial(tuple(Reader(m.file, {"c": c}, "meniscus.isotherm.coefficients")
                               .quantity("c", "length", positive=False) for c in co),
                         "scene file")
    else:
        x, h = t.raw("p_ratio"), t.raw("thickness")
        if not isinstance(x, list) or not isinstance(h, list) or len(x) != len(h):
            raise t.error("thickness", h, "a list as long as p_ratio")
        hs = tuple(Reader(m.file, {"h": v2}, "meniscus.isotherm.thickness")
                   .quantity("h", "length", positive=False) for v2 in h)
        try:
            iso = Tabulated(tuple(float(a) for a in x), hs, "scene file")
        except ValueError as exc:
            raise t.error("p_ratio", x, str(exc)) from None
    t.done()
    return iso
