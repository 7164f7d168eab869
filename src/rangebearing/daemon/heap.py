"""Keep freed memory in the process heap, so a frame's buffers are not page-faulted in anew each frame.

glibc's ``malloc`` serves large requests (from 128 KiB, a threshold it then
raises as such blocks are freed) with their own ``mmap`` and gives heap tops
above 128 KiB back to the kernel. Every frame allocates and frees the same
few hundred KiB of arrays (masks, crops, planes), so by default each frame
faulted ~60 fresh zeroed pages in (measured: 59 minor faults a frame at 30
fps, 640×480, one landmark; 1 with the thresholds below, and ~14 % less CPU).
Fixed thresholds keep those blocks in the heap: the daemon's RSS is its
steady working set either way.
"""

from __future__ import annotations

import ctypes
import logging

log = logging.getLogger("rangebearing.daemon")

M_TRIM_THRESHOLD = -1  # glibc malloc.h
M_MMAP_THRESHOLD = -3
MMAP_THRESHOLD_B = 16 * 1024 * 1024  # blocks below this come from the heap (a 1280×720 BGR frame is 2.7 MB)
TRIM_THRESHOLD_B = 128 * 1024 * 1024  # free heap top kept up to this


def keep_heap(mmap_threshold_b: int = MMAP_THRESHOLD_B, trim_threshold_b: int = TRIM_THRESHOLD_B) -> bool:
    """Set glibc's mmap and trim thresholds (``mallopt``); False where the C library has no ``mallopt``."""
    try:
        mallopt = ctypes.CDLL(None).mallopt  # the C library the process runs on (no ctypes.util: start-up time)
    except (OSError, AttributeError):  # not glibc (musl, macOS): nothing to tune
        return False
    mallopt.argtypes, mallopt.restype = [ctypes.c_int, ctypes.c_int], ctypes.c_int
    ok = mallopt(M_MMAP_THRESHOLD, mmap_threshold_b) == 1 and mallopt(M_TRIM_THRESHOLD, trim_threshold_b) == 1
    if not ok:
        log.debug("mallopt refused the heap thresholds; keeping the C library's defaults")
    return ok
