"""Reading one table of a scene file with key-by-key checks; every error names the file, the
key, the value and what was expected."""
import math

from ..errors import SceneError, _MISSING
from ..units import to_si


class Reader:
    """Reads one table with key-by-key checks; remembers the file for error messages."""

    def __init__(self, file, table, prefix):
        self.file, self.table, self.prefix = file, table, prefix
        self.used = set()

    def key(self, k):
        return f"{self.prefix}.{k}" if self.prefix else k

    def error(self, k, value, expected):
        return SceneError(self.file, self.key(k), value, expected)

    def raw(self, k, default=_MISSING):
        self.used.add(k)
        if k in self.table:
            return self.table[k]
        if default is _MISSING:
            raise self.error(k, _MISSING, "this key (it is required)")
        return default

    def quantity(self, k, dim, *, default=_MISSING, positive=True):
        v = self.raw(k, default)
        x = to_si(v, dim, file=self.file, key=self.key(k))
        if not math.isfinite(x):
            raise self.error(k, v, "a finite value")
        if positive and not x > 0:
            raise self.error(k, v, f"a positive {dim.replace('_', ' ')}")
        return x

    def choice(self, k, options, default=_MISSING):
        v = self.raw(k, default)
        if v not in options:
            raise self.error(k, v, "one of " + ", ".join(repr(o) for o in options))
        return v

    def integer(self, k, lo, default=_MISSING):
        v = self.raw(k, default)
        if isinstance(v, bool) or not isinstance(v, int) or v < lo:
            raise self.error(k, v, f"an integer >= {lo}")
        return v

    def table_at(self, k, default=_MISSING):
        v = self.raw(k, default)
        if v is not None and not isinstance(v, dict):
            raise self.error(k, v, "a table")
        return v

    def done(self, allowed=None):
        allowed = set(allowed or []) | self.used
        for k in self.table:
            if k not in allowed:
                raise self.error(k, self.table[k], "no such key here; allowed keys are "
                                 + ", ".join(sorted(allowed)))


def scene_name(top, file):
    """The [scene] table's name, validated (shared by contact and meniscus scenes)."""
    s = Reader(file, top.table_at("scene"), "scene")
    name = s.raw("name")
    if not isinstance(name, str) or not name:
        raise s.error("name", name, "a non-empty string")
    s.done()
    return name
