"""``topography = "file"`` in an asperity section: the GW numbers of the section computed
from a measured surface (:mod:`femadh.roughness.report`) instead of written by hand;
``topography = ["slider", "disk"]`` takes paper 1's Table 2 composite of two.

The files' paths are relative to the scene file (to the working folder for scenes built in
code); ``topography_cutoff`` sets the short-wavelength cutoff (default: the pixel scale).
The section's numeric keys that the topography provides must then be absent. The numbers are
put into the section as SI strings (exact round-trip) before the section is read, so they
pass the same checks as hand-written ones, and the report lands in ``scene.resolved``
(summary.json) under ``topography``.
"""
from pathlib import Path

from ..errors import SceneError
from .reader import BAD

#: the numeric keys a topography provides, by asperity section
PROVIDES = ("rms_height", "mean_height", "asperity_radius", "density")


def resolve(reader, raw, path, table, resolved):
    """The raw section with the topography's numbers filled in (or ``raw`` unchanged).

    Parameters
    ----------
    reader : femadh.scene.reader.Reader
        Collects the errors (file, key, value, expected).
    raw : dict
        The section as written.
    path : str
        Its dotted name, e.g. ``"effects.asperity_contact"``.
    table : femadh.schema.Table
        Its keys (only those it declares are filled).
    resolved : dict
        Receives ``path -> report`` (the values used, the file, cutoff and warnings).

    Returns
    -------
    dict or BAD
    """
    if not isinstance(raw, dict) or raw.get("topography") is None:
        return raw
    from ..roughness.report import scene_values, statistics

    name, key = raw["topography"], f"{path}.topography"
    names = reader.value(table.key("topography"), name, key)
    if names is BAD:
        return BAD
    fills = [k for k in PROVIDES if table.key(k) is not None]
    given = [k for k in fills if k in raw]
    if given:
        return reader.fail(key, name, f"either topography or {', '.join(given)}, not both "
                           "(the topography provides " + ", ".join(fills) + ")")
    cutoff = None
    if raw.get("topography_cutoff") is not None:
        cutoff = reader.value(table.key("topography_cutoff"), raw["topography_cutoff"],
                              f"{path}.topography_cutoff")
        if cutoff is BAD:
            return BAD
    base = Path(reader.file).parent if reader.file else Path.cwd()
    files = [base / n for n in names]
    try:
        report = statistics(files, cutoff, key=key, file=reader.file)
    except SceneError as exc:
        reader.errors.append(exc)
        return BAD
    values = scene_values(report)
    resolved[path] = {"files": [str(f) for f in files], "rule": report["rule"],
                      "cutoff_m": report["cutoff_m"],
                      "cutoff_source": report["cutoff_source"],
                      **{k: report[k] for k in ("m0", "m2", "m4", "alpha", "eta_per_m2",
                                                "beta_m", "sigma_s_m", "z_m_m")},
                      "warnings": report["warnings"]}
    return {**raw, **{k: values[k] for k in fills}}
