"""femadh: finite-element adhesion of a sphere on a flat (MEMS/NEMS stiction).

Python API::

    import femadh
    scene = femadh.load_scene("validation/scenes/paper1_fig3.toml")
    result = femadh.run(scene)                         # writes nothing; a ContactResult
    result.curve("approach")["F_ex"]                   # arrays of every force column
    softer = scene.replace({"effects.asperity_gap.sigma": "0.5 nm"})   # validated again
    femadh.run(softer, "out/sigma-0.5")                # csv, json, figures into that folder
"""
from ._version import __version__  # noqa: F401  (the package version, femadh.__version__)


def load_scene(path):
    """Read and validate a scene file; see :func:`femadh.scene.load_scene`."""
    from .scene import load_scene as _load
    return _load(path)


def scene_from_dict(data, file=None):
    """Validate a scene built in code (numbers for dimensional keys are SI)."""
    from .scene import scene_from_dict as _from_dict
    return _from_dict(data, file, bare_numbers=True)


def run(scene, out_dir=None, **kwargs):
    """Solve a scene (writes into ``out_dir`` only if given); see
    :func:`femadh.runner.contact.run`.

    A Ctrl-C stops the run at its next safe point (every completed state kept on disk,
    ``summary.json`` says "interrupted", ``--resume`` continues it) and then raises
    KeyboardInterrupt here, so that one Ctrl-C also stops a script's loop of runs (SIGTERM:
    SystemExit with code 143)."""
    import signal

    from .runner.contact import run as _run
    res = _run(scene, out_dir, **kwargs)
    if res.status == "interrupted":
        if getattr(res, "exit_code", 130) == 128 + signal.SIGTERM:
            raise SystemExit(res.exit_code)
        raise KeyboardInterrupt(f"{res.error}: the states computed before it are kept"
                                + (f" in {res.out_dir}" if res.out_dir else ""))
    return res
