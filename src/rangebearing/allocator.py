"""Keep the buffers a frame frees in the process heap, so the next frame does not fault them in again.

glibc serves every allocation above its mmap threshold (128 KiB at start, raised
towards the largest block freed since) with fresh pages from the kernel, and trims
the heap's free top back to the kernel past its trim threshold. A frame allocates
and frees dozens of such buffers (a 640×480 BGR frame is 900 KiB, its ½-resolution
HSV copy 225 KiB, the stacked tiles of the band measurement several hundred KiB),
so each frame paid page faults for memory it had just given back: on the
development VM that was a third of a clean full scan's CPU time. Fixing both
thresholds keeps those pages in the heap; the process grows by at most its largest
per-frame working set. Only the daemon and the benchmark call this: it sets a
process-wide policy, which a library must not do on import.
"""

from __future__ import annotations

import ctypes
import sys

M_TRIM_THRESHOLD, M_MMAP_THRESHOLD = -1, -3  # glibc's mallopt parameters (malloc.h)
KEEP_B = 32 * 2**20  # blocks up to this size come from the heap (glibc's own ceiling for the dynamic threshold)


def keep_freed_buffers(keep_b: int = KEEP_B) -> bool:
    """Set glibc's mmap threshold to ``keep_b`` bytes and its trim threshold to twice that.

    Returns whether the C library took both settings: ``False`` off Linux, or with a
    C library without ``mallopt`` (musl's accepts and ignores it). Calling it again is harmless.
    """
    if not sys.platform.startswith("linux"):
        return False
    try:  # the C library the process already runs on; ctypes.util.find_library would run ldconfig (~60 ms)
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):
        return False
    mallopt.argtypes = [ctypes.c_int, ctypes.c_int]
    mallopt.restype = ctypes.c_int
    return mallopt(M_MMAP_THRESHOLD, keep_b) == 1 and mallopt(M_TRIM_THRESHOLD, 2 * keep_b) == 1


def one_worker() -> None:
    """OpenCV's functions in the calling thread only (``cv2.setNumThreads(1)``): the daemon's own policy.

    OpenCV splits a call over a pool of one worker per core; at 640×480 the work is
    too small for that to pay, and waking the workers cost the daemon ~0.07 ms of
    CPU a frame on this 2-core VM (one worker; a Pi 4 has three), ~4 % of its CPU,
    for no frame sooner. Like :func:`keep_freed_buffers` it sets a process-wide
    policy: only the daemon calls it.
    """
    import cv2

    cv2.setNumThreads(1)
