"""The sweep of a contact scene ([sweep], [instrument]): the separations the sphere is moved
through, the branches traced and the instrument that drives it, with the table of its keys
(the instrument's tables are :mod:`femadh.scene.instrument`'s).
"""
from dataclasses import dataclass

from ...schema import Key, Table
from ..reader import BAD, any_bad

DIRECTIONS = ("approach", "retract")
#: the largest number of separations a sweep may list
MAX_SEPARATIONS = 100000


def _directions(reader, raw, path):
    if (not isinstance(raw, list) or not raw or any(x not in DIRECTIONS for x in raw)
            or len(set(raw)) != len(raw)):
        return reader.fail(path, raw, "a list drawn from ['approach', 'retract']")
    return tuple(raw)


SWEEP = Table("sweep", "The separations d of the sphere tip above the undeformed mean plane.", (
    Key("start", "length", "First separation."),
    Key("stop", "length", "Last separation."),
    Key("step", "length", "Step between separations.", lo=0.0),
    Key("directions", "custom", "Branches to trace: approach (start -> stop) and/or retract.",
        default=["approach", "retract"], parse=_directions,
        expect="a list drawn from ['approach', 'retract']"),
))


@dataclass(frozen=True)
class Sweep:
    """What the run traces, SI units.

    Attributes
    ----------
    d_values : tuple of float
        The separations d (m) of the sphere tip above the undeformed mean plane, in the
        approach's order.
    directions : tuple of str
        "approach" (d_values in order) and/or "retract" (reversed).
    instrument : Spring or None
        The instrument's spring in series with the contact (None: the sphere is driven
        rigidly).
    """

    d_values: tuple
    directions: tuple
    instrument: object = None

    def __post_init__(self):
        object.__setattr__(self, "d_values", tuple(float(d) for d in self.d_values))
        object.__setattr__(self, "directions", tuple(self.directions))


def separations(reader, sw, raw):
    """The separations (m) of a [sweep] table: start to stop in whole steps."""
    if any_bad(sw):
        return BAD
    start, stop, step, dirs = sw["start"], sw["stop"], sw["step"], sw["directions"]
    if "approach" in dirs and not stop < start:
        reader.fail("sweep.stop", raw.get("stop"), f"a separation below start "
                    f"({raw.get('start')}) for an approach")
        return BAD
    if dirs == ("retract",) and not stop > start:
        reader.fail("sweep.stop", raw.get("stop"), f"a separation above start "
                    f"({raw.get('start')}) for a retract-only sweep")
        return BAD
    n_steps = abs(stop - start) / step
    if n_steps < 1:
        reader.fail("sweep.step", raw.get("step"), f"a step no longer than the sweep "
                    f"|stop - start| = {abs(stop - start):.6g} m")
        return BAD
    if n_steps > MAX_SEPARATIONS:
        reader.fail("sweep.step", raw.get("step"), f"a step giving at most "
                    f"{MAX_SEPARATIONS} separations (this one gives {n_steps:.3g})")
        return BAD
    k = round(n_steps)
    if abs(n_steps - k) > 1e-6:
        reader.fail("sweep.step", raw.get("step"), f"a step that divides |stop - start| = "
                    f"{abs(stop - start):.6g} m into whole steps")
        return BAD
    sign = -1.0 if stop < start else 1.0
    return [start + sign * i * step for i in range(k + 1)]
