"""A config file's bytes, read so that no file can hang the reader: a FIFO, a pipe, a device, a huge file.

``open()`` of a FIFO with no writer blocks for ever, and ``rangebearing run``
keeps SIGTERM for itself (it stops the daemon between frames), so a
``--config`` naming one was a process that neither started nor stopped. Here
the file is opened non-blocking (a FIFO without a writer reads as empty); a
pipe, FIFO or device is read until its end, at most ``limit + 1`` bytes, and
for at most :data:`WAIT_S` (``--config /dev/stdin`` fed by ``cat`` works; a
writer that never closes is an error that says so).
"""

from __future__ import annotations

import os
import select
import stat
import time
from pathlib import Path
from typing import Union

WAIT_S = 5.0  # how long a pipe, FIFO or device may take to deliver the whole config


def is_regular(path: Union[str, Path]) -> bool:
    """Whether ``path`` is a regular file (following links); False for what cannot be stat'ed."""
    try:
        return stat.S_ISREG(os.stat(path).st_mode)
    except (OSError, ValueError):
        return False


def read_bounded(path: Union[str, Path], limit: int, wait_s: float = WAIT_S) -> bytes:
    """At most ``limit + 1`` bytes of ``path`` (so that "larger than limit" can be told).

    Raises OSError (TimeoutError for a pipe or device that sends nothing more
    and does not end within ``wait_s``) and ValueError (a NUL in the path), as
    ``open`` would.
    """
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | os.O_CLOEXEC | getattr(os, "O_NOCTTY", 0))
    try:
        if stat.S_ISREG(os.fstat(fd).st_mode):
            with os.fdopen(fd, "rb", closefd=False) as f:
                return f.read(limit + 1)
        return _drain(fd, limit + 1, wait_s)
    finally:
        os.close(fd)


def _drain(fd: int, most: int, wait_s: float) -> bytes:
    chunks, got = [], 0
    deadline = time.monotonic() + wait_s
    while got < most:
        try:
            chunk = os.read(fd, min(65536, most - got))
        except BlockingIOError:  # nothing yet: wait for more, or the end, until the deadline
            left = deadline - time.monotonic()
            if left <= 0 or not select.select([fd], [], [], left)[0]:
                raise TimeoutError(f"nothing more to read within {wait_s:g} s and no end (a pipe or FIFO "
                                   "whose writer never closes it?)") from None
            continue
        if not chunk:  # the end (a FIFO without a writer ends at once)
            break
        chunks.append(chunk)
        got += len(chunk)
    return b"".join(chunks)
