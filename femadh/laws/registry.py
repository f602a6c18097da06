"""Registration of the laws a scene can name: the scene table that builds them, and the output
columns, signs and legend labels of what they produce.

A new pressure law is one module in ``femadh/laws/`` with a ``REGISTRATION`` (its
``[effects.<table>]`` keys as :class:`femadh.schema.Table`, a ``build`` function and its
:class:`Output` s) and one line in :data:`REGISTRY`; the scene reader, the csv columns, the
summary and the figures follow from it.
"""
from .registration import Built, BuildContext, Output, Registration  # noqa: F401 (the API)


def _registrations():
    from . import asperity, capillary, gw, lj

    return (lj.REGISTRATION, capillary.REGISTRATION, asperity.REGISTRATION, gw.REGISTRATION)


#: effects table name -> Registration (filled on first use; see :func:`registry`)
REGISTRY = {}


def registry():
    """The registrations by table name (``lennard_jones``, ``capillary``, ...)."""
    if not REGISTRY:
        for r in _registrations():
            REGISTRY[r.table.path.split(".", 1)[1]] = r
    return REGISTRY


def outputs():
    """Output by law name, over every registered law (lj, capillary, asperity_adhesion, ...)."""
    out = {}
    for r in registry().values():
        for o in r.outputs:
            out.setdefault(o.name, o)
    return out


def extra_outputs(problem):
    """The registered outputs of the laws a problem carries beyond LJ (and eq 20 on the
    contact set), in registry order."""
    names = set(problem.effects)
    if problem.gap is not None and problem.gap.adhesion:
        names.add("asperity_adhesion")
    return [o for name, o in outputs().items() if name != "lj" and name in names]
