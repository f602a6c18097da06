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
            # LAPACK getrf + getri: 10-20 % less than solving the LU for the identity's N
            # columns (getrs, 2 N^3 flops) at 860-1720 nodes, K C - I as small (measured
            # 9e-14 against 1.6e-13 at 860 nodes); column-major like the getrs result, the
            # layout the corrector's products and slices were measured with
            self._stiffness = np.asfortranarray(linalg.inv(self.compliance, check_finite=False))
            if not np.all(np.isfinite(self._stiffness)):
                raise FloatingPointError(f"stiffness K = C^-1 of the {self.grid.n}-node "
                                         "operator is not finite (a singular or non-finite "
                                         "compliance)")
        return self._stiffness

    def displacement(self, pressure):
        """Nodal displacements w (m) of piecewise-constant pressures (Pa) on the annuli."""
        return self.compliance @ pressure
