"""``[instrument]``: the spring in series with the contact (an AFM cantilever as calibrated, or
a MEMS beam from its geometry); the drive is the spring's base z, swept over the scene's range.

    [instrument]
    stiffness = "0.5 N/m"                         # as calibrated, or one of:
    cantilever = { length = "200 um", width = "30 um", thickness = "2 um",
                   youngs_modulus = "169 GPa" }    # end-loaded: k = E w t^3 / (4 L^3)
    bridge = { ... }                               # fixed-fixed, centre load: k = 16 E w t^3 / L^3
    rest_gap = "2 um"                              # optional: the MEMS verdict, stuck or free
"""
from ..instrument import Spring
from ..schema import Key, Table
from .reader import BAD, any_bad

BEAM = Table("instrument.cantilever", "A rectangular beam (Euler-Bernoulli): the cantilever "
             "is loaded at its free end, the bridge (fixed-fixed) at its middle.", (
    Key("length", "length", "Beam length L.", lo=0.0),
    Key("width", "length", "Beam width w.", lo=0.0),
    Key("thickness", "length", "Beam thickness t (in the direction of the load).", lo=0.0),
    Key("youngs_modulus", "pressure", "Young's modulus E of the beam.", lo=0.0),
))


def _beam(kind):
    def parse(reader, raw, path):
        if raw is None:
            return None
        v = reader.read(BEAM, raw, path)
        return BAD if any_bad(v) else Spring.beam(kind, v["length"], v["width"],
                                                  v["thickness"], v["youngs_modulus"])
    return parse


INSTRUMENT = Table("instrument", "The spring in series with the contact: an AFM cantilever or "
                   "a MEMS suspension. The drive is the spring's base position z = d + F_ex/k "
                   "(the piezo); the instrument jumps where the contact's stiffness meets the "
                   "spring's and records F_instrument = k (z - d). Give exactly one of "
                   "stiffness, cantilever, bridge.", (
    Key("stiffness", "stiffness", "Spring constant k, as calibrated (AFM cantilevers "
        "0.01-50 N/m).", default=None, lo=0.0),
    Key("cantilever", "custom", "An end-loaded cantilever { length, width, thickness, "
        "youngs_modulus }: k = E w t^3 / (4 L^3).", default=None, parse=_beam("cantilever"),
        expect="a table { length, width, thickness, youngs_modulus }"),
    Key("bridge", "custom", "A fixed-fixed bridge loaded at its middle { length, width, "
        "thickness, youngs_modulus }: k = 16 E w t^3 / L^3.", default=None,
        parse=_beam("bridge"), expect="a table { length, width, thickness, youngs_modulus }"),
    Key("rest_gap", "length", "Where the suspension holds the part at rest (the base z at "
        "rest, a separation). With it the run gives the MEMS verdict: a part pressed into "
        "contact stays stuck iff, with its base back at the rest gap, the instrument still "
        "holds it near contact (the adhesion balancing k (rest_gap - d)) - it has not jumped "
        "out, nor peeled off, before z returned to the rest gap.",
        default=None, lo=0.0),
))


def read_instrument(reader, raw):
    """The scene's Spring, None without an [instrument] table, or BAD (errors recorded)."""
    if raw is None:
        return None
    v = reader.read(INSTRUMENT, raw, "instrument")
    if any_bad(v):
        return BAD
    given = [k for k in ("stiffness", "cantilever", "bridge") if v[k] is not None]
    if len(given) != 1:
        return reader.fail("instrument", raw, "exactly one of stiffness, cantilever, bridge "
                           f"(this table gives {', '.join(given) or 'none'})")
    spring = Spring(v["stiffness"]) if given[0] == "stiffness" else v[given[0]]
    return spring if v["rest_gap"] is None else spring.at_rest_gap(v["rest_gap"])
