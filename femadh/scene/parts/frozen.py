"""What makes a scene's parts immutable and comparable by content: a read-only mapping for the
tables a part keeps as dicts, and a content hash of any part.

The hash is what a study keys its reused surface operators by (:func:`content_hash` of the
body and the discretisation): it is computed from every field of the parts, recursively, so
a field added to a part is in the key without anyone remembering to add it.
"""
import dataclasses
import hashlib
import json
import math
import numbers

import numpy as np


class FrozenMap(dict):
    """A dict that refuses changes (a part's ``effects``, its grid or topography table).

    It is a dict for every reader (``in``, ``items()``, ``dict(m)``, JSON), so the code that
    reads a scene's tables is unchanged; writing into one raises TypeError, as assigning to a
    frozen part's field raises FrozenInstanceError."""

    __slots__ = ()

    def _refuse(self, *args, **kwargs):
        raise TypeError("a scene's parts are frozen: build a new scene with "
                        "scene.replace({'dotted.key': value})")

    __setitem__ = __delitem__ = _refuse
    clear = pop = popitem = setdefault = update = _refuse
    __ior__ = _refuse

    def __reduce__(self):
        # pickle and deepcopy rebuild it whole (the default would set items one by one)
        return (type(self), (dict(self),))

    def __hash__(self):
        return hash(content_hash(self))


def frozen_map(value):
    """``value`` as a :class:`FrozenMap` (nested dicts too); None stays None."""
    if value is None or isinstance(value, FrozenMap):
        return value
    return FrozenMap({k: frozen_map(v) if isinstance(v, dict) else v for k, v in value.items()})


def canonical(obj):
    """A JSON-ready, order-independent description of ``obj``'s content.

    Dataclasses (the parts, the laws, materials, FE settings) by their type and every field;
    mappings by sorted key; floats exactly (JSON writes the shortest repr, which round-trips).

    Raises
    ------
    TypeError
        For a value whose content it cannot describe (an object known only by its identity):
        a key built from such a value would never match, or match the wrong thing.
    """
    if obj is None or isinstance(obj, str):
        return obj
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, numbers.Integral):
        return int(obj)
    if isinstance(obj, numbers.Real):
        x = float(obj)
        if not math.isfinite(x):
            return repr(x)          # JSON has no NaN/inf; as a string they stay distinct
        return x
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return {"__type__": f"{type(obj).__module__}.{type(obj).__qualname__}",
                **{f.name: canonical(getattr(obj, f.name)) for f in dataclasses.fields(obj)}}
    if isinstance(obj, dict):
        return {"__map__": sorted(([canonical(k), canonical(v)] for k, v in obj.items()),
                                  key=lambda kv: json.dumps(kv[0], sort_keys=True))}
    if isinstance(obj, (list, tuple)):
        return [canonical(x) for x in obj]
    if isinstance(obj, np.ndarray):
        return {"__array__": [canonical(x) for x in obj.ravel().tolist()],
                "shape": list(obj.shape)}
    raise TypeError(f"no content description for a {type(obj).__name__} ({obj!r}); give "
                    "it a dataclass or plain values")


def content_hash(*objs):
    """SHA-1 (hex, 40 digits) of the canonical description of ``objs``: equal exactly when
    every field of every object is equal (floats bit for bit)."""
    blob = json.dumps([canonical(o) for o in objs], sort_keys=True, allow_nan=False)
    return hashlib.sha1(blob.encode()).hexdigest()
