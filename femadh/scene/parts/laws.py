"""The surface laws of a contact scene ([effects]): the sigma-gap and the laws the law registry
builds, with the table of the sigma-gap's keys (each law's table is its registration's,
:mod:`femadh.laws.registry`).
"""
from dataclasses import asdict, dataclass
import math

from ...contact.constraints import CONTACT_MODELS, AsperityGap
from ...laws.registry import BuildContext, registry
from ...schema import Key, Table
from ..reader import BAD, any_bad
from ..topography import resolve as resolve_topography
from .frozen import FrozenMap, frozen_map

GAP = Table("effects.asperity_gap", "The minimum gap sigma set by compressed asperities, "
            "paper 1 eq (8): h >= sigma.", (
    Key("sigma", "length", "Spacing of the mean planes in contact (Figs 3/4: 1 and 0.5 nm).",
        lo=0.0),
    Key("contact_model", "choice", "'complementarity': h >= sigma, p_c >= 0, p_c (h - sigma) "
        "= 0, exact; 'hertz-closure': the paper's Hertz-shaped contact pressure (eq 9) with "
        "the contact radius a continuous unknown.", default="complementarity",
        choices=CONTACT_MODELS),
))


@dataclass(frozen=True)
class Laws:
    """What acts between the surfaces, SI units.

    Attributes
    ----------
    effects : FrozenMap
        Law name -> law ("lj", "capillary", "asperity_adhesion", ...), paper 1 eqs (1), (20).
    gap : AsperityGap or None
        The sigma-gap h >= sigma of compressed asperities, paper 1 eq (8), with the adhesion
        the laws put on its contact set.
    topography : FrozenMap or None
        The resolved [effects.*.topography] tables (the asperity statistics the laws came
        from), or None.
    """

    effects: FrozenMap
    gap: AsperityGap | None = None
    topography: FrozenMap | None = None

    def __post_init__(self):
        object.__setattr__(self, "effects", frozen_map(dict(self.effects)))
        object.__setattr__(self, "topography", frozen_map(self.topography or None))


def law_dict(law):
    """A law's fields as plain values (for summary.json)."""
    out = {}
    for k, v in asdict(law).items():
        out[k] = v if isinstance(v, (int, float, str, type(None))) else repr(v)
    return out


def read_effects(reader, table, e_star, topography):
    """The sigma-gap and the laws the [effects.*] tables name (through the law registry);
    an asperity section's ``topography`` is resolved into ``topography`` (scene/topography)."""
    if table is None or not isinstance(table, dict) or not table:
        reader.fail("effects", table, "at least one surface force effect, e.g. "
                    "[effects.lennard_jones]")
        return None, {}
    reg = registry()
    allowed = ["asperity_gap"] + list(reg)
    for name in table:
        if name not in allowed:
            reader.unknown("effects", name, table[name], allowed)
    gap = None
    if "asperity_gap" in table:
        g = reader.read(GAP, table["asperity_gap"], "effects.asperity_gap")
        if not any_bad(g):
            gap = AsperityGap(g["sigma"], g["contact_model"])
    if "asperity_adhesion" in table and "asperity_gap" not in table:
        reader.fail("effects.asperity_adhesion", table["asperity_adhesion"], "an "
                    "[effects.asperity_gap] as well: eq 20 acts over the sigma-gap contact "
                    "region")
        return gap, {}
    if "asperity_contact" in table and "asperity_gap" in table:
        reader.fail("effects.asperity_contact", table["asperity_contact"], "no "
                    "[effects.asperity_gap]: the Greenwood-Williamson model replaces the hard "
                    "sigma-gap")
    effects, adhesion = {}, 0.0
    ctx = BuildContext(e_star if e_star is not BAD else math.nan,
                       None if gap is None else gap.sigma)
    for name, entry in reg.items():
        if name not in table:
            continue
        raw = resolve_topography(reader, table[name], f"effects.{name}", entry.table,
                                 topography)
        if raw is BAD:
            continue
        values = reader.read(entry.table, raw, f"effects.{name}")
        if any_bad(values) or e_star is BAD:
            continue
        built = entry.build(values, ctx)
        effects.update(built.laws)
        adhesion += built.gap_adhesion
    if gap is not None and adhesion:
        gap = AsperityGap(gap.sigma, gap.contact_model, adhesion)
    if gap is not None and gap.contact_model == "hertz-closure":
        if "asperity_adhesion" in effects:
            reader.fail("effects.asperity_adhesion.model", "smoothed", "'contact-set' with "
                        "contact_model = 'hertz-closure' (the closure applies eq 20 over "
                        "r < r_c exactly)")
        if "lj" not in effects:
            reader.fail("effects.asperity_gap.contact_model", gap.contact_model,
                        "'complementarity' unless [effects.lennard_jones] is present")
    # (a bare sigma-gap without laws is Hertz contact, A = 0: a valid limit)
    if not effects and gap is None and not reader.errors:
        reader.fail("effects", sorted(table), "at least one surface force effect, e.g. "
                    "[effects.lennard_jones]")
    return gap, effects
