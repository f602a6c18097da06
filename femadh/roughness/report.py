"""The roughness report of one or two topography files: spectral moments and GW summit
statistics at the pixel scale and at a user's cutoff, with the warnings that qualify them.
``femadh topography`` prints it; a scene's ``topography = "file"`` takes its numbers.
"""
from functools import lru_cache
import math
import os
from pathlib import Path

from ..errors import SceneError
from .composite import composite
from .moments import mccool, nyquist_wavelength, profile_moments
from .spectrum import tail_check

#: McCool's relations are Nayak's large-alpha forms; below this alpha they are rough
LOW_ALPHA = 2.0
#: y/x ratio of m2 beyond which (or below its inverse) the surface is called anisotropic
ANISOTROPY = 1.5
#: a cutoff may not exceed this fraction of the shortest scan side (a few wavelengths kept)
MAX_CUTOFF_FRACTION = 0.25


def _values(moments):
    """The report's numbers of one set of moments (SI)."""
    s = mccool(moments)
    return {"cutoff_m": moments.cutoff, "m0": moments.m0, "m2": moments.m2, "m4": moments.m4,
            "alpha": moments.alpha, "eta_per_m2": s.density, "beta_m": s.radius,
            "sigma_s_m": s.sigma_a, "z_m_m": s.z_m, "anisotropy_m2_y_over_x": moments.anisotropy}


def _summits_values(summits, moments, rule):
    return {"cutoff_m": moments.cutoff, "m0": moments.m0, "m2": moments.m2, "m4": moments.m4,
            "alpha": moments.alpha, "eta_per_m2": summits.density, "beta_m": summits.radius,
            "sigma_s_m": summits.sigma_a, "z_m_m": summits.z_m, "rule": rule}


def _check_cutoff(topo, cutoff, path, key, file):
    lo = nyquist_wavelength(topo)
    hi = MAX_CUTOFF_FRACTION * min(topo.physical_sizes)
    if not (lo <= cutoff <= hi):
        raise SceneError(file if file is not None else "command line", key,
                         f"{cutoff:.4g} m", f"a cutoff between the Nyquist wavelength (2 "
                         f"pixels) {lo:.4g} m and a quarter of the scan {hi:.4g} m of {path}")


@lru_cache(maxsize=16)
def _surface(path, stamp, cutoff, key, file):
    """One file's statistics (cached by path, modification stamp and cutoff: scenes are
    validated again for every study point and error estimate)."""
    from .reading import read_topography

    topo = read_topography(path, key=key, file=file)
    if cutoff is not None:
        # (a scene's key is "<section>.topography": its cutoff is "<section>.topography_cutoff")
        _check_cutoff(topo, cutoff, path, f"{key}_cutoff" if file else "--cutoff", file)
    name = Path(path).name
    pixel = profile_moments(topo)
    at_cut = None if cutoff is None else profile_moments(topo, cutoff)
    warnings = []
    tail = tail_check(topo)
    w = tail.warning(name)
    # the tail judges the pixel scale; a cutoff above the top octave leaves it behind
    if w and (cutoff is None or cutoff < 2 * nyquist_wavelength(topo)):
        warnings.append(w)
    reliable = topo.short_reliability_cutoff()
    if reliable is not None and (cutoff is None or cutoff < reliable):
        warnings.append(f"{name}: its instrument data (tip radius or resolution) make "
                        f"wavelengths below {reliable:.3g} m unreliable: give --cutoff "
                        f"{reliable * 1e9:.3g} nm or longer")
    used = at_cut or pixel
    if used.alpha < LOW_ALPHA:
        warnings.append(f"{name}: narrow-band spectrum (alpha = {used.alpha:.3g} < "
                        f"{LOW_ALPHA:g}): McCool's relations are large-alpha forms and rough "
                        "here")
    if topo.dim == 2 and not (1 / ANISOTROPY <= pixel.anisotropy <= ANISOTROPY):
        warnings.append(f"{name}: anisotropic (m2 along y / along x = {pixel.anisotropy:.3g}):"
                        " McCool's relations assume an isotropic surface; the moments are the "
                        "x/y average")
    if topo.dim == 1:
        warnings.append(f"{name}: a line scan: the surface is assumed isotropic")
    info = {"file": str(path), "nb_grid_pts": [int(n) for n in topo.nb_grid_pts],
            "physical_sizes_m": [float(s) for s in topo.physical_sizes],
            "periodic": bool(topo.is_periodic), "pixel": _values(pixel),
            "at_cutoff": None if at_cut is None else _values(at_cut),
            # (None, not nan, where the tail was not judged: JSON has no nan)
            "tail": {"slope": tail.slope if math.isfinite(tail.slope) else None,
                     "ratio": tail.ratio if math.isfinite(tail.ratio) else None,
                     "verdict": tail.verdict},
            "warnings": warnings}
    return info, pixel, at_cut


def surface(path, cutoff=None, *, key="FILE", file=None):
    """Statistics of one topography file (see :func:`statistics`); returns (info dict, pixel
    moments, moments at the cutoff or None)."""
    p = Path(path)
    try:
        st = p.stat()
        stamp = (st.st_mtime_ns, st.st_size)
    except OSError:
        stamp = None
    return _surface(os.path.abspath(p) if stamp else str(p), stamp, cutoff, key, file)


def statistics(paths, cutoff=None, *, key="FILE", file=None):
    """The roughness report of one surface, or the composite of two (slider and disk).

    Parameters
    ----------
    paths : list of str or Path
        One or two topography files.
    cutoff : float, optional
        Short-wavelength cutoff lambda_c (m); None: the pixel scale.
    key, file : str, optional
        Where the paths came from, for error messages.

    Returns
    -------
    dict
        JSON-ready, SI: ``m0`` (m^2), ``m2``, ``m4`` (1/m^2), ``alpha``, ``eta_per_m2``,
        ``beta_m``, ``sigma_s_m``, ``z_m_m`` and ``cutoff_m`` at the cutoff used (the user's,
        else the pixel scale: ``cutoff_source``), ``rule`` (how they were obtained),
        ``pixel`` (the same at the pixel scale), ``surfaces`` (each file's own report),
        ``spectral_composite`` (two files: McCool of the summed moments) and ``warnings``.
    """
    if not 1 <= len(paths) <= 2:
        raise SceneError(file or "command line", key, list(map(str, paths)),
                         "one or two topography files")
    surfaces = [surface(p, cutoff, key=key, file=file) for p in paths]
    out = {"files": [str(p) for p in paths],
           "cutoff_source": "pixel" if cutoff is None else "user",
           "surfaces": [s[0] for s in surfaces]}
    if len(surfaces) == 1:
        info, pixel, at_cut = surfaces[0]
        used = {k: v for k, v in _values(at_cut or pixel).items()}
        used["rule"] = "McCool 1986 (isotropic Gaussian surface)"
        out["pixel"] = info["pixel"]
    else:
        (_, p1, c1), (_, p2, c2) = surfaces
        rule = ("paper 1 Table 2 rule (sigma_a in quadrature, z_m summed, R_a harmonic) on "
                "each surface's McCool numbers; rho from the summed moments")
        t_pix, s_pix, m_pix = composite(p1, p2)
        out["pixel"] = _summits_values(t_pix, m_pix, rule)
        t, s, m = composite(c1 or p1, c2 or p2)
        used = _summits_values(t, m, rule)
        out["spectral_composite"] = _summits_values(s, m, "McCool 1986 of the summed moments "
                                                    "m_n = m_n1 + m_n2")
    out.update(used)
    out["warnings"] = [w for s in surfaces for w in s[0]["warnings"]]
    return out


def scene_values(report):
    """The asperity keys of a scene table from a report: paper 1's GW parameters with units
    (strings that round-trip the floats exactly)."""
    return {"rms_height": f"{report['sigma_s_m']!r} m", "mean_height": f"{report['z_m_m']!r} m",
            "asperity_radius": f"{report['beta_m']!r} m",
            "density": f"{report['eta_per_m2']!r} m^-2"}


def finite(report):
    """Whether every headline number of a report is finite (a guard before writing)."""
    return all(math.isfinite(report[k]) for k in ("m0", "m2", "m4", "alpha", "eta_per_m2",
                                                  "beta_m", "sigma_s_m", "z_m_m"))
