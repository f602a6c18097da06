"""What a contact scene's run writes ([output]), with the table of its keys."""
from dataclasses import dataclass

from ...schema import Key, Table

OUTPUT = Table("output", "Outputs.", (
    Key("dir", "string", "Output folder (default out/<scene name>; a relative path is taken "
        "from the current folder, as --out is, not from the scene file's).", default=None),
    Key("vtk", "bool", "VTK volume and surface files of every state as it converges (FE only; "
        "default false: `femadh render RUN_DIR --state K` writes and draws the states you ask "
        "for from fields.csv).", default=None),
))


@dataclass(frozen=True)
class Output:
    """Where and what a run writes.

    Attributes
    ----------
    output_dir : str
        The run's folder (default ``out/<scene name>``).
    vtk : bool
        VTK files of every state (FE only).
    """

    output_dir: str
    vtk: bool = False
