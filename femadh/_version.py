"""The package version (one place; read by the summary writers and ``--version``), and the
fingerprint of the code that computes: a study reuses a point's record only when it was
computed by the same code (a version string alone does not change while the code does)."""
from functools import lru_cache

__version__ = "0.2.0"


@lru_cache(maxsize=1)
def code_id():
    """``"<version>+<12 hex>"``: the version and a SHA-256 of every .py file of the package
    (relative path and bytes, in sorted order; ~10 ms, once per process). Its imports are
    here, not at the top: ``import femadh`` runs before the program's start-up signal
    handlers are in place (femadh.cli), and hashlib's ~2 ms were part of that window."""
    import hashlib
    from pathlib import Path

    root = Path(__file__).resolve().parent
    h = hashlib.sha256()
    for f in sorted(root.rglob("*.py")):
        h.update(f.relative_to(root).as_posix().encode() + b"\0")
        h.update(f.read_bytes())
    return f"{__version__}+{h.hexdigest()[:12]}"
