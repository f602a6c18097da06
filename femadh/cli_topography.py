"""``femadh topography FILE [FILE2] [--cutoff LENGTH] [--json] [--scene-fragment PATH]``:
the roughness statistics of a measured surface (or the composite of a slider and a disk) as
paper 1's Greenwood-Williamson parameters (:mod:`femadh.roughness.report`).

Errors follow :mod:`femadh.cli`: a bad file or cutoff is a SceneError (exit 2), a missing
SurfaceTopography a DependencyError (exit 5), an unwritable fragment an OutputError (exit 4).
Everything is computed before anything is written.
"""
import json
import math

from .errors import SceneError


def add_parser(sub):
    """Register the subcommand on the ``sub`` subparsers of femadh's parser."""
    t = sub.add_parser(
        "topography", allow_abbrev=False,
        help="GW asperity statistics (rho, R_a, sigma_a, z_m) of measured "
                           "surfaces",
        description="Read one topography (or a slider and a disk) with SurfaceTopography, "
                    "compute the profile spectral moments m0, m2, m4 at the pixel scale and "
                    "at --cutoff, and McCool's summit statistics of an isotropic Gaussian "
                    "surface in paper 1's notation; two files combine as in paper 1 "
                    "Table 2. Needs the 'data' extra: pip install -e \".[data]\".")
    t.add_argument("file", help="topography file (any format SurfaceTopography reads, with a "
                                "physical size and unit)")
    t.add_argument("file2", nargs="?", help="a second surface (the disk): the composite")
    t.add_argument("--cutoff", help="short-wavelength cutoff, e.g. '50 nm' (default: the "
                                    "pixel scale only)")
    t.add_argument("--json", action="store_true", help="print one JSON object (SI units)")
    t.add_argument("--scene-fragment", metavar="PATH",
                   help="write the [effects.asperity_contact] section as TOML to PATH")


def main(args):
    """Run the subcommand; returns the exit code (errors propagate to femadh.cli)."""
    from .roughness.report import finite, statistics
    from .units import to_si

    cutoff = None
    if args.cutoff is not None:
        cutoff = to_si(args.cutoff, "length", file="command line", key="--cutoff",
                       bare_numbers=False)
        if not (math.isfinite(cutoff) and cutoff > 0):
            raise SceneError("command line", "--cutoff", args.cutoff, "a positive length")
    files = [args.file] + ([args.file2] if args.file2 else [])
    report = statistics(files, cutoff)
    if not finite(report):
        raise SceneError("command line", "FILE", files, "a topography whose statistics are "
                         "finite (a spectrum with power at the cutoff)")
    fragment = scene_fragment(report)
    if args.scene_fragment:
        from .io.atomic import write_atomic

        write_atomic(args.scene_fragment, fragment)
    if args.json:
        print(json.dumps(report, indent=2, allow_nan=False))
    else:
        print(table(report))
        if args.scene_fragment:
            print(f"scene fragment written to {args.scene_fragment}")
    import sys

    for w in report["warnings"]:
        print(f"femadh: warning: {w}", file=sys.stderr)
    return 0


def _rows(v):
    return [("m0 (nm^2)", v["m0"] * 1e18), ("m2", v["m2"]), ("m4 (um^-2)", v["m4"] * 1e-12),
            ("alpha", v["alpha"]), ("rho = eta (um^-2)", v["eta_per_m2"] * 1e-12),
            ("R_a = beta (um)", v["beta_m"] * 1e6),
            ("sigma_a = sigma_s (nm)", v["sigma_s_m"] * 1e9),
            ("z_m (nm)", v["z_m_m"] * 1e9)]


def table(report):
    """The report as a plain-text table for people: pixel scale and, if given, the cutoff."""
    cols = [("pixel", report["pixel"])]
    if report["cutoff_source"] == "user":
        cols.append(("cutoff", report))
    head = f"{'':24s}" + "".join(f"{n + ' ' + _nm(v['cutoff_m']):>22s}" for n, v in cols)
    lines = [", ".join(report["files"])]
    if len(report["files"]) == 2:
        lines.append("composite: " + report["rule"])
    lines.append(head)
    for i, (label, _) in enumerate(_rows(report["pixel"])):
        lines.append(f"{label:24s}" + "".join(f"{_rows(v)[i][1]:22.4g}" for _, v in cols))
    return "\n".join(lines)


def _nm(length):
    return f"({length * 1e9:.3g} nm)"


def scene_fragment(report):
    """TOML of the asperity sections with the report's numbers (paper 1 sec 6 names)."""
    from .roughness.report import scene_values

    v = scene_values(report)
    src = ", ".join(report["files"])
    cut = (f"cutoff {report['cutoff_m']:.4g} m" if report["cutoff_source"] == "user"
           else f"pixel scale, {report['cutoff_m']:.4g} m")
    return "\n".join([
        f"# femadh topography {src} ({cut}): {report['rule']}",
        "# (or write: topography = \"FILE\" in the section, and femadh computes these)",
        "[effects.asperity_contact]",
        'model = "greenwood-williamson"',
        f'rms_height = "{v["rms_height"]}"',
        f'mean_height = "{v["mean_height"]}"',
        f'asperity_radius = "{v["asperity_radius"]}"',
        f'density = "{v["density"]}"',
        "", "# for the sigma-gap model's eq 20 instead:",
        "# [effects.asperity_adhesion]",
        f'# asperity_radius = "{v["asperity_radius"]}"',
        f'# density = "{v["density"]}"', ""])
