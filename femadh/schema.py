"""The declarative description of scene keys: name, kind (unit), range, default and doc.

One :class:`Key` per scene key; a :class:`Table` groups the keys of one TOML table. The scene
reader (:mod:`femadh.scene.reader`) interprets them - every check, every error message, the
"did you mean" suggestions and the reference page (``femadh keys``) come from these
descriptions, so a key is described once. Laws register their own tables
(:mod:`femadh.laws.registry`).

Kinds: a dimension of :data:`femadh.units.DIMENSIONS` ("length", "pressure", "energy",
"surface_energy", "areal_density", "temperature", "molar_volume": a string with a unit, or a
plain number taken as SI in code-built scenes), "number" (dimensionless), "integer", "choice",
"bool", "string", and "custom" (a polymorphic value read by the key's ``parse`` function).
"""
from dataclasses import dataclass, field


class _Required:
    def __repr__(self):
        return "(required)"


#: default of a key that must be given
REQUIRED = _Required()


@dataclass(frozen=True)
class Key:
    """One scene key.

    Attributes
    ----------
    name : str
    kind : str
        See the module docstring.
    doc : str
        What the key means (with the paper's equation where there is one).
    default : object
        As written in a scene file (e.g. ``"10 nm"``), or REQUIRED.
    lo, hi : float or None
        Bounds in SI units; ``lo_closed``/``hi_closed`` say whether they are allowed.
    choices : tuple
        For kind "choice".
    parse : callable or None
        For kind "custom": ``parse(reader, raw, path) -> value`` (raises SceneError).
    expect : str
        For kind "custom": what the value should be, in words (errors and the reference).
    """

    name: str
    kind: str
    doc: str
    default: object = REQUIRED
    lo: float | None = None
    hi: float | None = None
    lo_closed: bool = False
    hi_closed: bool = False
    choices: tuple = ()
    parse: object = field(default=None, compare=False)
    expect: str = ""

    @property
    def required(self):
        return self.default is REQUIRED

    def expected(self, words=None):
        """The expectation in words, e.g. 'a length > 0' or 'a number in (0, 1)'."""
        if self.kind == "custom":
            return self.expect
        if self.kind == "choice":
            return "one of " + ", ".join(repr(c) for c in self.choices)
        if self.kind == "bool":
            return "true or false"
        if self.kind == "string":
            return "a non-empty string"
        base = words or {"number": "a number", "integer": "an integer"}.get(self.kind, self.kind)
        return base + self.range_words()

    def range_words(self):
        from .units import DIMENSIONS

        # bounds are SI: a nonzero one names its unit ("a length in (0, 0.1 m]": a bare 0.1
        # reads as the scene's own unit, e.g. mm)
        unit = DIMENSIONS[self.kind][1] if self.kind in DIMENSIONS else ""

        def b(x):
            return f"{x:g} {unit}" if unit and x != 0 else f"{x:g}"
        lo, hi = self.lo, self.hi
        if lo is not None and hi is not None:
            return (f" in {'[' if self.lo_closed else '('}{b(lo)}, {b(hi)}"
                    f"{']' if self.hi_closed else ')'}")
        if lo is not None:
            return f" {'>=' if self.lo_closed else '>'} {b(lo)}"
        if hi is not None:
            return f" {'<=' if self.hi_closed else '<'} {b(hi)}"
        return ""

    def in_range(self, x):
        if self.lo is not None and not (x >= self.lo if self.lo_closed else x > self.lo):
            return False
        if self.hi is not None and not (x <= self.hi if self.hi_closed else x < self.hi):
            return False
        return True


@dataclass(frozen=True)
class Table:
    """The keys of one TOML table (dotted ``path``, e.g. ``"effects.lennard_jones"``)."""

    path: str
    doc: str
    keys: tuple

    def key(self, name):
        return next((k for k in self.keys if k.name == name), None)

    @property
    def names(self):
        return [k.name for k in self.keys]
