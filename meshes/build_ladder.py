"""Build the committed mesh ladder and its manifest: ``python meshes/build_ladder.py``.

Meshes are stored in units of the loaded radius a and named by the scale-free hash of their
parameters, so FEOperator finds them for any analysis radius with the same relative node
layout (uniform RadialGrid of N nodes) and mesh settings; tests and convergence studies then
run on these exact meshes, whatever gmsh version is installed.
"""
import json
from pathlib import Path

import meshio

from femadh.elastic import RadialGrid
from femadh.elastic.fe.mesh import MeshSpec, build_mesh, surface_points_of
from femadh.studies.convergence import FE_LEVELS

HERE = Path(__file__).resolve().parent

#: (N nodes, L/a, levels of FE_LEVELS): what the tests and the bundled FE scene use
LADDER = [(20, 1e3, (0, 1, 2)), (20, 10.0, (1,)), (20, 100.0, (1,)), (60, 1e4, (1,)),
          (100, 1e4, (0, 1)), (40, 1e4, (1,)), (40, 1e3, (1,)), (80, 1e3, (1,))]


def main():
    manifest = []
    for n, outer, levels in LADDER:
        grid = RadialGrid.uniform(1.0, n)
        for lev in levels:
            growth, frac = FE_LEVELS[lev]
            spec = MeshSpec(surface_points_of(grid), outer, growth, frac * float(grid.nodes[1]))
            path = HERE / f"halfspace-{spec.key()}.msh"
            build_mesh(spec, path)
            m = meshio.read(path)
            ntri = sum(len(c.data) for c in m.cells if c.type == "triangle")
            manifest.append({"file": path.name, "nodes": n, "outer_factor": outer,
                             "level": lev, "growth": growth, "surface_fraction": frac,
                             "points": len(m.points), "triangles": ntri})
            print(manifest[-1])
    (HERE / "manifest.json").write_text(json.dumps(manifest, indent=1) + "\n")


if __name__ == "__main__":
    main()
