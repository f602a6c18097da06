"""Scene files (TOML) -> validated scenes: the user-facing contract.

Quantities are strings with units ("2 mm") or plain numbers in SI. Unknown keys, missing keys,
wrong units and unphysical values raise :class:`~femadh.errors.SceneError` naming the file,
the key, the value and what was expected. A scene with a ``[meniscus]`` table is a capillary
(paper 2) scene (:class:`MeniscusScene`); otherwise a contact scene (:class:`Scene`).
"""
from pathlib import Path

try:
    import tomllib
except ModuleNotFoundError:  # Python < 3.11
    import tomli as tomllib

from ..errors import SceneError
from .build import build_operator, build_problem
from .contact import Scene, parse_contact
from .meniscus import MeniscusScene, parse_meniscus
from .reader import Reader

__all__ = ["Scene", "MeniscusScene", "load_scene", "scene_from_dict", "build_operator",
           "build_problem"]


def load_scene(path):
    """Read and validate a scene file.

    Parameters
    ----------
    path : str or Path
        The TOML file.

    Returns
    -------
    Scene

    Raises
    ------
    SceneError
        On any malformed, missing, unknown or unphysical entry.
    """
    path = Path(path)
    try:
        text = path.read_text()
    except OSError as exc:
        raise SceneError(str(path), "(file)", str(path), f"a readable file ({exc.strerror})") \
            from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(str(path), "(file)", "(TOML text)", f"valid TOML ({exc})") from None
    return scene_from_dict(data, str(path))


def scene_from_dict(data, file=None):
    """Validate a scene given as a dict (the parsed TOML); see :func:`load_scene`."""
    top = Reader(file, data, "")
    if "meniscus" in data:
        return parse_meniscus(top, file)
    return parse_contact(top, file)
