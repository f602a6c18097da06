"""Liquid properties with provenance.

Values at 25 C (298.15 K). Surface tensions: CRC Handbook of Chemistry and Physics, "Surface
tension of common liquids" (Jasper's compilation), interpolated to 25 C. Molar volumes: molar
mass / density at 25 C, densities from the CRC Handbook. Rounded to the digits given; they are
standard handbook data, not values from the papers (paper 1 uses gamma = 0.022 J/m^2 for the
disk lubricant; paper 2 gives no numbers in the text we have).
"""
from dataclasses import dataclass


@dataclass(frozen=True)
class Liquid:
    """A condensable liquid.

    Attributes
    ----------
    name : str
    surface_tension : float
        gamma (N/m).
    molar_volume : float
        V_m (m^3/mol).
    temperature : float
        Temperature the data refer to (K).
    source : str
        Provenance of the numbers.
    """

    name: str
    surface_tension: float
    molar_volume: float
    temperature: float = 298.15
    source: str = "user supplied"

    def __post_init__(self):
        if not self.surface_tension > 0:
            raise ValueError(f"surface_tension must be > 0 N/m, got {self.surface_tension}")
        if not self.molar_volume > 0:
            raise ValueError(f"molar_volume must be > 0 m^3/mol, got {self.molar_volume}")


_CRC = "CRC Handbook of Chemistry and Physics (surface tension, density), 25 C"

LIQUIDS = {
    "water": Liquid("water", 71.97e-3, 18.07e-6, 298.15, _CRC),
    "ethanol": Liquid("ethanol", 21.97e-3, 58.69e-6, 298.15, _CRC),
    "n-butanol": Liquid("n-butanol", 24.2e-3, 91.97e-6, 298.15, _CRC),
    "n-pentanol": Liquid("n-pentanol", 25.4e-3, 108.7e-6, 298.15, _CRC),
}
