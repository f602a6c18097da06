"""Measured AFM force-distance curves: reading, validation, the sign and position conventions.

Formats
-------
- ``.csv`` (read by femadh, no optional dependency): a header row, then one row per point.
  Columns: a position (``z``, ``height``, ``separation``, ``d``, ``tip position``), a force
  (``force``) and optionally ``branch`` (``approach``/``retract``, or ``segment`` 0/1). Every
  position and force column carries its unit, either as a suffix (``z_m``, ``force_N``,
  ``z_nm``, ``force_nN``) or in brackets (``z [nm]``, ``force (nN)``); a column without a unit
  is refused (a bare ``z`` could mean m or nm). Without a branch column the points up to the
  lowest z are the approach and the rest the retract. Comma, semicolon or tab separated;
  lines starting with ``#`` are comments.
- everything afmformats reads (JPK ``.jpk-force``, Igor ``.ibw``, its ``.h5`` export, its
  tab-separated ``.tab``, ...), with afmformats' own ``load_data``: force from its ``force``
  column; position from ``tip position`` when present (the separation, deflection removed),
  else ``height (measured)`` or ``height (piezo)``; approach/retract from ``segment`` 0/1.
  Needs the ``data`` extra (``pip install -e ".[data]"``).

Conventions
-----------
Force: the AFM convention, positive = repulsive (the tip pushed away from the sample),
negative = adhesion. femadh's curve.csv has the opposite sign (SIGN_NOTE in
:mod:`femadh.io.writers`: "the force on the sphere is -F_ex; adhesion shows as F_ex > 0"), so a
measured force compares with ``F_AFM = -F_ex``. Position: ``z`` grows away from the sample,
as femadh's separation ``d`` does; its zero (the contact point) is arbitrary in a measurement,
so ``d = z - z_offset`` with ``z_offset`` an unknown that :mod:`femadh.fitting` fits.
"""
import csv
from dataclasses import dataclass, field
import io
import math
from pathlib import Path
import re

import numpy as np

from ..errors import DependencyError, SceneError

#: suffixes read by afmformats (its ``supported_extensions`` minus .csv, which femadh reads)
AFM_SUFFIXES = (".h5", ".tab", ".jpk-force", ".jpk-force-map", ".jpk-qi-data",
                ".jpk-qi-series", ".ibw", ".txt", ".zip")
#: position column names (lower case, unit removed) and what they measure
Z_NAMES = {"z": "height", "height": "height", "piezo height": "height",
           "height (piezo)": "height", "height (measured)": "height",
           "separation": "separation", "d": "separation", "distance": "separation",
           "tip position": "separation"}
FORCE_NAMES = ("force", "f")
BRANCH_NAMES = ("branch", "segment")
_BRANCH_WORDS = {"approach": "approach", "appr": "approach", "extend": "approach",
                 "0": "approach", "retract": "retract", "retr": "retract", "1": "retract"}


class CurveError(SceneError):
    """A force-curve file is unreadable or malformed: one line naming the file and what is
    wrong. A SceneError, so that the command line treats it as bad input (exit code 2)."""

    def __init__(self, file, message):
        self.file, self.key, self.value, self.expected = file, "(curve)", None, message
        Exception.__init__(self, f"{file}: {message}")


@dataclass
class ForceCurve:
    """A measured force-distance curve, in SI.

    Attributes
    ----------
    z : ndarray
        Position of each point (m), growing away from the sample.
    force : ndarray
        Force on the tip (N), AFM convention: positive repulsive, negative adhesive.
    branch : ndarray of str
        "approach" or "retract" per point.
    source : str
        The file.
    columns : dict
        "z", "force" -> the column names they were read from.
    units : dict
        "z", "force" -> the units of those columns in the file.
    z_kind : str
        "separation" (tip position: deflection removed, compares with femadh's d) or "height"
        (piezo height: compares with d only for a stiff cantilever, else with an instrument's
        z).
    """

    z: np.ndarray
    force: np.ndarray
    branch: np.ndarray
    source: str = ""
    columns: dict = field(default_factory=dict)
    units: dict = field(default_factory=dict)
    z_kind: str = "height"

    def __len__(self):
        return len(self.z)

    @property
    def femadh_force(self):
        """The force in femadh's curve.csv convention (F_ex: adhesion positive), N."""
        return -self.force

    def branches(self):
        """The branch names present, approach first."""
        return [b for b in ("approach", "retract") if np.any(self.branch == b)]

    def write_csv(self, path):
        """Write the curve as ``branch,z_m,force_N`` (repr floats: a lossless round trip),
        atomically."""
        from .atomic import write_atomic

        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(["branch", "z_m", "force_N"])
        for b, z, f in zip(self.branch, self.z, self.force):
            w.writerow([b, repr(float(z)), repr(float(f))])
        write_atomic(path, buf.getvalue())
        return Path(path)


def read_force_curve(path, *, index=0):
    """Read a force-distance curve (see the module docstring for formats and conventions).

    Parameters
    ----------
    path : str or Path
    index : int
        Which curve of a multi-curve file (afmformats formats; JPK maps) to take.

    Returns
    -------
    ForceCurve

    Raises
    ------
    CurveError
        Unknown format, unreadable file, no force or position column, a column without a
        unit, non-finite values (naming the rows), fewer than 3 points.
    DependencyError
        An afmformats format without afmformats installed.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in (".csv",) + AFM_SUFFIXES:
        raise CurveError(str(path), f"unknown force-curve format '{suffix or '(none)'}': "
                         "expected .csv (columns z_m, force_N, branch) or a format afmformats "
                         f"reads ({', '.join(AFM_SUFFIXES)})")
    if not path.is_file():
        raise CurveError(str(path), "no such file")
    curve = _read_csv(path) if suffix == ".csv" else _read_afmformats(path, index)
    return validate(curve)


def validate(curve):
    """Check a curve: finite values, at least 3 points, known branches. Returns the curve."""
    bad = ~(np.isfinite(curve.z) & np.isfinite(curve.force))
    if bad.any():
        rows = np.flatnonzero(bad)
        shown = ", ".join(str(r + 1) for r in rows[:5]) + (" ..." if len(rows) > 5 else "")
        raise CurveError(curve.source, f"{len(rows)} data rows with a non-finite z or force "
                         f"(NaN or inf; data rows {shown}): remove them or fill them in")
    if len(curve) < 3:
        raise CurveError(curve.source, f"{len(curve)} points: a curve needs at least 3")
    unknown = set(np.unique(curve.branch)) - {"approach", "retract"}
    if unknown:
        raise CurveError(curve.source, f"branch values {sorted(unknown)}: expected approach "
                         "or retract")
    return curve


# --------------------------------------------------------------------------- csv

_BRACKET = re.compile(r"^(?P<name>.*?)\s*(?:\[(?P<u1>[^\]]*)\]|\((?P<u2>[^)]*)\))\s*$")
_SUFFIX = re.compile(r"^(?P<name>[A-Za-z][A-Za-z ]*?)_(?P<unit>[A-Za-zµ]+)$")


def _split_header(text):
    """('z', 'nm') from 'z [nm]', 'z (nm)' or 'z_nm'; (name, None) without a unit."""
    t = text.strip()
    low = t.lower()
    if low in Z_NAMES or low in FORCE_NAMES or low in BRANCH_NAMES:
        return low, None            # 'height (piezo)' is a name, not a unit
    m = _BRACKET.match(t)
    if m:
        return m.group("name").strip().lower(), (m.group("u1") or m.group("u2") or "").strip()
    m = _SUFFIX.match(t)
    if m:
        return m.group("name").strip().lower(), m.group("unit")
    return low, None


def _factor(unit, kind, file, column):
    """Factor from ``unit`` to SI for a length ("m") or a force ("N")."""
    from ..units import _PREFIX

    base = "m" if kind == "length" else "N"
    for pre, f in _PREFIX.items():          # the common prefixes without loading pint
        if unit == pre + base:
            return f
    from ..units import _registry

    ureg = _registry()
    try:
        q = ureg.Quantity(1.0, unit.replace("^", "**"))
    except Exception:        # pint raises many types for an unparsable unit
        raise CurveError(file, f"column '{column}': unknown unit '{unit}'") from None
    dim = "[length]" if kind == "length" else "[mass] * [length] / [time] ** 2"
    if not q.check(dim):
        raise CurveError(file, f"column '{column}': unit '{unit}' is not a {kind}")
    return float(q.to(base).magnitude)


def _read_csv(path):
    file = str(path)
    try:
        text = path.read_text()
    except (OSError, UnicodeDecodeError) as exc:
        raise CurveError(file, f"cannot read it as text ({exc})") from None
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    if not lines:
        raise CurveError(file, "no header row and no data")
    delim = max(",;\t", key=lines[0].count)
    rows = list(csv.reader(lines, delimiter=delim))
    header = [h.strip() for h in rows[0]]
    parsed = [_split_header(h) for h in header]
    iz = [i for i, (n, _) in enumerate(parsed) if n in Z_NAMES]
    jf = [i for i, (n, _) in enumerate(parsed) if n in FORCE_NAMES]
    kb = [i for i, (n, _) in enumerate(parsed) if n in BRANCH_NAMES]
    found = ", ".join(repr(h) for h in header)
    if not jf:
        raise CurveError(file, f"no force column (columns: {found}): expected e.g. force_N "
                         "or 'force [nN]'")
    if not iz:
        raise CurveError(file, f"no position column (columns: {found}): expected e.g. z_m or "
                         "'z [nm]' (or height, separation, tip position)")
    iz, jf = iz[0], jf[0]
    for i, kind in ((iz, "length"), (jf, "force")):
        if not parsed[i][1]:
            raise CurveError(file, f"column '{header[i]}' has no unit: write it as "
                             f"'{parsed[i][0]}_{'m' if kind == 'length' else 'N'}' or "
                             f"'{parsed[i][0]} [{'nm' if kind == 'length' else 'nN'}]'")
    fz = _factor(parsed[iz][1], "length", file, header[iz])
    ff = _factor(parsed[jf][1], "force", file, header[jf])
    z, f, br = [], [], []
    for n, row in enumerate(rows[1:], start=1):
        if len(row) < len(header):
            raise CurveError(file, f"data row {n} has {len(row)} fields, the header "
                             f"{len(header)}")
        try:
            z.append(float(row[iz]) * fz if row[iz].strip() else math.nan)
            f.append(float(row[jf]) * ff if row[jf].strip() else math.nan)
        except ValueError:
            raise CurveError(file, f"data row {n}: {row[iz]!r}, {row[jf]!r} are not "
                             "numbers") from None
        if kb:
            word = row[kb[0]].strip().lower()
            word = _BRANCH_WORDS.get(word[:-2] if word.endswith(".0") else word, word)
            br.append(word)
    z, f = np.array(z, float), np.array(f, float)
    branch = np.array(br, dtype=object) if kb else _infer_branches(z)
    kind = Z_NAMES[parsed[iz][0]]
    return ForceCurve(z, f, np.asarray(branch).astype(str), file,
                      {"z": header[iz], "force": header[jf]},
                      {"z": parsed[iz][1], "force": parsed[jf][1]}, kind)


def _infer_branches(z):
    """Approach up to the lowest z (the turning point of the piezo), retract after it."""
    out = np.full(len(z), "approach", dtype=object)
    if len(z) and np.all(np.isfinite(z)):
        k = int(np.argmin(z))
        out[k + 1:] = "retract"
    return out


# --------------------------------------------------------------------------- afmformats

def _afmformats():
    try:
        import afmformats
    except ImportError:
        raise DependencyError("reading AFM files (JPK, Igor, HDF5, tab) needs afmformats: "
                              "pip install -e \".[data]\" (plain .csv curves need nothing)") \
            from None
    return afmformats


def _read_afmformats(path, index):
    afm = _afmformats()
    file = str(path)
    try:
        data = afm.load_data(path)
    except Exception as exc:     # afmformats raises its own and h5py's/numpy's errors
        raise CurveError(file, f"afmformats cannot read it ({type(exc).__name__}: {exc})") \
            from None
    fd = [d for d in data if getattr(d, "modality", None) == "force-distance"]
    if not fd:
        raise CurveError(file, "no force-distance curve in it (afmformats found "
                         f"{len(data)} datasets of other modalities)")
    if not 0 <= index < len(fd):
        raise CurveError(file, f"curve index {index} out of range: it holds {len(fd)} curves")
    d = fd[index]
    cols = list(d.columns)
    if "force" not in cols:
        raise CurveError(file, f"no force column (afmformats columns: {cols})")
    for name in ("tip position", "height (measured)", "height (piezo)"):
        if name in cols:
            zcol = name
            break
    else:
        raise CurveError(file, f"no position column (afmformats columns: {cols}): expected "
                         "tip position, height (measured) or height (piezo)")
    units = afm.afm_data.column_units
    z = np.asarray(d[zcol], float)
    f = np.asarray(d["force"], float)
    seg = np.asarray(d["segment"]) if "segment" in cols else None
    branch = (np.where(seg == 0, "approach", "retract") if seg is not None
              else _infer_branches(z))
    return ForceCurve(z, f, np.asarray(branch).astype(str), file,
                      {"z": zcol, "force": "force"},
                      {"z": units.get(zcol, "m"), "force": units.get("force", "N")},
                      Z_NAMES[zcol])
