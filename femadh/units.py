"""Units: scene quantities are strings with units ("2 mm"), parsed with pint; plain numbers are SI.

Inside femadh every quantity is a float in SI units. This module is the only place that
knows about pint, and pint is imported lazily so that the numerical core never pays for it.
"""
from functools import lru_cache
import numbers

from .errors import SceneError


@lru_cache(maxsize=1)
def _registry():
    import pint

    ureg = pint.UnitRegistry()
    return ureg


#: dimension name -> (pint dimensionality string, SI unit it is converted to, words for errors)
DIMENSIONS = {
    "length": ("[length]", "m", "a length such as '2 mm' or '0.165 nm'"),
    "pressure": ("[mass] / [length] / [time] ** 2", "Pa", "a pressure such as '163 GPa'"),
    "energy": ("[mass] * [length] ** 2 / [time] ** 2", "J", "an energy such as '1e-19 J'"),
    "surface_energy": ("[mass] / [time] ** 2", "J/m^2", "a surface energy such as '0.06 J/m^2'"),
    "areal_density": ("1 / [length] ** 2", "1/m^2", "an areal density such as '100 um^-2'"),
    "temperature": ("[temperature]", "K", "a temperature such as '298.15 K'"),
    "molar_volume": ("[length] ** 3 / [substance]", "m^3/mol", "a molar volume such as '58.7 cm^3/mol'"),
    "stiffness": ("[mass] / [time] ** 2", "N/m", "a stiffness such as '0.5 N/m'"),
    "time": ("[time]", "s", "a duration such as '10 min' or '90 s'"),
    "dimensionless": ("", "", "a plain number"),
}


_NUMBER_UNIT = None

#: a temperature written with a letter pint reads as another unit ('25 C' is 25 coulomb)
_TEMPERATURE_HINTS = {"C": " (C is the coulomb: Celsius is 'degC')",
                      "F": " (F is the farad: Fahrenheit is 'degF')",
                      "k": " (k is the Boltzmann constant: kelvin is 'K')"}

_PREFIX = {"": 1.0, "k": 1e3, "M": 1e6, "G": 1e9, "T": 1e12, "m": 1e-3, "u": 1e-6, "µ": 1e-6,
           "n": 1e-9, "p": 1e-12, "f": 1e-15, "a": 1e-18, "z": 1e-21, "c": 1e-2}


def _table():
    """unit text -> (dimension, factor to SI) for the units scenes use most; everything else
    goes to pint. (Loading pint costs ~0.4 s, a third of a small run's wall time.)"""
    t = {}
    for pre, f in _PREFIX.items():
        t[pre + "m"] = ("length", f)
        t[pre + "Pa"] = ("pressure", f)
        t[pre + "J"] = ("energy", f)
        t[pre + "N/m"] = ("surface_energy", f)
        t[pre + "J/m^2"] = ("surface_energy", f)
        t[pre + "m^-2"] = ("areal_density", f**-2)
    t["K"] = ("temperature", 1.0)
    t["cm^3/mol"] = ("molar_volume", 1e-6)
    t["m^3/mol"] = ("molar_volume", 1.0)
    t["mol/m^3"] = None                      # (not a molar volume: let pint say so)
    return {k: v for k, v in t.items() if v is not None}


_FAST = None


def _fast(text, dimension):
    """SI value of 'number unit' for the units of :func:`_table` (None: ask pint)."""
    global _FAST
    if _FAST is None:
        _FAST = _table()
    mag, unit = _split(text)
    if mag is None or not unit:
        return None
    hit = _FAST.get(unit.replace("**", "^").replace(" ", ""))
    # a stiffness (N/m) shares its dimension with a surface energy: same table entry
    if hit is None or DIMENSIONS[hit[0]][0] != DIMENSIONS[dimension][0]:
        return None
    return float(mag) * hit[1]


def _split(text):
    """('25', 'degC') from '25 degC': offset units (degC, degF) need the magnitude apart."""
    import re

    global _NUMBER_UNIT
    if _NUMBER_UNIT is None:
        _NUMBER_UNIT = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(.*?)\s*$")
    m = _NUMBER_UNIT.match(text)
    return (m.group(1), m.group(2)) if m else (None, None)


def to_si(value, dimension, *, file=None, key=None, bare_numbers=True):
    """Convert a scene value to a float in SI units.

    Parameters
    ----------
    value : str or float or int
        ``"2 mm"``-style string (any unit pint knows, offset temperatures such as "25 degC"
        included) or a plain number, taken as SI.
    dimension : str
        One of :data:`DIMENSIONS`.
    file, key : str, optional
        Where the value came from, for the error message.
    bare_numbers : bool
        Whether a plain number is accepted as SI for a dimensional quantity. Scene *files*
        refuse it (``radius = 2`` would silently mean 2 m); scenes built in code accept it.

    Raises
    ------
    SceneError
        If the value is not a number or does not have the expected dimension.
    """
    dim, si, words = DIMENSIONS[dimension]
    if isinstance(value, bool):
        raise SceneError(file, key, value, words)
    if isinstance(value, numbers.Real):
        if not bare_numbers and dimension != "dimensionless":
            raise SceneError(file, key, value, f"{words}: a bare number has no unit (write it "
                             f"with its unit, e.g. '{value:g} {si.replace('^', '')}' if SI is "
                             "meant)")
        return float(value)
    if not isinstance(value, str):
        raise SceneError(file, key, value, words)
    fast = _fast(value, dimension) if dimension != "dimensionless" else None
    if fast is not None:
        return fast
    ureg = _registry()
    mag, unit = _split(value)
    try:
        if mag is not None and unit:
            q = ureg.Quantity(float(mag), unit.replace("^", "**"))
        else:
            q = ureg.Quantity(value.replace("^", "**"))
    except Exception as exc:  # pint raises many types for unparsable input
        if mag is not None and unit and type(exc).__name__ == "UndefinedUnitError":
            raise SceneError(file, key, value, f"{words}; '{unit}' is not a recognised unit"
                             f"{_case_twin(unit, dimension)}") from None
        raise SceneError(file, key, value, f"{words} (could not parse: {exc})") from None
    if not isinstance(q, ureg.Quantity):
        return float(q)
    if dimension == "dimensionless":
        if not q.dimensionless:
            raise SceneError(file, key, value, words)
        return float(q.to("").magnitude)
    if q.dimensionless:
        raise SceneError(file, key, value, f"{words}; a bare number in a string has no unit")
    if not q.check(dim):
        short = f"{q.units:~}"
        hint = _TEMPERATURE_HINTS.get(short, "") if dimension == "temperature" else ""
        if hint or not (mag is not None and unit):
            raise SceneError(file, key, value, f"{words}, but it has units of {short}{hint}")
        # a unit of another kind ('2 kg' for a length, or '2 MM', which pint reads as 2
        # megamolar): "has units of MM" read as if MM were a length unit; quote the user's
        # text, say what pint took it for, and the same letters in another case if they fit
        kind = words.split(" such as")[0].split(" ", 1)[-1]
        raise SceneError(file, key, value, f"{words}; '{unit}' is not a {kind} unit (pint "
                         f"reads it as {q.units}){_case_twin(unit, dimension)}")
    return float(q.to(si.replace("^", "**")).magnitude)


def _case_twin(unit, dimension):
    """``"; did you mean 'mm'?"`` when ``unit`` written in another case is a unit of
    ``dimension`` ('MM' -> 'mm', 'NM' -> 'nm'; pint's units are case-sensitive), else ""."""
    global _FAST
    if _FAST is None:
        _FAST = _table()
    dim = DIMENSIONS[dimension][0]
    low = unit.lower()
    # the all-lower spelling first ('mm', not the megametre 'Mm')
    twins = [low] + [u for u in _FAST if u.lower() == low and u != low]
    for u in twins:
        if u == unit:
            continue
        hit = _FAST.get(u)
        if hit is not None:
            ok = DIMENSIONS[hit[0]][0] == dim
        else:
            try:
                ok = _registry().Quantity(1.0, u.replace("^", "**")).check(dim)
            except Exception:  # (not a unit either)
                ok = False
        if ok:
            return f"; did you mean '{u}'?"
    return ""
