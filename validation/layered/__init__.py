"""Coated and layered substrates (issue 16): the layered FE body against the Hankel-transform
reference, its limits and cost, and two physics studies, one module per study over
:mod:`.common` (what they share):

- ``python -m validation.layered.crosscheck``: results/layered_fe.md, FE vs
  :mod:`femadh.reference.layered` on 1-3-layer stacks at three mesh levels with the fitted
  orders, far-field truncation, the radial grading rule, nearly incompressible layers;
- ``python -m validation.layered.slider``: results/layered_slider.md/.png, paper 1's 2-mm glass
  slider on a magnetic disk with a 2-10 nm carbon overcoat against the bare disk;
- ``python -m validation.layered.film``: results/layered_film.md/.png, a 1-um silica tip on a
  soft, nearly incompressible polymer film on glass, 10 nm ... 10 um thick;
- ``python -m validation.layered.render``: results/layered_body.png (VTK in out/layered-vtk),
  the layered body under a contact;
- ``python -m validation.layered.benchmark``: results/layered_benchmark.md, operator build and
  sweep times.

``python -m validation.layered [--part NAME ...]`` runs them in turn (default: all). Every
number in the .md files is recomputed by these scripts.
"""
import os

# one BLAS thread, set before numpy is first imported (the timings assume it)
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
