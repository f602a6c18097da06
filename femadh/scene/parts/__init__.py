"""A contact scene's parts, each a frozen dataclass beside the tables of its keys:

=================  ==========================================  =================================
part               tables                                      module
=================  ==========================================  =================================
``Body``           [sphere], [materials], [substrate]           :mod:`.body`
``Laws``           [effects.*]                                  :mod:`.laws` (+ the law registry)
``Discretisation`` [solver], [solver.grid], [solver.mesh]       :mod:`.discretisation`
``Sweep``          [sweep], [instrument]                        :mod:`.sweep`
``Output``         [output]                                     :mod:`.output`
=================  ==========================================  =================================

The surface operator is built from the body and the discretisation alone
(:func:`femadh.scene.build.operator_from_parts`); :func:`content_hash` of that pair is the key
under which a study's worker reuses it.
"""
from .body import Body
from .discretisation import Discretisation
from .frozen import FrozenMap, content_hash
from .laws import Laws
from .output import Output
from .sweep import Sweep

__all__ = ["Body", "Laws", "Discretisation", "Sweep", "Output", "FrozenMap", "content_hash"]
