"""femadh: finite-element adhesion of a sphere on a flat (MEMS/NEMS stiction)."""
__version__ = "0.1.0"
