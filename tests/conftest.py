import os

# Small dense solves: threaded BLAS only adds overhead on the CI machine's 2 cores.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
import pytest

from femadh.materials import IsotropicMaterial, composite_modulus

E_STAR = composite_modulus(IsotropicMaterial(163e9, 0.3), IsotropicMaterial(83e9, 0.21))
HAMAKER, Z0 = 1e-19, 0.165e-9


def observed_order(h, err):
    """Slope of log(err) vs log(h): the observed convergence order."""
    return np.polyfit(np.log(h), np.log(err), 1)[0]


@pytest.fixture
def e_star():
    return E_STAR
