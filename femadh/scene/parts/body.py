"""The body of a contact scene: the sphere and the flat, their elastic constants and the
flat's coatings ([sphere], [materials], [substrate]), with the tables that describe their keys.
"""
from dataclasses import dataclass

from ...indenter import PROFILES, Sphere
from ...materials import IsotropicMaterial, composite_modulus
from ...schema import Key, Table
from ..reader import BAD, any_bad

SPHERE = Table("sphere", "The rigid sphere (slider, tip, asperity), paper 1 eq (4).", (
    Key("radius", "length", "Sphere radius R (paper 1: 2 mm slider, 1 um in Fig 6); at most "
        "10 cm: MEMS/NEMS contacts (a larger R is a unit typo, e.g. '2 m' for '2 mm').",
        lo=0.0, hi=0.1, hi_closed=True),
    Key("profile", "choice", "'paraboloid': b = d + r^2/2R (eq 4); 'sphere': the exact cap.",
        default="paraboloid", choices=PROFILES),
))

MATERIAL = Table("materials.disk", "An isotropic elastic solid.", (
    Key("youngs_modulus", "pressure", "Young's modulus E.", lo=0.0),
    Key("poisson_ratio", "number", "Poisson ratio nu.", lo=-1.0, hi=0.5),
))

MATERIALS = Table("materials", "Elastic constants: disk and slider (composite modulus E* of "
                  "eq 2) or E* itself.", (
    Key("disk", "custom", "{ youngs_modulus, poisson_ratio } of the disk (flat).",
        default=None, parse=lambda r, raw, path: _material(r, raw, path),
        expect="a table { youngs_modulus, poisson_ratio }"),
    Key("slider", "custom", "{ youngs_modulus, poisson_ratio } of the sphere; omitted: rigid.",
        default=None, parse=lambda r, raw, path: _material(r, raw, path),
        expect="a table { youngs_modulus, poisson_ratio }"),
    Key("composite_modulus", "pressure", "E* directly, instead of disk/slider.", default=None,
        lo=0.0),
))

#: the largest Poisson ratio the FE body takes (its mixed formulation eliminates the pressure
#: with a finite lambda; equal to femadh.elastic.fe.settings.NU_LIMIT, tested)
LAYER_NU_LIMIT = 0.49999

LAYER = Table("substrate.layers", "One bonded elastic layer (an element of the layers list, "
              "top first).", (
    Key("thickness", "length", "Layer thickness t.", lo=0.0),
    Key("youngs_modulus", "pressure", "Young's modulus E of the layer.", lo=0.0),
    Key("poisson_ratio", "number", "Poisson ratio nu of the layer (nearly incompressible "
        f"layers up to {LAYER_NU_LIMIT}: the FE body switches to a mixed formulation above "
        "0.45).", lo=-1.0, hi=LAYER_NU_LIMIT, hi_closed=True),
))


def _layers(reader, raw, path):
    """The layer stack: a non-empty list of LAYER tables, top first, as (t, E, nu) tuples."""
    if not isinstance(raw, list) or not raw:
        return reader.fail(path, raw, "a non-empty list of tables { thickness, youngs_modulus, "
                           "poisson_ratio }, top layer first")
    out = []
    for i, item in enumerate(raw):
        v = reader.read(LAYER, item, f"{path}.{i}")
        out.append(BAD if any_bad(v) else
                   (v["thickness"], v["youngs_modulus"], v["poisson_ratio"]))
    return BAD if any_bad(*out) else tuple(out)


SUBSTRATE = Table("substrate", "Coatings: bonded elastic layers on the disk material "
                  "([materials] disk is the substrate half-space below them). Needs "
                  "[solver] method = 'fe': the Green function is the homogeneous half-space's. "
                  "The sphere's own compliance ([materials] slider; omitted: rigid) is added "
                  "as its half-space Green function on the same nodes. E* (eq 2) stays the bare "
                  "disk/slider pair's: the JKR/DMT reference curves show the uncoated contact "
                  "and the asperity laws use it.", (
    Key("layers", "custom", "The layers, top first: [{ thickness = \"5 nm\", youngs_modulus "
        "= \"200 GPa\", poisson_ratio = 0.25 }, ...].", default=(), parse=_layers,
        expect="a list of tables { thickness, youngs_modulus, poisson_ratio }, top first"),
))

#: the tables of the body, in the order of the reference page
TABLES = (SPHERE, MATERIALS, MATERIAL, SUBSTRATE, LAYER)


@dataclass(frozen=True)
class Body:
    """The solids in contact, SI units: everything about them that is not a surface law.

    Attributes
    ----------
    sphere : Sphere
        The rigid sphere's radius R (m) and profile (paper 1 eq 4).
    e_star : float
        Composite modulus E* (Pa), paper 1 eq (2): of the disk/slider pair, or given.
    disk, slider : IsotropicMaterial or None
        The flat's and the sphere's constants (None: given as E* only; a rigid slider).
    layers : tuple of (float, float, float)
        Bonded coatings on the disk, top first: (thickness m, Young's modulus Pa, nu).
    """

    sphere: Sphere
    e_star: float
    disk: IsotropicMaterial | None = None
    slider: IsotropicMaterial | None = None
    layers: tuple = ()

    def __post_init__(self):
        object.__setattr__(self, "layers", tuple(tuple(x) for x in self.layers))


def read_sphere(reader, data):
    """The [sphere] table as a Sphere (None when it has errors, recorded in ``reader``)."""
    sp = reader.read(SPHERE, data.get("sphere"), "sphere",
                     missing="a [sphere] table (it is required)")
    return None if any_bad(sp) else Sphere(sp["radius"], sp["profile"])


def _material(reader, raw, path):
    if raw is None:
        return None
    v = reader.read(MATERIAL, raw, path)
    if any_bad(v):
        return BAD
    return IsotropicMaterial(v["youngs_modulus"], v["poisson_ratio"])


def read_materials(reader, data):
    """(E*, disk, slider) of the [materials] table; E* is BAD when it has errors."""
    mt = reader.read(MATERIALS, data.get("materials"), "materials",
                     missing="a [materials] table (it is required)")
    if "materials" not in data:
        return BAD, None, None
    if any_bad(mt):
        return BAD, None, None
    if mt["composite_modulus"] is not None:
        if mt["disk"] is not None or mt["slider"] is not None:
            reader.fail("materials.composite_modulus", data["materials"]["composite_modulus"],
                        "either composite_modulus or disk/slider, not both")
            return BAD, None, None
        return mt["composite_modulus"], None, None
    if mt["disk"] is None:
        reader.fail("materials.disk", None, "a table { youngs_modulus, poisson_ratio } (or "
                    "materials.composite_modulus)")
        return BAD, None, None
    return composite_modulus(mt["disk"], mt["slider"]), mt["disk"], mt["slider"]


def read_layers(reader, data, disk):
    """The [substrate] layers (top first) as (t, E, nu) tuples; () without the table."""
    if "substrate" not in data:
        return ()
    v = reader.read(SUBSTRATE, data["substrate"], "substrate")
    layers = v["layers"]
    if layers is BAD:
        return BAD
    if not layers:
        reader.fail("substrate.layers", None, "a non-empty list of layers (or no [substrate] "
                    "table)")
        return BAD
    if disk is None and "materials" in data and isinstance(data["materials"], dict) \
            and "composite_modulus" in data["materials"]:
        reader.fail("materials.composite_modulus", data["materials"]["composite_modulus"],
                    "disk (and slider) materials in a layered scene: the layers lie on the "
                    "disk, and the sphere's compliance is added separately")
    return layers
