"""On-disk cache of condensed FE operators, keyed by content like the meshes.

Condensing the FE body onto the surface nodes (assembly, sparse factorisation, one solve per
annulus) costs about a second for a 200-node grid, the whole of an FE run's overhead over the
Green function's; the result is a dense N x N matrix that depends only on the mesh, the
grid, the materials and the settings. It is stored as ``<key>.npz`` in the operator cache
(FEMADH_OPERATOR_CACHE, else ``~/.cache/femadh/operators``), the key a hash of:

- the mesh file's bytes (a rebuilt or replaced mesh is a different body),
- the grid's nodes, annulus edges and analysis radius (SI, exact float reprs),
- every region's (E, nu), the formulation, the FE settings,
- the femadh and scikit-fem versions and :data:`FORMAT` (a changed weak form or assembly is
  a different operator).

The sphere's own compliance (its Green function, milliseconds) is not cached: it is added on
load. A cache hit is the same array the fresh condensation produced (saved as float64:
identical bits); the stored nodes are compared with the grid's on load, and a file that
cannot be read is rebuilt. Writers use a temporary file and an atomic rename, so concurrent
processes (study workers) never read half a file.
"""
import hashlib
import json
import os
from pathlib import Path
import tempfile
import time

import numpy as np


#: bump when the condensation changes in a way the versions below do not capture
#: (2: the surface load through a scikit-fem FacetBasis, which moves the compliance by
#: round-off; an entry of format 1 is not the same bits as a fresh condensation)
FORMAT = 2


def cache_folder(cache_dir=None):
    """The operator cache: ``cache_dir``, else FEMADH_OPERATOR_CACHE, else
    ``~/.cache/femadh/operators`` (beside the mesh cache)."""
    from .mesh import DEFAULT_CACHE

    return Path(cache_dir or os.environ.get("FEMADH_OPERATOR_CACHE")
                or DEFAULT_CACHE.parent / "operators")


def _file_hash(path):
    h = hashlib.sha1()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def operator_key(op):
    """Content hash of what an FEOperator's body compliance depends on (see module doc)."""
    from dataclasses import asdict

    import skfem

    from ..._version import __version__

    g = op.grid
    blob = {
        "format": FORMAT, "femadh": __version__, "skfem": skfem.__version__,
        "mesh": _file_hash(op._mesh_path),
        "nodes": [repr(float(x)) for x in g.nodes],
        "edges": [repr(float(x)) for x in g.edges],
        "radius": repr(float(g.radius)),
        "materials": [[repr(float(E)), repr(float(nu))] for E, nu in op.materials],
        "formulation": op.formulation,
        "settings": asdict(op.settings),
        "outer_radius": repr(float(op.spec.outer_radius)),
    }
    return hashlib.sha1(json.dumps(blob, sort_keys=True).encode()).hexdigest()[:20]


def cached_operator(op, progress=None, *, cache_dir=None):
    """``op``, an :class:`~.operator.FEOperator` prepared but not built (its body, grid,
    settings and mesh file set), with its condensed compliance read from the on-disk operator
    cache when an identical body was condensed before, else built and stored there (keyed by
    content: the mesh file's bytes, the grid, the materials, the settings). A cached operator
    builds its mesh, stiffness and factorisation only when full fields are asked for.
    ``FEOperator.homogeneous(..., cache=True)`` and ``FEOperator.layered(..., cache=True)``
    call this (the operator hands itself in: the cache does not import it)."""
    grid = op.grid
    t0 = time.perf_counter()
    key = operator_key(op)
    folder = cache_folder(cache_dir)
    path = folder / f"fe-{key}.npz"
    stored = _read(path, grid)
    if stored is not None:
        op._built = False
        op.timings["cache_read"] = time.perf_counter() - t0
        op.cache_path, op.cache_hit = path, True
        op._set_compliance(stored)
        return op
    if progress:
        progress(f"condensing the FE body onto {grid.n} surface nodes -> {path}")
    op._build()
    fresh = op._condense()
    op._set_compliance(fresh)
    op.cache_path, op.cache_hit = path, False
    _write(path, grid, fresh)
    return op


def _read(path, grid):
    """The stored body compliance, or None (absent, unreadable, or another grid's)."""
    try:
        with np.load(path) as z:
            nodes, body = z["nodes"], z["compliance_body"]
    except (OSError, KeyError, ValueError):
        return None
    if nodes.shape != grid.nodes.shape or not np.array_equal(nodes, grid.nodes) \
            or body.shape != (grid.n, grid.n):
        return None
    return body


def _write(path, grid, body):
    """Store atomically; a cache that cannot be written only costs the next run the
    condensation (a read-only home is not an error)."""
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=".npz", dir=path.parent)
        os.close(fd)
        try:
            np.savez(tmp, nodes=grid.nodes, compliance_body=body)
            os.replace(tmp, path)
        finally:
            if os.path.exists(tmp):
                os.remove(tmp)
    except OSError:
        pass
