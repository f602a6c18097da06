"""The values of a study's ``--vary``: the grammar a person types, and their SI view.

Values: a comma list (``"0.5 nm,1 nm,2 nm"``), a linear range ``"lo..hi:n"``, or a log range
``"lo..hi:n:log"`` (the unit of ``lo`` applies to ``hi`` when ``hi`` has none). A quantity
needs its unit, as in a scene file: ``"0.8..1.2:3"`` gives the bare numbers 0.8, 1.0, 1.2,
which a length key refuses with the file's one-line error (never 0.8 m silently); plain
numbers are for dimensionless and integer keys (``solver.nodes``, a relative pressure).
"""
import math
import re

import numpy as np

from ..errors import SceneError

_RANGE = re.compile(r"^\s*(?P<lo>[^.:]+(?:\.\d+)?(?:[eE][-+]?\d+)?[^.:]*?)\s*\.\.\s*"
                    r"(?P<hi>[^:]+?)\s*:\s*(?P<n>\d+)\s*(?::\s*(?P<log>log|lin))?\s*$")

#: the SI unit a study table's column carries in its header, by dimension
#: (``effects.asperity_gap.sigma_m``); N/m is J/m^2, a stiffness or a surface energy
SI_SUFFIX = {"length": "m", "pressure": "Pa", "energy": "J", "surface_energy": "N_per_m",
             "temperature": "K", "areal_density": "per_m2", "molar_volume": "m3_per_mol"}


def parse_values(spec, key="(value)"):
    """The list of values of one ``--vary`` spec (see the module docstring).

    Parameters
    ----------
    spec : str or list
        The spec as typed (a list is taken as the values themselves).
    key : str
        The dotted key, for the error message.

    Returns
    -------
    list
        Strings with their unit ("0.8 nm"), ints for integer ranges, floats otherwise.

    Raises
    ------
    SceneError
        A malformed spec: one line naming the key, the spec and the grammar.
    """
    if isinstance(spec, list):
        return list(spec)
    if not isinstance(spec, str) or not spec.strip():
        raise SceneError("study", key, spec, "a comma list of values or a range 'lo..hi:n'")
    m = _RANGE.match(spec)
    if m and ".." in spec:
        lo_txt, hi_txt, n = m.group("lo").strip(), m.group("hi").strip(), int(m.group("n"))
        if n < 1:
            raise SceneError("study", key, spec, "a range with at least 1 point")
        lo_v, lo_u = _split(lo_txt, key, spec)
        hi_v, hi_u = _split(hi_txt, key, spec)
        unit = lo_u or hi_u
        if lo_u and hi_u and lo_u != hi_u:
            raise SceneError("study", key, spec, "a range whose ends have the same unit")
        if m.group("log") == "log":
            if lo_v <= 0 or hi_v <= 0:
                raise SceneError("study", key, spec, "a log range of positive values")
            vals = np.geomspace(lo_v, hi_v, n)
        else:
            vals = np.linspace(lo_v, hi_v, n)
        if not unit and _is_int(lo_txt) and _is_int(hi_txt) and m.group("log") != "log" \
                and np.all(vals == np.round(vals)):
            return [int(v) for v in vals]          # an integer key (e.g. solver.nodes)
        # 12 significant digits: 0.45, not linspace's 0.44999999999999996 (a value a user
        # reads in the table and types again)
        return [f"{v:.12g} {unit}" if unit else float(f"{v:.12g}") for v in vals]
    out = []
    for item in spec.split(","):
        item = item.strip()
        if not item:
            continue
        for cast in (int, float):
            try:
                out.append(cast(item))
                break
            except ValueError:
                continue
        else:
            out.append(item)
    if not out:
        raise SceneError("study", key, spec, "at least one value")
    return out


def _is_int(text):
    return re.fullmatch(r"[-+]?\d+", text.strip()) is not None


def _split(text, key, spec):
    m = re.match(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(.*)$", text)
    if not m:
        raise SceneError("study", key, spec, "a range of numbers with an optional unit, "
                         "e.g. '0.2 nm..2 nm:10'")
    return float(m.group(1)), m.group(2).strip()


def si_value(value):
    """(SI float, dimension) of a study value; (value, None) for a number or a word.

    A string with a unit is tried against every dimension of :data:`SI_SUFFIX` (the key's
    own validation has already accepted it, so exactly one fits)."""
    from ..units import to_si

    if isinstance(value, bool) or not isinstance(value, (str, int, float)):
        return value, None
    if not isinstance(value, str):
        return value, None
    for dim in SI_SUFFIX:
        try:
            return to_si(value, dim), dim
        except SceneError:
            continue
    try:
        return float(value), None           # a number typed as a string ("0.5")
    except ValueError:
        return value, None


def si_columns(points):
    """The table's columns of the varied keys: ``[(header, key, dimension or None)]``; a key
    whose values all carry one dimension is written in SI with the unit in its header."""
    keys = list(points[0].changes) if points else []
    out = []
    for k in keys:
        dims = {si_value(p.changes[k])[1] for p in points}
        dim = dims.pop() if len(dims) == 1 else None
        out.append((f"{k}_{SI_SUFFIX[dim]}" if dim else k, k, dim))
    return out


def mask_numbers(text):
    """A reason with its numbers blanked, so that failures differing only in where they
    happened (d = 1.2 nm, residual 3e-9) group under one line."""
    return re.sub(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?", "#", str(text))


def is_finite_number(v):
    """Whether ``v`` is a finite real number (not a bool)."""
    return (isinstance(v, (int, float)) and not isinstance(v, bool)
            and math.isfinite(v))
