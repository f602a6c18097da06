"""The figures of a contact run, drawn into its folder as the run's last phase."""
import time

from ..errors import Interrupted
from .. import interrupt


def draw_figures(res, folder):
    """The run's figures into its folder (:func:`femadh.io.plots.contact_figures`); a signal
    stops them at once (each file is written whole or not at all) and the run ends
    "interrupted" (--resume draws them). Their time goes to ``res.timings["figures_s"]``."""
    from ..io.plots import contact_figures

    t0 = time.perf_counter()
    try:
        with interrupt.immediate():
            contact_figures(res, folder.path)
        res.timings["figures_s"] = time.perf_counter() - t0
    except Interrupted as exc:
        res.stop(exc, " while drawing the figures")
