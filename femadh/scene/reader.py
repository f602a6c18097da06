"""Reading scene tables against their declarative descriptions (:mod:`femadh.schema`).

Every problem is collected - unknown keys (with a "did you mean"), missing keys, wrong units or
types, values out of range - and reported together: each names the file, the key, the value and
what was expected.
"""
import difflib
import math
import numbers

from ..errors import SceneError, SceneErrors, _MISSING
from ..units import DIMENSIONS, to_si


class _Bad:
    def __repr__(self):
        return "(invalid)"


#: the value of a key that failed its check (its error is recorded)
BAD = _Bad()


class Reader:
    """Reads the tables of one scene, collecting errors.

    Parameters
    ----------
    file : str or None
        The scene file (for messages).
    bare_numbers : bool
        Whether a plain number is SI for a dimensional key (scenes built in code) or an error
        (scene files: ``radius = 2`` would silently mean 2 m).
    kinds : dict, optional
        ``kind -> parse(reader, raw, path)`` for structured key kinds ("liquid", "isotherm").
    strict : iterable of str, optional
        Dotted keys (and the tables under them) where a bare number is refused even when
        ``bare_numbers`` is true: the keys a person just typed (:meth:`Scene.replace`, a
        study's ``--vary``), while the rest of a code-built scene stays SI.
    """

    def __init__(self, file, *, bare_numbers=False, kinds=None, strict=()):
        self.file, self.bare_numbers = file, bare_numbers
        self.strict = tuple(strict)
        # parsers of the structured kinds ("liquid", "isotherm": scene.liquids), given by the
        # caller so that this base reader imports no table of its own
        self.kinds = dict(kinds or {})
        self.errors = []
        # keys an unknown key was taken for (dotted paths): a typo's "did you mean" line
        # stands for their "missing" line too
        self.suggested = set()

    def bare_ok(self, path):
        """Whether a bare number is SI (not an error) at the dotted ``path``."""
        return self.bare_numbers and not any(
            path == s or path.startswith(s + ".") for s in self.strict)

    def fail(self, path, value, expected):
        """Record an error; returns BAD."""
        self.errors.append(SceneError(self.file, path, value, expected))
        return BAD

    def finish(self):
        """Raise every recorded error at once."""
        if len(self.errors) == 1:
            raise self.errors[0]
        if self.errors:
            raise SceneErrors(self.errors)

    def read(self, table, data, path=None, *, missing=None):
        """Values (SI) of the keys of ``table`` from the dict ``data`` (None: all defaults).

        Unknown keys are errors; missing required keys are errors; a key that fails is BAD.
        ``missing``: the table is required (what to expect, in words): without it that is the
        one error, its required keys BAD without a line each (one typo, one line).
        """
        path = table.path if path is None else path
        absent = data is None and missing is not None
        if absent and path not in self.suggested:
            self.fail(path, _MISSING, missing)
        if data is None:
            data = {}
        if not isinstance(data, dict):
            self.fail(path or "(top level)", data, "a table")
            return {k.name: BAD for k in table.keys}
        names = table.names
        for name in data:
            if name not in names:
                self.unknown(path, name, data[name], names)
        out = {}
        for key in table.keys:
            full = f"{path}.{key.name}" if path else key.name
            if key.name in data:
                out[key.name] = self.value(key, data[key.name], full)
            elif key.required and (absent or full in self.suggested):
                out[key.name] = BAD
            elif key.required:
                out[key.name] = self.fail(full, _MISSING, f"{key.expected(_words(key))} "
                                          "(this key is required)")
            else:
                out[key.name] = self.value(key, key.default, full, default=True)
        return out

    def unknown(self, path, name, value, allowed):
        close = difflib.get_close_matches(str(name), allowed, n=1, cutoff=0.6)
        hint = f"did you mean '{close[0]}'? " if close else ""
        full = f"{path}.{name}" if path else str(name)
        self.fail(full, value, f"no such key here; {hint}allowed keys are "
                  + ", ".join(sorted(allowed)))
        if close:
            self.suggested.add(f"{path}.{close[0]}" if path else close[0])

    def value(self, key, raw, path, default=False):
        """One key's value in SI (or BAD, with its error recorded)."""
        if key.kind == "custom":
            return key.parse(self, raw, path)
        if key.kind in self.kinds:
            return self.kinds[key.kind](self, raw, path)
        if raw is None and default:
            return None
        if key.kind == "choice":
            return raw if raw in key.choices else self.fail(path, raw, key.expected())
        if key.kind == "bool":
            return raw if isinstance(raw, bool) else self.fail(path, raw, key.expected())
        if key.kind == "string":
            return raw if isinstance(raw, str) and raw else self.fail(path, raw,
                                                                      key.expected())
        if key.kind == "integer":
            # numbers.Integral: numpy integers from code-built scenes count too
            if isinstance(raw, bool) or not isinstance(raw, numbers.Integral) \
                    or not key.in_range(raw):
                return self.fail(path, raw, key.expected())
            return int(raw)
        if key.kind == "number":
            if isinstance(raw, bool) or not isinstance(raw, numbers.Real) \
                    or not math.isfinite(raw) or not key.in_range(raw):
                return self.fail(path, raw, key.expected())
            return float(raw)
        if key.kind in DIMENSIONS:
            try:
                x = to_si(raw, key.kind, file=self.file, key=path,
                          bare_numbers=self.bare_ok(path) or default)
            except SceneError as exc:
                self.errors.append(exc)
                return BAD
            if not math.isfinite(x) or not key.in_range(x):
                # a unit string out of range: say what it came to in the bounds' SI unit
                # ('2 furlongs' is 402.3 m, not a length in (0, 0.1 m])
                bounded = any(v not in (None, 0) for v in (key.lo, key.hi))
                si = (f"; it is {x:.4g} {DIMENSIONS[key.kind][1]}" if isinstance(raw, str)
                      and math.isfinite(x) and DIMENSIONS[key.kind][1] and bounded else "")
                return self.fail(path, raw, key.expected(_words(key)) + si)
            return x
        raise ValueError(f"unknown key kind {key.kind!r} of {path}")


def _words(key):
    """'a length', 'a pressure', ... for a dimensional key (from units.DIMENSIONS)."""
    if key.kind in DIMENSIONS:
        word = key.kind.replace("_", " ")
        return ("an " if word[0] in "aeiou" else "a ") + word
    return None


def quantity(reader, raw, path, dimension, *, positive=True):
    """A one-off quantity outside a Table (list items, sub-tables of custom keys)."""
    try:
        x = to_si(raw, dimension, file=reader.file, key=path, bare_numbers=reader.bare_ok(path))
    except SceneError as exc:
        reader.errors.append(exc)
        return BAD
    if not math.isfinite(x) or (positive and not x > 0):
        return reader.fail(path, raw, f"a positive {dimension.replace('_', ' ')}")
    return x


def any_bad(*values):
    """Whether any value (or any item of a dict of values) failed its check."""
    for v in values:
        if v is BAD or (isinstance(v, dict) and any(x is BAD for x in v.values())):
            return True
    return False
