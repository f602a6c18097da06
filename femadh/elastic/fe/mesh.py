"""gmsh builder of the axisymmetric half-space mesh (r, z), z <= 0, and its cache.

Homogeneous domain: the quarter disk r^2 + z^2 <= L^2 with r, -z >= 0. Boundaries: ``surface``
(z = 0), ``axis`` (r = 0), ``far`` (the arc). Layered domain (:func:`build_layered_mesh`): the
layers are structured bands 0 <= r <= L, -D <= z <= 0 (D the stack depth), a structured
transition zone of the substrate follows, then the quarter disk of radius L centred on the axis
below it; ``far`` is the bands' outer edge r = L plus that arc.

On the loaded part of the surface, 0 <= r <= a, the mesh has a vertex at every collocation
node *and* every annulus edge of the RadialGrid, so each surface facet lies inside one pressure
annulus (the load is integrated exactly) and the nodal displacements are mesh values. The
element size grows linearly with the distance from the loaded segment (gmsh Distance + MathEval
fields), so L can be 1e4-1e5 times a for a few percent more elements.
"""
from dataclasses import dataclass
import hashlib
import json
from pathlib import Path

import numpy as np

#: cache folder for meshes built on demand (override with FEMADH_MESH_CACHE)
DEFAULT_CACHE = Path.home() / ".cache" / "femadh" / "meshes"


@dataclass(frozen=True)
class MeshSpec:
    """Parameters of a half-space mesh (SI units).

    Attributes
    ----------
    surface_points : tuple of float
        Sorted radii of the surface vertices on the loaded segment [0, a] (nodes and annulus
        edges of the RadialGrid), first 0, last a.
    outer_radius : float
        L, radius of the far boundary (m).
    growth : float
        Element size growth rate: h = h_s + growth * distance from the loaded segment.
    surface_size : float
        h_s, element size at the loaded segment (m).
    layers : tuple of float
        Layer thicknesses (m), top first; empty for the homogeneous half-space.
    layer_surface_size : float or None
        Radial element size on the loaded surface inside the layers (m), <= surface_size
        (thin layers are resolved radially; the substrate keeps surface_size).
    layer_min_elements : int
        Least number of elements through a layer (see
        :func:`~femadh.elastic.fe.layers.layer_depths`).
    """

    surface_points: tuple
    outer_radius: float
    growth: float
    surface_size: float
    layers: tuple = ()
    layer_min_elements: int = 2
    layer_surface_size: float = None

    @property
    def loaded_radius(self):
        return self.surface_points[-1]

    @property
    def depth(self):
        """D, total thickness of the layers (m)."""
        return float(sum(self.layers))

    @property
    def file_name(self):
        """Cache file name: ``halfspace-<key>.msh`` or ``layered-<key>.msh``."""
        return f"{'layered' if self.layers else 'halfspace'}-{self.key()}.msh"

    def normalised(self):
        """The spec in units of the loaded radius a (what gmsh meshes and the file stores).

        The layer entries appear only for a layered body, so homogeneous keys (and the
        committed meshes named by them) are those of the meshes built before layers existed.
        """
        a = self.loaded_radius
        out = {"surface_points": [round(x / a, 12) for x in self.surface_points],
               "outer_factor": round(self.outer_radius / a, 9),
               "growth": round(self.growth, 12),
               "surface_size": round(self.surface_size / a, 12)}
        if self.layers:
            out["layers"] = [round(t / a, 12) for t in self.layers]
            out["layer_min_elements"] = int(self.layer_min_elements)
            out["layer_surface_size"] = round((self.layer_surface_size or self.surface_size)
                                              / a, 12)
        return out

    def key(self):
        """Content hash of the normalised parameters: the cache file name. Scale-free, so one
        committed mesh serves every analysis radius with the same relative node layout (and,
        layered, the same thicknesses relative to it)."""
        blob = json.dumps(self.normalised(), sort_keys=True).encode()
        return hashlib.sha1(blob).hexdigest()[:16]


def surface_points_of(grid):
    """Sorted union of a RadialGrid's nodes and annulus edges."""
    return tuple(float(x) for x in np.unique(np.concatenate([grid.nodes, grid.edges])))


def build_mesh(spec: MeshSpec, path):
    """Mesh ``spec`` with gmsh (linear triangles) and write it to ``path`` (.msh).

    Returns the path. gmsh runs headless and quiet; it is initialised and finalised here.
    A spec with layers is meshed by :func:`build_layered_mesh`.
    """
    import gmsh

    if spec.layers:
        return build_layered_mesh(spec, path)

    # gmsh works in units of the loaded radius a: its geometric tolerances are absolute
    # (1e-8), which SI micrometre coordinates would fall below
    a = float(spec.surface_points[-1])
    pts = np.asarray(spec.surface_points) / a
    L = float(spec.outer_radius) / a
    if not L > 1:
        raise ValueError(f"outer radius {spec.outer_radius} m must exceed the loaded radius "
                         f"{a} m")
    gmsh.initialize(interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("halfspace")
        geo = gmsh.model.geo
        lc_far = L / 4
        tags = [geo.addPoint(r, 0.0, 0.0, lc_far) for r in pts]
        p_far_r = geo.addPoint(L, 0.0, 0.0, lc_far)
        p_far_z = geo.addPoint(0.0, -L, 0.0, lc_far)
        center = tags[0]
        loaded = [geo.addLine(tags[i], tags[i + 1]) for i in range(len(tags) - 1)]
        free = geo.addLine(tags[-1], p_far_r)
        arc = geo.addCircleArc(p_far_r, center, p_far_z)
        axis = geo.addLine(p_far_z, center)
        loop = geo.addCurveLoop(loaded + [free, arc, axis])
        surf = geo.addPlaneSurface([loop])
        geo.synchronize()
        gmsh.model.addPhysicalGroup(1, loaded + [free], name="surface")
        gmsh.model.addPhysicalGroup(1, [axis], name="axis")
        gmsh.model.addPhysicalGroup(1, [arc], name="far")
        gmsh.model.addPhysicalGroup(2, [surf], name="solid")
        f = gmsh.model.mesh.field
        dist = f.add("Distance")
        f.setNumbers(dist, "CurvesList", loaded)
        f.setNumber(dist, "Sampling", 4)  # per curve: each loaded curve is one short segment
        size = f.add("MathEval")
        f.setString(size, "F", f"{spec.surface_size / a:.12f} + {spec.growth:.12f} * F{dist}")
        f.setAsBackgroundMesh(size)
        gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
        gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
        gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
        gmsh.option.setNumber("Mesh.Algorithm", 6)  # Frontal-Delaunay: good grading
        gmsh.model.mesh.generate(2)
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
        gmsh.write(str(path))
    finally:
        gmsh.finalize()
    return Path(path)


def build_layered_mesh(spec: MeshSpec, path):
    """Mesh a layered body (layers on a substrate half-space) and write ``path`` (.msh).

    Structured bands for the layers and a structured transition zone below them, gmsh for
    the rest of the substrate (:mod:`~femadh.elastic.fe.layered_mesh`); the same surface
    vertices and size law as the homogeneous mesh. Physical groups: triangles ``layer_<i>``
    (tag i + 1, top layer i = 0) and ``substrate`` (tag n + 1); lines ``surface``, ``axis``,
    ``far``, ``interface_<i>`` (below layer i).
    """
    from .layered_mesh import layered_mesh, write_msh

    a = float(spec.surface_points[-1])
    pts = np.asarray(spec.surface_points) / a
    L = float(spec.outer_radius) / a
    thick = [float(t) / a for t in spec.layers]
    if not L > max(1.0, 2 * sum(thick)):
        raise ValueError(f"outer radius {spec.outer_radius} m must exceed the loaded radius "
                         f"{a} m and twice the stack depth {spec.depth} m")
    layer_size = (spec.layer_surface_size or spec.surface_size) / a
    points, tri, region, bnd = layered_mesh(pts, L, spec.surface_size / a, layer_size,
                                            spec.growth, thick, spec.layer_min_elements)
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    write_msh(path, points, tri, region, bnd, len(thick))
    return Path(path)


def _read_meshio(path):
    """The meshio Mesh of a .msh file, quietly."""
    import contextlib
    import io

    import meshio

    # meshio's gmsh 4.1 reader prints a bare newline to stdout, which would end up in a
    # user's piped output
    with contextlib.redirect_stdout(io.StringIO()):
        return meshio.read(str(path))


def _triangles(m, regions):
    """(points (n, 2), triangles (m, 3) into them, remap of the file's points[, tags]) of a
    meshio Mesh, the points not used by any triangle dropped."""
    blocks = [i for i, c in enumerate(m.cells) if c.type == "triangle"]
    tri = np.concatenate([m.cells[i].data for i in blocks])
    used = np.unique(tri)
    # drop points not used by triangles (gmsh keeps geometry points such as the arc centre)
    remap = -np.ones(len(m.points), int)
    remap[used] = np.arange(used.size)
    points = m.points[used, :2]
    if not regions:
        return points, remap[tri], remap
    tag = np.concatenate([m.cell_data["gmsh:physical"][i] for i in blocks]).astype(int)
    if "solid" in m.field_data:
        tag = np.ones_like(tag)
    return points, remap[tri], remap, tag - 1


def read_mesh(path, scale=1.0, regions=False):
    """Read a .msh with meshio; returns (points (n, 2) times ``scale``, triangles (m, 3)).

    Meshes are stored in units of the loaded radius; pass scale = a for SI coordinates. With
    ``regions`` also returns each triangle's region id: the physical tag - 1, i.e. the layer
    index from the top (0 ...) and the layer count for the substrate; a homogeneous mesh
    (one physical group "solid") gives 0 everywhere.
    """
    out = _triangles(_read_meshio(path), regions)
    if not regions:
        return out[0] * scale, out[1]
    return out[0] * scale, out[1], out[3]


#: the named boundaries (1D physical groups) every half-space mesh carries
BOUNDARIES = ("surface", "axis", "far")


def named_boundaries(m, remap, facets):
    """Facet indices of every 1D physical group of a meshio Mesh ``m``.

    Parameters
    ----------
    m : meshio.Mesh
        As read from the .msh (gmsh 4.1 from gmsh, 2.2 from the layered mesher: both carry
        ``gmsh:physical`` line tags and the group names in ``field_data``).
    remap : ndarray of int
        The file's point index -> the mesh's (-1: dropped).
    facets : ndarray (2, nf)
        The scikit-fem mesh's facets (vertex pairs).

    Returns
    -------
    dict of str -> ndarray of int
        Sorted facet indices per group name (``surface``, ``axis``, ``far``, ``interface_<i>``).
    """
    names = {int(v[0]): k for k, v in m.field_data.items() if int(v[1]) == 1}
    n = int(facets.max()) + 1
    lo, hi = np.sort(facets, axis=0)
    key = lo.astype(np.int64) * n + hi
    order = np.argsort(key)
    out = {}
    for cells, tags in zip(m.cells, m.cell_data["gmsh:physical"]):
        if cells.type != "line":
            continue
        e = np.sort(remap[cells.data], axis=1)
        if np.any(e < 0):
            raise ValueError("a named boundary edge has a vertex of no triangle")
        k = e[:, 0].astype(np.int64) * n + e[:, 1]
        pos = np.searchsorted(key, k, sorter=order).clip(0, key.size - 1)
        found = order[pos]
        if not np.array_equal(key[found], k):
            raise ValueError("a named boundary edge is no edge of the mesh")
        for tag in np.unique(tags):
            name = names.get(int(tag), f"tag_{int(tag)}")
            out.setdefault(name, []).append(found[tags == tag])
    return {k: np.unique(np.concatenate(v)) for k, v in out.items()}


def load_mesh(path, scale=1.0):
    """The scikit-fem mesh of a .msh with its named boundaries, and each triangle's region.

    Points are scaled by ``scale`` (meshes are stored in units of the loaded radius a: pass
    scale = a for SI coordinates); ``mesh.boundaries`` maps every 1D physical group (at least
    :data:`BOUNDARIES`) to its facets, so boundary DOFs are found by name
    (``basis.get_dofs("far")``). Regions as :func:`read_mesh`.

    Raises
    ------
    ValueError
        If a group of :data:`BOUNDARIES` is missing (naming the file and the group).
    """
    from skfem import MeshTri

    m = _read_meshio(path)
    points, tri, remap, region = _triangles(m, True)
    mesh = MeshTri(np.ascontiguousarray((points * scale).T), np.ascontiguousarray(tri.T))
    bnd = named_boundaries(m, remap, mesh.facets)
    missing = [b for b in BOUNDARIES if b not in bnd]
    if missing:
        raise ValueError(f"mesh {path} has no boundary group {', '.join(map(repr, missing))} "
                         f"(expected the 1D physical groups {', '.join(BOUNDARIES)})")
    return mesh.with_boundaries(bnd), region


def mesh_search_path():
    """Folders searched for a mesh before the cache: FEMADH_MESH_PATH (os.pathsep-separated),
    e.g. the repository's committed ladder ``meshes/`` that the tests use."""
    import os

    return [Path(p) for p in os.environ.get("FEMADH_MESH_PATH", "").split(os.pathsep) if p]


def cached_mesh(spec: MeshSpec, cache_dir=None, *, progress=None):
    """Path of the mesh for ``spec``, built with gmsh on first use and cached by content hash
    in ``cache_dir`` (default FEMADH_MESH_CACHE, else ~/.cache/femadh/meshes). Folders of
    :func:`mesh_search_path` are searched first.

    Safe with concurrent writers: each builds into its own temporary file and renames it into
    place (atomic on one filesystem), so a reader never sees a half-written mesh and two
    processes building the same mesh both end with a complete one.
    """
    import os
    import tempfile

    name = spec.file_name
    for folder in mesh_search_path():
        if (folder / name).exists():
            return folder / name
    cache = Path(cache_dir or os.environ.get("FEMADH_MESH_CACHE") or DEFAULT_CACHE)
    path = cache / name
    if not path.exists():
        if progress:
            progress(f"meshing ({len(spec.surface_points)} surface points, L = "
                     f"{spec.outer_radius:.3g} m) -> {path}")
        cache.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{name}.", suffix=".msh", dir=cache)
        os.close(fd)
        try:
            build_mesh(spec, tmp)
            os.replace(tmp, path)
        finally:
            if os.path.exists(tmp):
                os.remove(tmp)
    return path
