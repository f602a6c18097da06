"""The instrument in series with the contact (AFM cantilever, MEMS suspension): its spring
(:mod:`.spring`) and the force-z curve it records, read off the contact's equilibrium states
(:mod:`.readout`)."""
from .readout import InstrumentPath, read_instrument, stable_pieces
from .spring import Spring, bridge_stiffness, cantilever_stiffness

__all__ = ["InstrumentPath", "Spring", "bridge_stiffness", "cantilever_stiffness",
           "read_instrument", "stable_pieces"]
