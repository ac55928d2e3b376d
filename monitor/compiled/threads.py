"""numba's worker threads, shared by every compiled kernel: the lock each parallel launch takes, and how
many threads the kernels use.

numba's default (workqueue) threading layer runs one parallel region at a time in a process, and the
daemon may assess two satellites in two threads: every parallel kernel launch takes KERNEL_LOCK (with the
OpenMP or TBB layers it costs nothing).
"""

from __future__ import annotations

import threading
from collections.abc import Iterator
from contextlib import contextmanager

import numba

KERNEL_LOCK = threading.Lock()


@contextmanager
def parallel_threads(workers: int) -> Iterator[None]:
    """Run the compiled kernels on a number of threads in this block.

    Parameters
    ----------
    workers : int
        Threads, at most numba's pool.

    Returns
    -------
    iterator
        A context manager's one value, None.
    """
    previous = numba.get_num_threads()
    numba.set_num_threads(max(1, min(workers, numba.config.NUMBA_NUM_THREADS)))
    try:
        yield
    finally:
        numba.set_num_threads(previous)
