"""What every surface operator shares: w = C p, and the stiffness K = C^-1 on demand."""
import numpy as np
from scipy import linalg


class SurfaceOperator:
    """Base of the Green and FE operators. Subclasses set ``grid`` and ``compliance`` (m/Pa)."""

    _stiffness = None

    @property
    def stiffness(self):
        """K = C^-1 (Pa/m): nodal pressures that hold the surface at given displacements."""
        if self._stiffness is None:
            # the LU solved for the identity's columns (getrs); getri is 10-20 % cheaper but
            # moves K's last bits, and the landings of lattice-trapped runs follow round-off
            # (validation/results/greenop.md)
            lu = linalg.lu_factor(self.compliance, check_finite=False)
            self._stiffness = linalg.lu_solve(lu, np.eye(self.grid.n), check_finite=False)
            if not np.all(np.isfinite(self._stiffness)):
                raise FloatingPointError(f"stiffness K = C^-1 of the {self.grid.n}-node "
                                         "operator is not finite (a singular compliance)")
        return self._stiffness

    def displacement(self, pressure):
        """Nodal displacements w (m) of piecewise-constant pressures (Pa) on the annuli."""
        return self.compliance @ pressure
