"""The C allocator, set for an assessment's large short-lived arrays (glibc; elsewhere nothing changes).

An assessment allocates and frees hundreds of MB per VIIRS granule (read, checked, prepared, collocated).
glibc serves every allocation above 32 MB from fresh pages that the kernel zeroes at first touch and takes
back at free, so each granule would pay for zeroing them again, in system time. Served from the heap and not
trimmed at every free, freed memory is reused as it is; :func:`release_freed_memory` hands what is free back
to the system after a job (the daemon then idles until the next day). Reprocessing's Dask workers set it at
each satellite-day (:func:`monitor.service.reprocess.day_task`) and keep the memory between days (their peak:
docs/performance.md): Dask's own setting (MALLOC_TRIM_THRESHOLD_ = 64 KiB) would return it at every free.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import logging
from functools import lru_cache

LOG = logging.getLogger(__name__)

_M_TRIM_THRESHOLD = -1  # mallopt parameters (malloc.h)
_M_MMAP_MAX = -4
_NEVER_TRIM = 2**31 - 1


@lru_cache(maxsize=1)
def _glibc() -> ctypes.CDLL | None:
    """glibc's handle, or None where the C library is another (musl, macOS)."""
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        libc.gnu_get_libc_version.restype = ctypes.c_char_p
        libc.gnu_get_libc_version()
        return libc
    except (OSError, AttributeError):
        return None


def reuse_freed_memory() -> bool:
    """Serve large allocations from the heap and keep what is freed for reuse (process-wide); whether
    it was set (glibc only).

    Returns
    -------
    bool
        Whether it was set (glibc only).
    """
    libc = _glibc()
    if libc is None:
        return False
    ok = libc.mallopt(_M_MMAP_MAX, 0) == 1 and libc.mallopt(_M_TRIM_THRESHOLD, _NEVER_TRIM) == 1
    if not ok:
        LOG.debug("mallopt refused the allocator settings; the defaults stay")
    return ok


def release_freed_memory() -> None:
    """Give the memory freed so far back to the system (after a job)."""
    libc = _glibc()
    if libc is not None:
        libc.malloc_trim(0)
