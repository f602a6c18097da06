"""A headline number on members of one banded family at many band spacings: the sawtooth (or
the smooth order) an error estimate's members sample.

``python -m validation.effectivity_scan SCENE REQUEST SPACING_NM ...`` runs the scene's
adaptive grid at the request, then solves the reduced member (femadh.runner.members) of the
same family at each band spacing and prints its headline numbers, with the fraction of a
spacing at which the contact edge of the deepest state sits (r_e / h mod 1).
"""
import sys

import femadh
import femadh.runner.estimates as est
from femadh.runner.members import contact_edge, reduced_member

from .accuracy import SCENES, _adaptive, capture

Q = ("max_adhesion_N", "d_at_max_adhesion_m", "F_LJ_deepest_N", "jump_in_d_m", "jump_out_d_m")


def main(argv=None):
    argv = argv or sys.argv[1:]
    name, req, spacings = argv[0], float(argv[1]), [float(x) * 1e-9 for x in argv[2:]]
    base = femadh.load_scene(SCENES / f"{name}.toml")
    res, got = capture(_adaptive(base, req))
    sc, problem, sink, fine = got["scene"], got["problem"], got["sink"], got["res"]
    h0 = float(problem.grid.nodes[1])
    r_e = contact_edge(problem, sink.committed["approach"][-1])
    r_p = contact_edge(problem, sink.peak[3]) if sink.peak is not None else None
    print(f"peak state edge {r_p}")
    print(f"fine: spacing {h0 * 1e9:.4g} nm, deepest edge {r_e}, "
          + ", ".join(f"{q} {fine.headline.get(q)!r}" for q in Q))
    print("estimates:", {q: res.estimates.get(q) for q in Q})
    for h in spacings:
        m = est.variant(sc, grid={**sc.grid, "spacing": h})
        hl, how = reduced_member(sc, m, problem, sink, fine)
        frac = (r_e / h) % 1 if r_e else float("nan")
        frac_p = (r_p / h) % 1 if r_p else float("nan")
        if hl is None:
            print(f"{h * 1e9:8.4g} nm: not reduced ({how})")
            continue
        print(f"{h * 1e9:8.4g} nm  edge frac {frac:.3f} peak edge frac {frac_p:.3f} " + "  ".join(
            f"{q} {hl.get(q, float('nan')):.9g}" for q in Q), flush=True)


if __name__ == "__main__":
    main()
