"""What a law module declares to be nameable in a scene: its outputs (csv columns, signs,
legend labels), what its table builds, and its registration. The law modules import this
base module; :mod:`femadh.laws.registry` imports the law modules (no cycle)."""
from dataclasses import dataclass, field


@dataclass(frozen=True)
class Output:
    """What one law (by its name in ``ContactProblem.effects``) contributes to the outputs.

    Attributes
    ----------
    name : str
        Key of the law in the problem's effects (and of its pressure in a State).
    force : str
        curve.csv column of its force (N).
    field : str
        fields.csv column of its pressure (Pa, attractive positive as the law returns it).
    sign : float
        +1 if the force is reported attractive positive, -1 for a repulsive law reported as a
        positive (repulsive) force.
    label : str
        Legend label.
    """

    name: str
    force: str
    field: str
    sign: float
    label: str


@dataclass(frozen=True)
class Built:
    """What a law table builds: laws by name, and (eq 20 on the contact set) an adhesive
    pressure carried by the sigma-gap constraint instead of a law."""

    laws: dict = field(default_factory=dict)
    gap_adhesion: float = 0.0


@dataclass(frozen=True)
class Registration:
    """One ``[effects.<table>]`` of a scene.

    Attributes
    ----------
    table : femadh.schema.Table
        Its keys (path ``effects.<name>``).
    build : callable
        ``build(values, ctx) -> Built``: ``values`` the table's values in SI, ``ctx`` a
        :class:`BuildContext`.
    outputs : tuple of Output
    """

    table: object
    build: object
    outputs: tuple


@dataclass(frozen=True)
class BuildContext:
    """What a law may need from the rest of the scene: the composite modulus E* (Pa) and the
    sigma-gap's sigma (m, None without one)."""

    e_star: float
    sigma: float | None
