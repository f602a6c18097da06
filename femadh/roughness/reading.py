"""Measured surfaces: read a topography file with SurfaceTopography (ContactEngineering) and
check that it can give physical roughness statistics.

SurfaceTopography is an optional dependency (``pip install -e ".[data]"``); it is imported
here, inside :func:`read_topography`, so that the rest of femadh imports without it.

A topography is accepted only if it has a physical size and a length unit (a height matrix
without them has no scale: its slopes and curvatures would be numbers without meaning), holds
no undefined (NaN / masked) points (the spectra need every point), and is not flat. Every
problem is one :class:`~femadh.errors.SceneError` naming the file and what was expected.
"""
import math
from pathlib import Path

import numpy as np

from ..errors import DependencyError, SceneError

#: the key under which file-level problems are reported (as femadh.scene does for "(file)")
FILE_KEY = "(topography)"


def _surface_topography():
    try:
        from SurfaceTopography import open_topography
    except ImportError:
        raise DependencyError('reading topography files needs SurfaceTopography: pip install '
                              '-e ".[data]" (or pip install "femadh[data]")') from None
    return open_topography


def read_topography(path, *, key=FILE_KEY, file=None):
    """Read a topography file and return it detrended, in metres.

    Parameters
    ----------
    path : str or Path
        Any format SurfaceTopography reads (NetCDF, Gwyddion, Digital Instruments, x3p, ...).
    key, file : str, optional
        Where the path came from, for error messages (default: the topography file itself;
        a scene passes its own file and key).

    Returns
    -------
    SurfaceTopography.Topography or SurfaceTopography.UniformLineScan
        Heights and sizes in m. Periodic data keep their tilt-free mean plane (only the mean
        is removed: a plane fit would break periodicity); non-periodic data have their
        best-fit plane removed (``detrend_mode='height'``), so that heights are measured from
        the mean plane of paper 1 Fig 1.

    Raises
    ------
    DependencyError
        SurfaceTopography is not installed.
    SceneError
        The file is missing or unreadable, its format unknown, it has no physical size or
        length unit, it holds undefined (NaN) points, or it is flat.
    """
    import warnings

    # SurfaceTopography's NetCDF reader warns when its memory map is closed while arrays
    # still refer to it (an error path that raises before the heights are copied);
    # the accepted topography is squeezed into memory before the file is closed
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return _read(path, key, file)


def _read(path, key, file):
    open_topography = _surface_topography()
    path = Path(path)
    where = file if file is not None else str(path)

    def bad(expected, value=str(path)):
        return SceneError(where, key, value, expected)

    if not path.is_file():
        raise bad("an existing topography file" + (" (this is a folder)" if path.is_dir()
                                                   else " (no such file)"))
    try:
        reader = open_topography(str(path))
    except Exception as exc:  # SurfaceTopography raises many types for unknown formats
        why = ("no reader recognised it" if type(exc).__name__ == "CannotDetectFileFormat"
               else _first_line(exc))
        raise bad("a topography file in a format SurfaceTopography reads (NetCDF, Gwyddion, "
                  f"x3p, Digital Instruments, ...): {why}") from None
    try:
        return _check(reader, bad)
    finally:
        if hasattr(reader, "close"):
            reader.close()


def _check(reader, bad):
    """The checks of :func:`read_topography` on an open reader."""
    if not reader.channels:
        raise bad("a topography file with at least one data channel")
    channel = reader.channels[0]
    sizes, unit = channel.physical_sizes, channel.unit
    if sizes is None or unit is None:
        missing = ("neither a physical size nor a length unit" if sizes is None and unit is None
                   else "no physical size" if sizes is None else "no length unit")
        raise bad(f"a topography with a physical size and a length unit; this file has "
                  f"{missing} (write it in a format that stores them, e.g. SurfaceTopography's "
                  "NetCDF)")
    try:
        topo = reader.topography()
    except Exception as exc:
        raise bad(f"a readable topography: {_first_line(exc)}") from None
    if not all(math.isfinite(float(s)) and float(s) > 0 for s in topo.physical_sizes):
        raise bad(f"a topography with a positive physical size (it has {topo.physical_sizes} "
                  f"{unit})")
    try:
        topo = topo.to_unit("m")
    except Exception as exc:
        raise bad(f"a topography whose unit is a length (it is {unit!r}: "
                  f"{_first_line(exc)})") from None
    if topo.has_undefined_data:
        n_bad = int(np.ma.count_masked(np.ma.masked_invalid(topo.heights())))
        raise bad(f"a topography without undefined (NaN) points; {n_bad} of "
                  f"{int(np.prod(topo.nb_grid_pts))} are undefined (fill or crop them first: "
                  "spectral moments need every point)")
    if min(topo.nb_grid_pts) < 8:
        raise bad(f"a topography of at least 8 points along each side (it has "
                  f"{'x'.join(str(n) for n in topo.nb_grid_pts)})")
    scale = float(np.max(np.abs(topo.heights())))
    topo = topo.detrend("center" if topo.is_periodic else "height").squeeze()
    # flat: nothing left after detrending but the rounding of the plane fit
    if not float(np.sqrt(np.mean(topo.heights() ** 2))) > 1e-10 * scale:
        raise bad("a rough topography (this one is flat: every height equal after "
                  "detrending)")
    return topo


def _first_line(exc):
    text = str(exc).strip().splitlines()
    return text[0].strip() if text else type(exc).__name__
