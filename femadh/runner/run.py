"""Run any scene: :func:`run` loads it if given a path, sets the run's time limit, signal
handling and BLAS threads, and hands it to its kind's runner - :func:`femadh.runner.contact.
run_contact` or :func:`femadh.runner.meniscus.run_meniscus`. Each returns a
:class:`~femadh.runner.result.RunResult` whose life (status, summary) is
:mod:`femadh.runner.lifecycle`'s.

This is the runner's entry (the command line's, the studies'): an interrupted run is
returned with status "interrupted". :func:`femadh.run`, the Python API, raises
KeyboardInterrupt for it instead (:func:`~femadh.runner.lifecycle.raise_if_stopped`).
"""
import math
import sys

from .._threads import blas_threads
from .. import interrupt


def run(scene, out_dir=None, *, figures=True, progress=None, overwrite=False, resume=False,
        estimate=True, time_limit=None, resume_from=None, operator=None, folder_id=None):
    """Solve a scene.

    Parameters
    ----------
    scene : Scene, MeniscusScene, str or Path
        A scene or the path of its TOML file.
    out_dir : str or Path, optional
        Folder for the csv/json/VTK outputs and figures. None (the default): nothing is
        written (the command line passes the scene's ``[output] dir``). An empty string is
        refused (it would mean the current folder).
    figures : bool
        Draw the scene's figures into ``out_dir``.
    progress : bool, optional
        Progress bar on stderr; default: only when stderr is a terminal.
    overwrite, resume : bool
        What to do with a folder that holds a previous run: replace it, or continue it
        (an interrupted, failed or time-limited run of the same scene; every committed row is
        checked first, see :mod:`femadh.io.resume_check`). Neither: refuse it. A meniscus
        run is not resumed (it is short): ``resume`` is ignored for it.
    estimate : bool or "peak"
        Estimate the error of the headline numbers (a coarser grid's run, the tail beyond the
        analysis radius, the peak between the grid separations; see
        :mod:`femadh.runner.estimates`); "peak": only locate the peak.
    time_limit : float or str, optional
        Stop cleanly after this long (seconds, or a duration such as "10 min"); default the
        scene's ``[solver] time_limit``. Status "time limit"; ``resume`` continues.
    resume_from : int, optional
        Resume keeping only the first ``resume_from`` committed states (a folder whose later
        rows do not match their record).
    operator : SurfaceOperator, optional
        Reuse an operator built for this scene's grid (studies keep one per worker).
    folder_id : str, optional
        The scene id the output folder is claimed under (an adaptive run's trials claim it
        under the user's scene, so that --resume and --overwrite recognise it).

    Returns
    -------
    ContactResult or MeniscusRunResult
        Also when a step fails (status "failed", ``error`` says where), the run is
        interrupted (status "interrupted", ``exit_code`` 130 or 143) or reaches its time
        limit (status "time limit", ``exit_code`` 6): every state computed before is in the
        result and on disk.

    Raises
    ------
    SceneError, OutputError, DependencyError
        Before anything is computed.
    """
    if not hasattr(scene, "kind"):
        from ..scene import load_scene

        scene = load_scene(scene)
    if out_dir is not None and not str(out_dir).strip():
        from ..errors import OutputError

        raise OutputError("output folder '' is empty: give a folder name (None writes "
                          "nothing; '.' is the current folder)")
    if resume_from is not None:
        resume = True
    limit = time_limit_s(scene, time_limit)
    if progress is None:
        progress = sys.stderr.isatty()
    if scene.kind == "meniscus":
        from .meniscus import run_meniscus

        # (a meniscus run has its own progress bar)
        with blas_threads(), interrupt.interruptible(limit):
            return run_meniscus(scene, out_dir, figures=figures, progress=progress,
                                overwrite=overwrite)
    from ..io.progress import display
    from .contact import run_contact

    # one display over the whole run: its trials, estimate members and figures
    with blas_threads(), interrupt.interruptible(limit), display(scene.name, progress):
        return run_contact(scene, out_dir, run=run, figures=figures, progress=progress,
                           overwrite=overwrite, resume=resume, estimate=estimate,
                           resume_from=resume_from, operator=operator, folder_id=folder_id)


def time_limit_s(scene, given):
    """The run's time limit in seconds (None: none): ``given`` (seconds or a duration such as
    "10 min"), else the scene's ``[solver] time_limit``."""
    if given is None:
        return getattr(scene, "time_limit", None)
    if isinstance(given, str):
        from ..units import to_si

        given = to_si(given, "time", file="time_limit", key="time_limit")
    if not (isinstance(given, (int, float)) and given > 0 and math.isfinite(given)):
        from ..errors import SceneError

        raise SceneError("time_limit", "time_limit", given, "a positive duration such as "
                         "'10 min' or a number of seconds")
    return float(given)
