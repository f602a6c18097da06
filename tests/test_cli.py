"""The command line a newcomer meets: --version, python -m femadh, --help, the key reference,
and the PyVista render of an FE run (read back as a picture)."""
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import femadh
from femadh.cli import main


ROOT = Path(__file__).resolve().parents[1]


def test_version_and_module_entry_point():
    out = subprocess.run([sys.executable, "-m", "femadh", "--version"], capture_output=True,
                         text=True, cwd=ROOT)
    assert out.returncode == 0 and out.stdout.strip() == f"femadh {femadh.__version__}"
    out = subprocess.run([sys.executable, "-m", "femadh", "--help"], capture_output=True,
                         text=True, cwd=ROOT)
    for cmd in ("run", "check", "keys", "mesh", "render", "study", "regime"):
        assert cmd in out.stdout
    assert "exit codes" in out.stdout


def test_keys_prints_the_reference(capsys):
    assert main(["keys"]) == 0
    page = capsys.readouterr().out
    assert page.startswith("# Scene keys") and "## [effects.lennard_jones]" in page


@pytest.mark.slow
def test_render_an_fe_run_to_png(tmp_path, tiny_fe_run):
    """femadh render on an FE run: a PNG of the deformed zone, read back: the size asked for
    and a picture (many distinct colours), not an empty canvas. (The run is conftest's
    tiny_fe_run, shared with test_output's render test: without the error estimate, whose
    coarser FE members the render never reads.)"""
    import matplotlib.image as mpimg

    out = tiny_fe_run(tmp_path)
    assert main(["render", str(out)]) == 0
    img = mpimg.imread(out / "render.png")
    assert img.shape[:2] == (700, 1100)
    colours = np.unique((img[..., :3] * 255).astype(int).reshape(-1, 3), axis=0)
    assert len(colours) > 200
    assert main(["render", str(tmp_path)]) == 4       # no FE run there: one clear line
