"""Scene readers of the liquid vocabulary shared by contact and meniscus scenes: a liquid (a
built-in name or a table) and an adsorption isotherm (a table with a model)."""
from ..meniscus.isotherms import BET, GAB, Polynomial, Tabulated
from ..meniscus.liquids import LIQUIDS, Liquid
from ..schema import Key, Table
from .reader import BAD, quantity

LIQUID_TABLE = Table("liquid", "A liquid given by its properties.", (
    Key("name", "string", "A label for the outputs.", default="user liquid"),
    Key("surface_tension", "surface_energy", "gamma (e.g. '22 mN/m').", lo=0.0),
    Key("molar_volume", "molar_volume", "V_m (e.g. '58.7 cm^3/mol').", lo=0.0),
))

ISOTHERM_MODELS = ("gab", "bet", "polynomial", "tabulated", "none")
ISOTHERM_TABLES = {
    "gab": Table("isotherm", "Guggenheim-Anderson-de Boer: h = t_m c k x / ((1 - k x)"
                 "(1 - k x + c k x)).", (
        Key("model", "choice", "The isotherm model.", choices=ISOTHERM_MODELS),
        Key("monolayer", "length", "Monolayer thickness t_m.", lo=0.0),
        Key("c", "number", "Energy constant c.", lo=0.0),
        Key("k", "number", "Multilayer factor k (< 1 keeps the film finite at saturation).",
            lo=0.0, hi=1.0))),
    "bet": Table("isotherm", "Brunauer-Emmett-Teller: h = t_m c x / ((1 - x)(1 - x + c x)).", (
        Key("model", "choice", "The isotherm model.", choices=ISOTHERM_MODELS),
        Key("monolayer", "length", "Monolayer thickness t_m.", lo=0.0),
        Key("c", "number", "Energy constant c.", lo=0.0))),
    "polynomial": Table("isotherm", "h = sum_i a_i x^i.", (
        Key("model", "choice", "The isotherm model.", choices=ISOTHERM_MODELS),
        Key("coefficients", "custom", "Lengths a_0, a_1, ..., lowest order first.",
            parse=lambda r, raw, path: _lengths(r, raw, path, positive=False),
            expect="a list of lengths, lowest order first"))),
    "tabulated": Table("isotherm", "Measured (p/psat, thickness) pairs, linear in between.", (
        Key("model", "choice", "The isotherm model.", choices=ISOTHERM_MODELS),
        Key("p_ratio", "custom", "Increasing p/psat values in (0, 1).",
            parse=lambda r, raw, path: _ratios(r, raw, path),
            expect="a list of increasing numbers in (0, 1)"),
        Key("thickness", "custom", "Film thickness at each p_ratio.",
            parse=lambda r, raw, path: _lengths(r, raw, path, positive=False),
            expect="a list of lengths as long as p_ratio"))),
    "none": Table("isotherm", "No adsorbed film.", (
        Key("model", "choice", "The isotherm model.", choices=ISOTHERM_MODELS),)),
}


def read_liquid(reader, raw, path):
    """A built-in liquid by name, or a user liquid from a table (Liquid, or BAD)."""
    if isinstance(raw, str):
        if raw not in LIQUIDS:
            return reader.fail(path, raw, f"one of {sorted(LIQUIDS)} or a table "
                               "{ name, surface_tension, molar_volume }")
        return LIQUIDS[raw]
    if not isinstance(raw, dict):
        return reader.fail(path, raw, "a liquid name or a table")
    v = reader.read(LIQUID_TABLE, raw, path)
    if any(x is BAD for x in v.values()):
        return BAD
    return Liquid(v["name"], v["surface_tension"], v["molar_volume"], source="scene file")


def read_isotherm(reader, raw, path):
    """An isotherm (or None for model = 'none'; "default" where the key was not given)."""
    if raw == "default":
        return "default"
    if not isinstance(raw, dict):
        return reader.fail(path, raw, "a table with model = " + " | ".join(ISOTHERM_MODELS))
    model = raw.get("model")
    if not isinstance(model, str) or model not in ISOTHERM_TABLES:
        return reader.fail(f"{path}.model", model, "one of " + ", ".join(
            repr(m) for m in ISOTHERM_MODELS))
    v = reader.read(ISOTHERM_TABLES[model], raw, path)
    if any(x is BAD for x in v.values()):
        return BAD
    if model == "none":
        return None
    if model == "gab":
        return GAB(v["monolayer"], v["c"], v["k"], "scene file")
    if model == "bet":
        return BET(v["monolayer"], v["c"], "scene file")
    if model == "polynomial":
        return Polynomial(tuple(v["coefficients"]), "scene file")
    if len(v["thickness"]) != len(v["p_ratio"]):
        return reader.fail(f"{path}.thickness", raw.get("thickness"),
                           "a list as long as p_ratio")
    try:
        return Tabulated(tuple(v["p_ratio"]), tuple(v["thickness"]), "scene file")
    except ValueError as exc:
        return reader.fail(f"{path}.p_ratio", raw.get("p_ratio"), str(exc))


def _lengths(reader, raw, path, *, positive=True):
    if not isinstance(raw, list) or not raw:
        return reader.fail(path, raw, "a non-empty list of lengths")
    out = [quantity(reader, x, f"{path}[{i}]", "length", positive=positive)
           for i, x in enumerate(raw)]
    return BAD if any(x is BAD for x in out) else out


def _ratios(reader, raw, path):
    if (not isinstance(raw, list) or len(raw) < 2
            or any(isinstance(x, bool) or not isinstance(x, (int, float)) or not 0 < x < 1
                   for x in raw)):
        return reader.fail(path, raw, "a list of at least 2 numbers in (0, 1)")
    return [float(x) for x in raw]
