"""Contact scenes (paper 1): the sphere, the materials, the effects (gap laws and the
sigma-gap), the solver and the sweep, validated into a :class:`Scene` in SI units."""
from dataclasses import asdict, dataclass, field
import math

from ..contact.constraints import CONTACT_MODELS, AsperityGap
from ..errors import SceneError
from ..indenter import PROFILES, Sphere
from ..laws import LennardJones
from ..materials import IsotropicMaterial, composite_modulus
from .reader import Reader, scene_name

METHODS = ("green", "fe")
DIRECTIONS = ("approach", "retract")

_TOP = {"scene", "sphere", "materials", "effects", "solver", "sweep", "output"}
_EFFECTS = {"lennard_jones", "asperity_gap", "capillary", "asperity_adhesion",
            "asperity_contact"}


@dataclass
class Scene:
    """A validated scene, all quantities in SI units.

    Attributes mirror the TOML sections; ``raw`` keeps the file's own text values and
    ``resolved`` the SI values written to summary.json.
    """

    name: str
    path: str | None
    sphere: Sphere
    e_star: float
    effects: dict
    gap: AsperityGap | None
    method: str
    nodes: int
    analysis_radius: float
    tolerance: float
    max_iter: int
    fe_settings: object | None
    d_values: list
    directions: tuple
    output_dir: str
    fe_poisson_ratio: float = 0.3
    vtk: bool = False
    continuation: str = "steps"
    raw: dict = field(repr=False, default_factory=dict)

    @property
    def resolved(self):
        """Plain-dict SI view of the scene (for summary.json)."""
        return {
            "name": self.name,
            "sphere": {"radius_m": self.sphere.radius, "profile": self.sphere.profile},
            "composite_modulus_Pa": self.e_star,
            "effects": {name: asdict(e) for name, e in self.effects.items()},
            "asperity_gap": None if self.gap is None else
            {"sigma_m": self.gap.sigma, "contact_model": self.gap.contact_model},
            "solver": {"method": self.method, "nodes": self.nodes,
                       "analysis_radius_m": self.analysis_radius,
                       "tolerance_m": self.tolerance, "max_iter": self.max_iter,
                       "continuation": self.continuation,
                       "mesh": None if self.fe_settings is None else {
                           "outer_factor": self.fe_settings.outer_factor,
                           "growth": self.fe_settings.growth,
                           "surface_fraction": self.fe_settings.surface_fraction,
                           "far_field": self.fe_settings.far_field,
                           "poisson_ratio": self.fe_poisson_ratio}},
            "sweep": {"d_m": list(self.d_values), "directions": list(self.directions)},
            "output_dir": self.output_dir,
        }


def _capillary(file, table):
    """[effects.capillary]: liquid, temperature, relative_pressure, isotherm, smoothing."""
    from ..laws import CapillaryCondensate
    from ..meniscus.isotherms import default_isotherm
    from ..meniscus.kelvin import kelvin_radius
    from ..meniscus.liquids import LIQUIDS
    from .liquids import read_isotherm, read_liquid

    c = Reader(file, table, "effects.capillary")
    liquid = read_liquid(c, c.raw("liquid"))
    temperature = c.quantity("temperature", "temperature", default="298.15 K")
    x = c.raw("relative_pressure")
    if isinstance(x, bool) or not isinstance(x, (int, float)) or not 0 < x < 1:
        raise c.error("relative_pressure", x, "a number in (0, 1)")
    iso_raw = c.raw("isotherm", None)
    if iso_raw is None:
        iso = default_isotherm(liquid.name) if liquid.name in LIQUIDS else None
    else:
        iso = read_isotherm(c, iso_raw)
    smoothing = c.raw("smoothing", 0.02)
    if isinstance(smoothing, bool) or not isinstance(smoothing, (int, float)) \
            or not 0 < smoothing <= 0.5:
        raise c.error("smoothing", smoothing, "a fraction in (0, 0.5] of the filled gap")
    c.done()
    r_k = kelvin_radius(liquid, float(x), temperature)
    film = 0.0 if iso is None else float(iso(float(x)))
    fill = 2 * abs(r_k) + 2 * film
    return CapillaryCondensate(liquid.surface_tension, r_k, film, float(smoothing) * fill)


def _asperity_adhesion(file, table, sigma):
    """[effects.asperity_adhesion]: eq 20 over the contact region."""
    from ..laws import AsperityAdhesion

    t = Reader(file, table, "effects.asperity_adhesion")
    Ra = t.quantity("asperity_radius", "length")
    dg = t.quantity("surface_energy", "surface_energy")
    rho = t.quantity("density", "areal_density", positive=False)
    if rho < 0:
        raise t.error("density", table["density"], "a density >= 0")
    p = t.raw("contact_probability", 0.5)
    if isinstance(p, bool) or not isinstance(p, (int, float)) or not 0 <= p <= 1:
        raise t.error("contact_probability", p, "a number in [0, 1]")
    sm = t.raw("smoothing", 0.02)
    if isinstance(sm, bool) or not isinstance(sm, (int, float)) or not 0 < sm <= 0.2:
        raise t.error("smoothing", sm, "a fraction in (0, 0.2] of sigma")
    t.done()
    return AsperityAdhesion.from_asperities(Ra, dg, rho, float(p), sigma, float(sm))


def _asperity_contact(file, table, e_star):
    """[effects.asperity_contact] model = "greenwood-williamson": eqs 23-24 as gap laws."""
    from ..laws import GWAdhesion, GWElastic, Summits

    t = Reader(file, table, "effects.asperity_contact")
    t.choice("model", ("greenwood-williamson",))
    rough = Summits(t.quantity("rms_height", "length"),
                      t.quantity("mean_height", "length", positive=False),
                      t.quantity("asperity_radius", "length"),
                      t.quantity("density", "areal_density"))
    dg = t.quantity("surface_energy", "surface_energy", default=0.0, positive=False)
    t.done()
    out = {"asperity_elastic": GWElastic(rough, e_star)}
    if dg > 0:
        out["asperity_adhesion"] = GWAdhesion(rough, dg)
    return out


def _material(r, k):
    t = r.table_at(k)
    m = Reader(r.file, t, r.key(k))
    E = m.quantity("youngs_modulus", "pressure")
    nu = m.raw("poisson_ratio")
    if isinstance(nu, bool) or not isinstance(nu, (int, float)) or not -1.0 < nu < 0.5:
        raise m.error("poisson_ratio", nu, "a number in (-1, 0.5)")
    m.done()
    return IsotropicMaterial(E, float(nu))


def parse_contact(top, file):
    """Build a contact :class:`Scene` from the top-level Reader of a scene file."""
    data = top.table
    top.used |= _TOP
    top.done(_TOP)

    name = scene_name(top, file)

    sp = Reader(file, top.table_at("sphere"), "sphere")
    sphere = Sphere(sp.quantity("radius", "length"),
                    sp.choice("profile", PROFILES, "paraboloid"))
    sp.done()

    mt = Reader(file, top.table_at("materials"), "materials")
    disk = None
    if "composite_modulus" in mt.table:
        if "disk" in mt.table or "slider" in mt.table:
            raise mt.error("composite_modulus", mt.table["composite_modulus"],
                           "either composite_modulus or disk/slider, not both")
        e_star = mt.quantity("composite_modulus", "pressure")
    else:
        disk = _material(mt, "disk")
        slider = _material(mt, "slider") if "slider" in mt.table else None
        e_star = composite_modulus(disk, slider)
    mt.done()

    ef = Reader(file, top.table_at("effects", {}), "effects")
    effects, gap = {}, None
    lj_t = ef.table_at("lennard_jones", None)
    if lj_t is not None:
        lj = Reader(file, lj_t, "effects.lennard_jones")
        effects["lj"] = LennardJones(lj.quantity("hamaker", "energy"),
                                     lj.quantity("equilibrium_distance", "length"))
        lj.done()
    gap_t = ef.table_at("asperity_gap", None)
    if gap_t is not None:
        g = Reader(file, gap_t, "effects.asperity_gap")
        gap = AsperityGap(g.quantity("sigma", "length"),
                          g.choice("contact_model", CONTACT_MODELS, "complementarity"))
        g.done()
    cap_t = ef.table_at("capillary", None)
    if cap_t is not None:
        effects["capillary"] = _capillary(file, cap_t)
    ad_t = ef.table_at("asperity_adhesion", None)
    if ad_t is not None:
        if gap is None:
            raise SceneError(file, "effects.asperity_adhesion", ad_t, "an [effects.asperity_gap]"
                             " as well: eq 20 acts over the sigma-gap contact region")
        effects["asperity_adhesion"] = _asperity_adhesion(file, ad_t, gap.sigma)
    gw_t = ef.table_at("asperity_contact", None)
    if gw_t is not None:
        if gap is not None:
            raise SceneError(file, "effects.asperity_contact", gw_t, "no [effects.asperity_gap]"
                             ": the Greenwood-Williamson model replaces the hard sigma-gap")
        effects.update(_asperity_contact(file, gw_t, e_star))
    ef.done(_EFFECTS)
    if not effects:
        raise SceneError(file, "effects", sorted(ef.table), "at least one surface force "
                         "effect, e.g. [effects.lennard_jones]")
    if gap is not None and gap.contact_model == "hertz-closure" and "lj" not in effects:
        raise SceneError(file, "effects.asperity_gap.contact_model", gap.contact_model,
                         "'complementarity' unless [effects.lennard_jones] is present")

    so = Reader(file, top.table_at("solver", {}), "solver")
    method = so.choice("method", METHODS, "green")
    nodes = so.integer("nodes", 8, 200)
    ar = so.raw("analysis_radius", {"delta": "10 nm"})
    if isinstance(ar, dict):
        arr = Reader(file, ar, "solver.analysis_radius")
        delta = arr.quantity("delta", "length")
        arr.done()
        a = math.sqrt(2.0 * sphere.radius * delta)  # paper 1 sec 4: delta = a^2 / 2R
    else:
        a = so.quantity("analysis_radius", "length")
    if sphere.profile == "sphere" and a >= sphere.radius:
        raise so.error("analysis_radius", ar, f"less than the sphere radius {sphere.radius} m")
    tol = so.quantity("tolerance", "length", default="1e-10 nm")
    max_iter = so.integer("max_iter", 1, 40)
    continuation = so.choice("continuation", ("steps", "arclength"), "steps")
    if continuation == "arclength" and gap is not None:
        raise so.error("continuation", continuation, "'steps' with [effects.asperity_gap]: "
                       "arclength continuation traces smooth laws only (the hard sigma-gap "
                       "is not smooth)")
    fe_settings, fe_nu = None, (disk.poisson_ratio if disk is not None else 0.3)
    mesh_t = so.table_at("mesh", None)
    if method == "fe":
        from ..elastic.fe import FESettings

        ms = Reader(file, mesh_t or {}, "solver.mesh")
        d0 = FESettings()
        outer = ms.raw("outer_factor", d0.outer_factor)
        growth = ms.raw("growth", d0.growth)
        surf = ms.raw("surface_fraction", d0.surface_fraction)
        for k, v, lo, hi in (("outer_factor", outer, 1.0, 1e7), ("growth", growth, 0.0, 2.0),
                             ("surface_fraction", surf, 0.0, 1.0)):
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not lo < v <= hi:
                raise ms.error(k, v, f"a number in ({lo:g}, {hi:g}]")
        far = ms.choice("far_field", ("boussinesq", "fixed"), d0.far_field)
        nu = ms.raw("poisson_ratio", fe_nu)
        if isinstance(nu, bool) or not isinstance(nu, (int, float)) or not -1 < nu < 0.5:
            raise ms.error("poisson_ratio", nu, "a number in (-1, 0.5)")
        ms.done()
        fe_settings, fe_nu = FESettings(float(outer), float(growth), float(surf), far), float(nu)
    elif mesh_t is not None:
        raise so.error("mesh", mesh_t, "no [solver] mesh table unless method = \"fe\"")
    so.done()

    cap = effects.get("capillary")
    delta_a = a * a / (2 * sphere.radius)
    if cap is not None and cap.fill_gap >= delta_a:
        raise SceneError(file, "solver.analysis_radius", ar, f"an analysis radius whose gap "
                         f"a^2/2R = {delta_a * 1e9:.4g} nm exceeds the condensate's filled gap "
                         f"2|r_K| + 2h = {cap.fill_gap * 1e9:.4g} nm, so that the meniscus lies "
                         f"inside it (e.g. analysis_radius = {{ delta = "
                         f"\"{2 * cap.fill_gap * 1e9:.3g} nm\" }})")
    sw = Reader(file, top.table_at("sweep"), "sweep")
    start = sw.quantity("start", "length", positive=False)
    stop = sw.quantity("stop", "length", positive=False)
    step = sw.quantity("step", "length")
    dirs = sw.raw("directions", ["approach", "retract"])
    if (not isinstance(dirs, list) or not dirs or any(x not in DIRECTIONS for x in dirs)
            or len(set(dirs)) != len(dirs)):
        raise sw.error("directions", dirs, "a list drawn from ['approach', 'retract']")
    if "approach" in dirs and not stop < start:
        raise sw.error("stop", sw.table["stop"], f"a separation below start "
                       f"({sw.table['start']}) for an approach")
    if dirs == ["retract"] and not stop > start:
        raise sw.error("stop", sw.table["stop"], f"a separation above start "
                       f"({sw.table['start']}) for a retract-only sweep")
    n_steps = abs(stop - start) / step
    if n_steps > 100000:
        raise sw.error("step", sw.table["step"], "a step giving at most 100000 separations")
    k = round(n_steps)
    if abs(n_steps - k) > 1e-6:
        raise sw.error("step", sw.table["step"], f"a step that divides |stop - start| = "
                       f"{abs(stop - start):.6g} m into whole steps")
    if continuation == "arclength" and "approach" not in dirs:
        raise sw.error("directions", dirs, "a list with 'approach' for [solver] continuation "
                       "= 'arclength' (the curve is traced from start to stop)")
    sign = -1.0 if stop < start else 1.0
    d_values = [start + sign * i * step for i in range(k + 1)]
    sw.done()
    if gap is None and d_values[0] <= 0:
        raise SceneError(file, "sweep.start", sw.table["start"], "a positive separation for a "
                         "smooth sphere (no [effects.asperity_gap]): the sweep starts from the "
                         "undeformed surface, which the tip must not touch")

    ou = Reader(file, top.table_at("output", {}), "output")
    out_dir = ou.raw("dir", f"out/{name}")
    if not isinstance(out_dir, str) or not out_dir:
        raise ou.error("dir", out_dir, "a folder path")
    vtk = ou.raw("vtk", method == "fe")
    if not isinstance(vtk, bool):
        raise ou.error("vtk", vtk, "true or false")
    if vtk and method != "fe":
        raise ou.error("vtk", vtk, "false unless [solver] method = \"fe\" (the Green "
                       "operator has no interior field to write)")
    ou.done()

    return Scene(name=name, path=file, sphere=sphere, e_star=e_star, effects=effects, gap=gap,
                 method=method, nodes=nodes, analysis_radius=a, tolerance=tol,
                 max_iter=max_iter, fe_settings=fe_settings, d_values=d_values,
                 directions=tuple(dirs), output_dir=out_dir, fe_poisson_ratio=fe_nu, vtk=vtk,
                 continuation=continuation, raw=data)


