"""femadh: finite-element adhesion of a sphere on a flat (MEMS/NEMS stiction).

Python API::

    import femadh
    scene = femadh.load_scene("validation/scenes/paper1_fig3.toml")
    result = femadh.run(scene)          # RunResult: sweeps, jumps, curves, status
"""
from ._version import __version__  # noqa: F401  (the package version, femadh.__version__)


def load_scene(path):
    """Read and validate a scene file; see :func:`femadh.scene.load_scene`."""
    from .scene import load_scene as _load
    return _load(path)


def run(scene, out_dir=None, **kwargs):
    """Solve a scene; see :func:`femadh.runner.run`."""
    from .runner.contact import run as _run
    return _run(scene, out_dir, **kwargs)
