"""femadh's dense linear algebra is many small solves: threaded BLAS only adds overhead and,
with anything else running on the machine, makes them 3-18x slower (measured on 2 cores).
femadh therefore runs its solves with one BLAS/OpenMP thread, unless the user has chosen
(OPENBLAS_NUM_THREADS, OMP_NUM_THREADS, MKL_NUM_THREADS or FEMADH_THREADS set)."""
from contextlib import contextmanager, nullcontext
import os

_USER_VARS = ("FEMADH_THREADS", "OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")


def blas_threads():
    """A context manager: one BLAS thread for the block, or the user's choice."""
    if os.environ.get("FEMADH_THREADS"):
        return _limit(int(os.environ["FEMADH_THREADS"]))
    if any(os.environ.get(v) for v in _USER_VARS[1:]):
        return nullcontext()
    return _limit(1)


@contextmanager
def _limit(n):
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=n):
        yield
