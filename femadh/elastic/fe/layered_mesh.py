"""Mesh of a layered body: structured layer bands on a gmsh-meshed substrate.

Everything here is in units of the loaded radius a (as the homogeneous mesh). The body is
z <= 0, the layers are the bands -D <= z <= 0, 0 <= r <= L, top first, and the substrate fills
the rest: a structured transition zone just below the stack, then the quarter disk of radius L
centred on the axis at the bottom of that zone, meshed by gmsh.

Why structured bands: a layer is often much thinner than the radial element size it needs (a
2-nm overcoat under a micrometre contact; any layer far out towards L = 1e4 a). A band made of
the surface's radial columns cut into rows resolves it with flat right triangles whatever its
thickness, where an unstructured mesher would need elements as small as the thickness all the
way to L. Column widths follow the homogeneous mesh's law (h_s on the loaded segment, with a
vertex at every grid node and annulus edge; h_s + growth (r - a) beyond); row heights follow
:func:`~femadh.elastic.fe.layers.layer_depths`. Where the size law allows it at depth (under
the load it grows like h_s + growth z), neighbouring columns are merged two into one by a
transition row, so thick layers do not carry the surface's fine columns down. Every interface
is a row boundary, i.e. a mesh line, and every triangle knows its region.

The radial refinement for thin layers (see :func:`~femadh.elastic.fe.settings.layered_surface_size`)
serves the layers only. Below the stack a few more structured rows, doubling in height, merge
the columns two into one per row back to the grid's own surface size, then follow the size law
until it is twice that (the substrate sees the same law as under a homogeneous surface, and
gmsh receives a boundary no finer than that); gmsh meshes the rest with the distance-graded
size field of the homogeneous mesh (distance from the loaded surface segment).
"""
import math

import numpy as np

from .layers import layer_depths


def surface_columns(points, size, growth, outer):
    """Radial vertex positions of the surface (units of a).

    Each interval between the fixed surface points (grid nodes and annulus edges, [0, 1]) is
    split into equal elements no longer than ``size``; beyond r = 1 the element length grows
    like size + growth (r - 1) up to r = outer (the last step is absorbed by rescaling).
    """
    pts = np.asarray(points, float)
    out = [pts[:1]]
    for lo, hi in zip(pts[:-1], pts[1:]):
        n = max(1, math.ceil((hi - lo) / size - 1e-9))
        out.append(lo + (hi - lo) * np.arange(1, n + 1) / n)
    free = [1.0]
    while free[-1] < outer:
        free.append(free[-1] + size + growth * (free[-1] - 1.0))
    free = np.asarray(free)
    # stretch the graded free part so it ends exactly at the outer radius
    free = 1.0 + (free - 1.0) * (outer - 1.0) / (free[-1] - 1.0)
    if free.size > 2 and free[-1] - free[-2] < 0.5 * (free[-2] - free[-3]):
        free = np.delete(free, -2)  # no sliver column at the outer edge
    out.append(free[1:])
    return np.concatenate(out)


def _target_size(r, depth, size, growth):
    """The size law at (r, -depth): size + growth * distance from the loaded segment."""
    return size + growth * np.hypot(np.maximum(r - 1.0, 0.0), depth)


def _merge(cols, depth, row_height, size, growth):
    """Columns that stay after a transition at ``depth``: pairs (j, j+1) whose joint width fits
    the size law there and at most twice the row height below (the transition triangle over a
    pair is then no flatter than a row's own triangles) are merged by dropping their middle
    vertex. Returns the kept indices into ``cols`` (0 and the outer edge always stay)."""
    keep = [0]
    j = 0
    n = cols.size
    while j < n - 1:
        if j + 2 <= n - 1:
            width = cols[j + 2] - cols[j]
            mid = 0.5 * (cols[j] + cols[j + 2])
            if width <= min(_target_size(mid, depth, size, growth), 2.0 * row_height):
                keep.append(j + 2)
                j += 2
                continue
        keep.append(j + 1)
        j += 1
    return np.asarray(keep)


def _row_triangles(top_ids, top_r, bottom_ids, kept):
    """Triangles between a row's top vertices and its bottom vertices (``kept``: which top
    columns continue below; a dropped top vertex makes a 3-triangle transition)."""
    tris = []
    kept_set = np.zeros(top_r.size, bool)
    kept_set[kept] = True
    below = -np.ones(top_r.size, int)
    below[kept] = bottom_ids
    j = 0
    while j < top_r.size - 1:
        if kept_set[j + 1]:
            t0, t1, b0, b1 = top_ids[j], top_ids[j + 1], below[j], below[j + 1]
            tris += [(t0, b0, b1), (t0, b1, t1)]
            j += 1
        else:  # j and j+2 continue, j+1 ends here
            t0, t1, t2 = top_ids[j], top_ids[j + 1], top_ids[j + 2]
            b0, b2 = below[j], below[j + 2]
            tris += [(t0, b0, t1), (t1, b0, b2), (t1, b2, t2)]
            j += 2
    return tris


def structured_bands(columns, row_depths, row_regions, row_sizes, growth):
    """Vertices and triangles of the structured bands.

    Parameters
    ----------
    columns : ndarray
        Surface vertex radii (units of a), from 0 to the outer radius.
    row_depths : ndarray
        Depths (> 0, increasing) of the row boundaries below the surface.
    row_regions : ndarray of int
        Region id of each row.
    row_sizes : ndarray
        Base size of the size law (units of a) that decides merges at each row's bottom:
        columns may coarsen to row_size + growth * distance from the loaded segment.
    growth : float

    Returns
    -------
    points : ndarray (n, 2)
    triangles : ndarray (m, 3)
    regions : ndarray (m,)
    bottom : (ids, radii) of the lowest row boundary's vertices
    """
    points = [np.column_stack([columns, np.zeros_like(columns)])]
    top_ids = np.arange(columns.size)
    top_r = columns
    n_pts = columns.size
    tris, regs = [], []
    prev = 0.0
    for depth, region, size in zip(row_depths, row_regions, row_sizes):
        kept = _merge(top_r, depth, depth - prev, size, growth)
        r_bot = top_r[kept]
        bot_ids = n_pts + np.arange(r_bot.size)
        points.append(np.column_stack([r_bot, np.full(r_bot.size, -depth)]))
        n_pts += r_bot.size
        row = _row_triangles(top_ids, top_r, bot_ids, kept)
        tris += row
        regs += [region] * len(row)
        top_ids, top_r, prev = bot_ids, r_bot, depth
    return (np.vstack(points), np.asarray(tris, int), np.asarray(regs, int), (top_ids, top_r))


def transition_depths(start, first, node_size, growth):
    """Row boundaries (depths) of the substrate's structured zone below a stack at ``start``.

    The rows double in height from ``first`` (the finest column width, so columns refined for a
    thin layer merge two into one per row) until they reach ``node_size`` (the grid's own
    surface size), then follow node_size + growth z until that reaches twice ``node_size``:
    from there the columns match the substrate's size law and gmsh takes over.
    """
    out = []
    z, height = start, first
    while height < node_size:
        height *= 2.0
        z += height
        out.append(z)
    while node_size + growth * z < 2.0 * node_size or not out:
        z += node_size + growth * z
        out.append(z)
    return np.asarray(out)


def gmsh_substrate(bottom_r, depth, outer, size, growth):
    """Mesh the substrate quarter disk below the structured zone with gmsh.

    Its top boundary is the structured zone's bottom row (one mesh edge per pair of vertices),
    centre (0, -depth), radius ``outer``; size field: size + growth * distance from the loaded
    surface segment (0 <= r <= 1, z = 0). Returns (points (n, 2), triangles (m, 3)) with the
    top-row vertices first, in the order of ``bottom_r``.
    """
    import gmsh

    gmsh.initialize(interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("substrate")
        geo = gmsh.model.geo
        lc = outer / 4
        top = [geo.addPoint(float(r), -depth, 0.0, lc) for r in bottom_r]
        centre = top[0]
        bottom = geo.addPoint(0.0, -depth - outer, 0.0, lc)
        lines = [geo.addLine(top[i], top[i + 1]) for i in range(len(top) - 1)]
        arc = geo.addCircleArc(top[-1], centre, bottom)
        axis = geo.addLine(bottom, top[0])
        surf = geo.addPlaneSurface([geo.addCurveLoop(lines + [arc, axis])])
        # the loaded surface segment, only as the source of the distance field
        s0, s1 = geo.addPoint(0.0, 0.0, 0.0, lc), geo.addPoint(1.0, 0.0, 0.0, lc)
        helper = geo.addLine(s0, s1)
        geo.synchronize()
        for c in lines:  # keep the structured zone's vertices: one mesh edge per line
            gmsh.model.mesh.setTransfiniteCurve(c, 2)
        f = gmsh.model.mesh.field
        dist = f.add("Distance")
        f.setNumbers(dist, "CurvesList", [helper])
        f.setNumber(dist, "Sampling", 400)
        law = f.add("MathEval")
        f.setString(law, "F", f"{size:.12f} + {growth:.12f} * F{dist}")
        f.setAsBackgroundMesh(law)
        gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
        gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
        gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
        gmsh.option.setNumber("Mesh.Algorithm", 6)
        gmsh.model.mesh.generate(2)
        tags, xyz, _ = gmsh.model.mesh.getNodes()
        xyz = xyz.reshape(-1, 3)[:, :2]
        _, _, conn = gmsh.model.mesh.getElements(2, surf)
        tri_tags = conn[0].reshape(-1, 3)
        top_tags = [gmsh.model.mesh.getNodes(0, p)[0][0] for p in top]
    finally:
        gmsh.finalize()
    # renumber: the top-row vertices first (in bottom_r order), then the rest
    used = np.unique(tri_tags)
    index = {int(t): i for i, t in enumerate(tags)}
    top_set = set(int(x) for x in top_tags)
    order = [index[int(t)] for t in top_tags]
    rest = [index[int(t)] for t in used if int(t) not in top_set]
    pos = np.concatenate([order, rest]).astype(int)
    new = -np.ones(int(tags.max()) + 1, int)
    new[tags[pos].astype(int)] = np.arange(pos.size)
    return xyz[pos], new[tri_tags.astype(int)]


def layered_mesh(surface_points, outer, size, layer_size, growth, thicknesses, min_elements):
    """The whole layered mesh in units of a.

    Parameters
    ----------
    surface_points : ndarray
        Fixed surface vertices on [0, 1] (grid nodes and annulus edges).
    outer : float
        L / a.
    size : float
        The grid's surface element size h_s: the substrate's size law is h_s + growth * d.
    layer_size : float
        Radial element size on the loaded surface for the layers (<= size: the radial grading
        rule for thin layers); the layers' own law is layer_size + growth * d.
    growth : float
    thicknesses : sequence of float
        Layer thicknesses (units of a), top first.
    min_elements : int
        Least number of rows through a layer.

    Returns
    -------
    points (n, 2), triangles (m, 3), region ids (m,) (layer index from the top,
    len(thicknesses) for the substrate), and a dict of boundary edges (pairs of vertex
    indices): "surface", "axis", "far" and "interface_<i>".
    """
    pts = np.asarray(surface_points, float)
    node_size = min(size, float(np.min(np.diff(pts))))
    h_top = min(layer_size, node_size)
    columns = surface_columns(pts, h_top, growth, outer)
    depths, regions, sizes = [], [], []
    top = 0.0
    for i, (t, frac) in enumerate(zip(thicknesses, layer_depths(thicknesses, h_top, growth,
                                                                  min_elements))):
        depths += list(top + t * frac)
        regions += [i] * frac.size
        sizes += [h_top] * frac.size
        top += t
    n_layers = len(thicknesses)
    zone = transition_depths(top, h_top, node_size, growth)
    depths += list(zone)
    regions += [n_layers] * zone.size
    sizes += [node_size] * zone.size
    p_s, t_s, r_s, (bot_ids, bot_r) = structured_bands(columns, np.asarray(depths),
                                                       np.asarray(regions), np.asarray(sizes),
                                                       growth)
    z_bottom = depths[-1]
    p_g, t_g = gmsh_substrate(bot_r, z_bottom, outer, node_size, growth)
    # glue: gmsh's first len(bot_r) vertices are the structured bottom row
    n_top = bot_r.size
    if np.max(np.abs(p_g[:n_top, 0] - bot_r)) > 1e-12 * outer:
        raise RuntimeError("gmsh moved the vertices of the structured zone's bottom row")
    glue = np.concatenate([bot_ids, p_s.shape[0] + np.arange(p_g.shape[0] - n_top)])
    points = np.vstack([p_s, p_g[n_top:]])
    triangles = _counter_clockwise(points, np.vstack([t_s, glue[t_g]]))
    region = np.concatenate([r_s, np.full(t_g.shape[0], n_layers)])
    return points, triangles, region, _boundaries(points, triangles, region, n_layers, outer,
                                                  z_bottom, depths, regions)


def _counter_clockwise(points, triangles):
    """The triangles with their vertices in counter-clockwise order in (r, z)."""
    x = points[triangles]
    area = ((x[:, 1, 0] - x[:, 0, 0]) * (x[:, 2, 1] - x[:, 0, 1])
            - (x[:, 2, 0] - x[:, 0, 0]) * (x[:, 1, 1] - x[:, 0, 1]))
    if np.any(area == 0.0):
        raise RuntimeError("degenerate triangle in the layered mesh")
    out = triangles.copy()
    flip = area < 0
    out[flip] = out[flip][:, [0, 2, 1]]
    return out


def _boundaries(points, triangles, region, n_layers, outer, z_bottom, depths, regions):
    """Boundary and interface edges (vertex pairs) of the mesh, for its 1D physical groups."""
    edges = np.sort(np.vstack([triangles[:, [0, 1]], triangles[:, [1, 2]],
                               triangles[:, [2, 0]]]), axis=1)
    uniq, count = np.unique(edges, axis=0, return_counts=True)
    bnd = uniq[count == 1]
    x = points[bnd]                                # (nb, 2 ends, 2 coords)
    out = {"surface": bnd[np.all(x[:, :, 1] == 0.0, axis=1)],
           "axis": bnd[np.all(x[:, :, 0] == 0.0, axis=1)]}
    edge_far = np.all(x[:, :, 0] >= outer * (1 - 1e-12), axis=1)
    arc = np.all(np.hypot(x[:, :, 0], x[:, :, 1] + z_bottom) >= outer * (1 - 1e-9), axis=1)
    out["far"] = bnd[edge_far | arc]
    # interfaces: row boundaries where the region changes
    inner = uniq[count == 2]
    xi = points[inner]
    for i in range(n_layers):
        z_i = depths[int(np.flatnonzero(np.asarray(regions) == i)[-1])]
        on = np.all(np.abs(xi[:, :, 1] + z_i) <= 1e-12 * max(1.0, z_i), axis=1)
        out[f"interface_{i}"] = inner[on]
    return out


def write_msh(path, points, triangles, region, boundaries, n_layers):
    """Write the layered mesh as a gmsh .msh (via meshio) with physical groups: triangles
    ``layer_<i>`` (tag i + 1) and ``substrate`` (tag n + 1); lines ``surface``, ``axis``,
    ``far`` and ``interface_<i>`` (tags from 101)."""
    import meshio

    names = [f"layer_{i}" for i in range(n_layers)] + ["substrate"]
    field_data = {name: np.array([i + 1, 2]) for i, name in enumerate(names)}
    cells, phys = [("triangle", triangles)], [region + 1]
    for k, (name, e) in enumerate(boundaries.items()):
        if len(e):
            cells.append(("line", e))
            phys.append(np.full(len(e), 101 + k))
            field_data[name] = np.array([101 + k, 1])
    mesh = meshio.Mesh(np.column_stack([points, np.zeros(len(points))]), cells,
                       cell_data={"gmsh:physical": phys, "gmsh:geometrical": phys},
                       field_data=field_data)
    meshio.write(str(path), mesh, file_format="gmsh22", binary=False)
