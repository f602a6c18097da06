"""Scene files (TOML) -> validated scenes: the user-facing contract.

Quantities are strings with units ("2 mm", "25 degC"); in scene *files* a bare number for a
dimensional key is an error (``radius = 2`` would silently mean 2 m), and so it is in the keys
a person types into :meth:`Scene.replace` and a study's ``--vary`` (the same one-line error);
in scenes built in code (:func:`scene_from_dict`, :meth:`Scene.from_dict`, and
``Scene.replace(..., si=True)``) it is taken as SI. Every problem of a scene -
unknown keys (with a "did you mean"), missing keys, wrong units, values out of range - is
reported at once, each naming the file, the key, the value and what was expected
(:class:`~femadh.errors.SceneError`). A scene with a ``[meniscus]`` table is a capillary
(paper 2) scene (:class:`MeniscusScene`); otherwise a contact scene (:class:`Scene`), made of
frozen parts (:mod:`femadh.scene.parts`: body, laws, discretisation, sweep, output).
``femadh keys`` prints every key (:func:`reference_page`).
"""
import copy
import hashlib
import json
from pathlib import Path

try:
    import tomllib
except ModuleNotFoundError:  # Python < 3.11
    import tomli as tomllib

from ..errors import SceneError, given_by
from .build import build_operator, build_problem, operator_key
from .contact import Scene, parse_contact
from .meniscus import MeniscusScene, parse_meniscus
from .parts import Body, Discretisation, Laws, Output, Sweep
from .reader import Reader

__all__ = ["Scene", "MeniscusScene", "Body", "Laws", "Discretisation", "Sweep", "Output",
           "load_scene", "scene_from_dict", "apply_overrides", "build_operator",
           "build_problem", "operator_key", "reference_page", "scene_id"]


def load_scene(path):
    """Read and validate a scene file.

    Parameters
    ----------
    path : str or Path
        The TOML file.

    Returns
    -------
    Scene or MeniscusScene

    Raises
    ------
    SceneError
        Naming every malformed, missing, unknown or unphysical entry (SceneErrors when
        there are several).
    """
    path = Path(path)
    try:
        text = path.read_text()
    except OSError as exc:
        raise SceneError(str(path), "(file)", str(path), f"a readable file ({exc.strerror})") \
            from None
    except UnicodeDecodeError:
        raise SceneError(str(path), "(file)", str(path), "a UTF-8 text (TOML) file") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(str(path), "(file)", "(TOML text)", f"valid TOML ({exc})") from None
    return scene_from_dict(data, str(path), bare_numbers=False)


def scene_from_dict(data, file=None, *, bare_numbers=True, strict=()):
    """Validate a scene given as a dict (the parsed TOML); see :func:`load_scene`.
    ``bare_numbers``: whether plain numbers are SI for dimensional keys (code) or errors
    (files); ``strict``: dotted keys where a bare number is an error all the same (the keys
    of :meth:`Scene.replace`)."""
    from .liquids import read_isotherm, read_liquid

    reader = Reader(file, bare_numbers=bare_numbers, strict=strict,
                    kinds={"liquid": read_liquid, "isotherm": read_isotherm})
    if not isinstance(data, dict):
        reader.fail("(top level)", data, "a table of tables")
        reader.finish()
    parse = parse_meniscus if "meniscus" in data else parse_contact
    scene = parse(reader, data, file)
    reader.finish()
    return scene


def apply_overrides(raw, changes, file=None):
    """A deep copy of a scene dict with dotted keys set (``"effects.asperity_gap.sigma"``);
    intermediate tables are created. The result is a dict, to be validated.

    Raises
    ------
    SceneError
        For a key that is not a dotted string (``{1: 2}``), or an index past a list's end.
    """
    if not isinstance(changes, dict):
        raise SceneError(file, "(changes)", changes, "a dict of dotted scene keys to values, "
                         "e.g. {'sphere.radius': '1 um'}")
    data = copy.deepcopy(raw)
    for dotted, value in changes.items():
        if not isinstance(dotted, str) or not dotted.strip(".") or ".." in dotted:
            raise SceneError(file, repr(dotted), value, "a dotted scene key such as "
                             "'sphere.radius' (see `femadh keys`)")
        parts = dotted.split(".")
        node = data
        for i, p in enumerate(parts):
            last = i == len(parts) - 1
            if isinstance(node, list):
                # a list element by its index: "substrate.layers.0.thickness"
                if not (p.isdigit() and int(p) < len(node)):
                    raise SceneError(file, ".".join(parts[:i + 1]), value,
                                     f"an index 0..{len(node) - 1} into "
                                     f"[{'.'.join(parts[:i])}]")
                p = int(p)
            elif not last and not isinstance(node.get(p), (dict, list)):
                node[p] = {}
            if last:
                node[p] = value
            else:
                node = node[p]
    return data


def replace_scene(scene, changes, kw, si, where=None):
    """Shared body of :meth:`Scene.replace` and :meth:`MeniscusScene.replace`.

    ``where``: what gave the changed values, named by their errors instead of the scene file,
    which does not hold them (:func:`~femadh.errors.given_by`); default "given to
    Scene.replace" (a study passes its ``--vary``)."""
    where = where or f"given to {type(scene).__name__}.replace"
    if changes is None or isinstance(changes, dict):
        changes = {**(changes or {}), **{k.replace("__", "."): v for k, v in kw.items()}}
    data = apply_overrides(scene.raw, changes, where)
    # the typed keys refuse a bare number for a dimensional value (as a file does); the
    # rest of the scene keeps what it was built with (SI numbers in code-built scenes)
    try:
        return scene_from_dict(data, scene.path, bare_numbers=True,
                               strict=() if si else tuple(changes))
    except SceneError as exc:
        raise given_by(exc, where, changes) from None


def reference_page():
    """Markdown page of every scene key, generated from the declarative tables."""
    from ..laws.registry import registry
    from ..schema import REQUIRED
    from . import contact, liquids, meniscus
    from .reader import _words

    tables = (list(contact.TABLES[:4]) + [r.table for r in registry().values()]
              + list(contact.TABLES[4:]) + list(meniscus.TABLES) + [liquids.LIQUID_TABLE]
              + list(liquids.ISOTHERM_TABLES.values()))
    lines = ["# Scene keys", "", "Generated from femadh's scene schema (`femadh keys`). "
             "Quantities are strings with units (\"2 mm\", \"0.165 nm\", \"25 degC\"); in "
             "scene files a bare number for a dimensional key is an error.", ""]
    seen = set()
    for t in tables:
        tag = (t.path, t.doc)
        if tag in seen:
            continue
        seen.add(tag)
        lines += [f"## [{t.path}]" if t.path else "## (top level)", "", t.doc, "",
                  "| key | expected | default | meaning |", "|---|---|---|---|"]
        for k in t.keys:
            default = "required" if k.default is REQUIRED else (
                "-" if k.default is None else f"`{k.default!r}`".replace("'", '"'))
            lines.append(f"| `{k.name}` | {k.expected(_words(k))} | {default} | {k.doc} |")
        lines.append("")
    return "\n".join(lines)


def scene_id(scene):
    """Content hash of a scene's resolved values (its output folder aside): two runs of the
    same physics and numerics have the same id."""
    data = dict(scene.resolved)
    data.pop("output_dir", None)
    blob = json.dumps(data, sort_keys=True, default=repr).encode()
    return hashlib.sha1(blob).hexdigest()[:16]
