"""The layered body under a contact, rendered: a silica tip on a 300-nm PDMS-like film on glass
near zero load, regions and interfaces visible, sigma_zz.

``python -m validation.layered.render`` writes out/layered-vtk/ and results/layered_body.png
(PyVista, off-screen).
"""
from pathlib import Path

import numpy as np

from femadh.contact import State
from femadh.discretisation.moving import contact_edge
from femadh.elastic.fe import FEOperator, Layer
from femadh.studies.smooth_sphere import lj_sphere_problem

from .common import FILM, FILM_MU, GLASS, RESULTS, TIP, TIP_R, film_law, film_point

OUT = Path("out") / "layered-vtk"


def main():
    """Write the VTK of a film under contact (out/layered-vtk) and results/layered_body.png."""
    import pyvista as pv

    from femadh.io.vtk import write_state

    pv.OFF_SCREEN = True
    A, z0 = film_law()
    base, lj, _, _, d_min = lj_sphere_problem(FILM_MU, TIP_R, A, z0, 0.4, 120)
    grid = base.grid
    t = 300e-9
    op = FEOperator.layered(grid, GLASS, [Layer(t, FILM.youngs_modulus, FILM.poisson_ratio)],
                            TIP)
    point = film_point(op, lj, z0, d_min)
    problem, curve = point["problem"], point["curve"]
    # a compressive stable state near the zero-load contact
    cf = point["curve_F"]
    k = next(i for i in range(len(cf)) if curve.points[i].stable and cf[i] < -0.5
             and curve.points[i].d < 0)
    p = curve.points[k]
    h = problem.contour(p.d) - p.w
    state = State(p.d, p.w, h, {"lj": problem.effects["lj"].pressure(h)}, np.zeros_like(h),
                  np.zeros(h.size, bool), contact_edge(problem, p.w, p.d, z0), 0, 0.0,
                  True, True)
    OUT.mkdir(parents=True, exist_ok=True)
    vol, _ = write_state(OUT, "film", 0, state, problem)
    m = pv.read(OUT / vol)
    a0 = point["a0"]
    clip = m.clip_box([0, 2.5 * a0, -2.5 * a0, 0, -1, 1], invert=False)
    scale = 0.15 * a0 / max(np.abs(m["displacement"]).max(), 1e-30)
    warped = clip.warp_by_vector("displacement", factor=scale)
    warped.points[:] /= 1e-6
    pl = pv.Plotter(off_screen=True, shape=(1, 2), window_size=(1600, 650))
    pl.subplot(0, 0)
    pl.add_mesh(warped, scalars="region", categories=True, cmap=["#e9a3a3", "#cfd8e3"],
                show_edges=True, edge_color="grey", line_width=0.3,
                scalar_bar_args={"title": "region (0 film, 1 glass)"})
    pl.add_text(f"film t = {t * 1e9:g} nm on glass, d = {p.d / z0:.1f} z0, displacement x "
                f"{scale:.2g}; um", font_size=9)
    pl.view_xy()
    pl.subplot(0, 1)
    pl.add_mesh(warped, scalars="sigma_zz", cmap="coolwarm", show_edges=False,
                scalar_bar_args={"title": "sigma_zz (Pa)"})
    pl.add_text("sigma_zz: tension at the adhesive rim, compression under the contact",
                font_size=9)
    pl.view_xy()
    RESULTS.mkdir(exist_ok=True)
    pl.screenshot(str(RESULTS / "layered_body.png"))
    pl.close()
    print(f"wrote {OUT / vol} and results/layered_body.png "
          f"(cell data 'region': {sorted(set(np.unique(m['region']).tolist()))})")


if __name__ == "__main__":
    main()
