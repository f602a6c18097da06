"""Validation scripts: paper tables, cross-checks and benchmarks (``python -m validation.X``)."""
import os
from pathlib import Path

# the validation runs on the committed FE mesh ladder where it has the mesh (as the tests do)
os.environ.setdefault("FEMADH_MESH_PATH", str(Path(__file__).resolve().parents[1] / "meshes"))
