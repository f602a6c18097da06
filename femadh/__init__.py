"""femadh: finite-element adhesion of a sphere on a flat (MEMS/NEMS stiction).

Python API::

    import femadh
    scene = femadh.load_scene("validation/scenes/paper1_fig3.toml")
    result = femadh.run(scene)                         # writes nothing; a ContactResult
    result.curve("approach")["F_ex"]                   # arrays of every force column
    softer = scene.replace({"effects.asperity_gap.sigma": "0.5 nm"})   # validated again
    femadh.run(softer, "out/sigma-0.5")                # csv, json, figures into that folder
"""
# the package version, femadh.__version__, and the fingerprint of its code (a study's records)
from ._version import __version__, code_id  # noqa: F401
from .errors import (ConvergenceError, DependencyError, DomainError,  # noqa: F401
                     FemadhError, Interrupted, LawError, MeshResolutionWarning, OutputError,
                     SceneError, TimeLimitReached)

#: the result types, loaded on first use (they load the numerical core, ~0.8 s)
_RESULTS = ("RunResult", "ContactResult", "MeniscusRunResult")

__all__ = ["load_scene", "scene_from_dict", "run", "Scene", *_RESULTS,
           "FemadhError", "SceneError", "OutputError", "ConvergenceError", "DependencyError",
           "LawError", "DomainError", "Interrupted", "TimeLimitReached",
           "MeshResolutionWarning", "__version__", "code_id"]


def __getattr__(name):
    # Scene and the result types load the numerical core (~0.8 s): only when asked for
    if name == "Scene":
        from .scene import Scene
        return Scene
    if name in _RESULTS:
        from .runner import result
        return getattr(result, name)
    raise AttributeError(f"module 'femadh' has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(__all__))


def load_scene(path):
    """Read and validate a scene file; see :func:`femadh.scene.load_scene`."""
    from .scene import load_scene as _load
    return _load(path)


def scene_from_dict(data, file=None):
    """Validate a scene built in code (numbers for dimensional keys are SI)."""
    from .scene import scene_from_dict as _from_dict
    return _from_dict(data, file, bare_numbers=True)


def run(scene, out_dir=None, *, figures=True, progress=None, overwrite=False, resume=False,
        estimate=True, time_limit=None, resume_from=None, operator=None, folder_id=None):
    """Solve a scene; write its outputs into ``out_dir`` only if one is given.

    Parameters
    ----------
    scene : Scene or str or Path
        A scene (:func:`load_scene`, :func:`scene_from_dict`, ``Scene.replace``) or the path
        of its TOML file.
    out_dir : str or Path, optional
        Folder for curve.csv, fields.csv, diagnostics.csv, jumps.csv, summary.json and the
        figures (a meniscus scene: meniscus.csv, profiles.csv). None (default): nothing is
        written. ``""`` is refused (OutputError).
    figures : bool
        Draw the figures into ``out_dir`` (default True).
    progress : bool, optional
        Progress on stderr (default: only when stderr is a terminal).
    overwrite : bool
        Replace the outputs of a previous run in ``out_dir``.
    resume : bool
        Continue an interrupted, failed or time-limited run of the same scene in ``out_dir``
        (every committed row is checked first; the result equals an uninterrupted run's).
    estimate : bool or "peak"
        Estimate the headline numbers' errors (coarser grids, the tail, the peak between
        the separations); "peak": only locate the peak; False: neither.
    time_limit : float or str, optional
        Stop cleanly after this long (seconds or e.g. "10 min"); default the scene's
        ``[solver] time_limit``. The result then has status "time limit".
    resume_from : int, optional
        Resume keeping only the first ``resume_from`` committed states.
    operator : SurfaceOperator, optional
        Reuse a surface operator built for this scene's grid (:func:`femadh.scene.
        build_operator`; studies keep one per worker).
    folder_id : str, optional
        Claim ``out_dir`` under this scene id instead of the scene's own (an adaptive run's
        trials are claimed under the user's scene).

    Returns
    -------
    RunResult
        A ContactResult or a MeniscusRunResult: ``status`` is "converged", "failed"
        (``error`` says where) or "time limit" (``exit_code`` 6); ``headline`` (the numbers
        and their ``<name>_error``), ``timings``, ``summary()``, ``to_csv(path)``; a contact
        run also ``curve(branch)``, ``estimates``, ``jumps``, a meniscus run ``curves``.

    Raises
    ------
    KeyboardInterrupt
        After a Ctrl-C: the run stopped at its next safe point (every completed state kept
        on disk, ``summary.json`` says "interrupted", ``resume=True`` continues it), so that
        one Ctrl-C also stops a script's loop of runs.
    SystemExit
        With code 143 after SIGTERM (the same safe stop).
    SceneError, OutputError, DependencyError
        Before anything is computed.
    """
    from .runner.lifecycle import raise_if_stopped
    from .runner.run import run as _run

    return raise_if_stopped(_run(
        scene, out_dir, figures=figures, progress=progress, overwrite=overwrite,
        resume=resume, estimate=estimate, time_limit=time_limit, resume_from=resume_from,
        operator=operator, folder_id=folder_id))
