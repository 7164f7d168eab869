"""Decoded frames of a looping recording, kept in the page cache rather than in the process.

A looped clip is decoded once (a camera hands over decoded buffers too), but
holding it decoded in the heap made it most of the daemon's resident memory
(60 VGA frames with their YUV420: 79 MiB of 138). Here each decoded frame is
written once to an unlinked temporary file and handed out as a read-only view
of a shared mapping of it. After the caller is done with a frame (its next
read), :meth:`ClipStore.release` drops those pages from the process
(``MADV_DONTNEED``): the next use maps them in again from the page cache,
which the kernel may also reclaim and read back from the file. Dropping pages
never changes what a view holds, so a frame kept longer (a recorder, the view
page) stays valid.

Where the mapping or the temporary file cannot be had (no ``madvise``, a full
or read-only temp dir), :meth:`ClipStore.put` returns None and the caller
keeps its frames in memory as before.
"""

from __future__ import annotations

import contextlib
import mmap
import os
from typing import Dict, Hashable, List, Optional, Sequence, Tuple

import numpy as np

CAN_RELEASE = hasattr(mmap.mmap, "madvise") and hasattr(mmap, "MADV_DONTNEED")
LIMIT_BYTES = 512 * 1024 * 1024  # of temporary file: ~380 VGA frames with their YUV420


class ClipStore:
    """Arrays written once under a key, read back as read-only views of a file mapping."""

    def __init__(self, limit_bytes: int = LIMIT_BYTES) -> None:
        self.limit_bytes = limit_bytes
        self.failed = not CAN_RELEASE
        self._file: Optional[int] = None
        self._end = 0
        self._entries: Dict[Hashable, Tuple[mmap.mmap, List[np.ndarray]]] = {}
        self._mapped: Dict[Hashable, mmap.mmap] = {}  # handed out since the last release

    @property
    def nbytes(self) -> int:
        """Bytes written to the file so far."""
        return self._end

    def get(self, key: Hashable) -> Optional[List[np.ndarray]]:
        """The arrays stored under ``key`` (the same objects every time), or None."""
        entry = self._entries.get(key)
        if entry is None:
            return None
        self._mapped[key] = entry[0]
        return entry[1]

    def put(self, key: Hashable, arrays: Sequence[np.ndarray]) -> Optional[List[np.ndarray]]:
        """Store ``arrays`` (C-contiguous or not) under ``key``; their read-only views, or None if not kept."""
        if self.failed:
            return None
        sizes = [a.nbytes for a in arrays]
        spans, offset = [], 0
        for n in sizes:  # each array page-aligned within the entry
            spans.append(offset)
            offset += -(-n // mmap.PAGESIZE) * mmap.PAGESIZE
        if offset == 0 or self._end + offset > self.limit_bytes:
            return None
        try:
            if self._file is None:
                self._file = _unlinked_temp_file()
            for a, start in zip(arrays, spans):
                data = memoryview(np.ascontiguousarray(a)).cast("B")
                written = 0
                while written < len(data):
                    written += os.pwrite(self._file, data[written:], self._end + start + written)
            os.ftruncate(self._file, self._end + offset)  # the last array's page padding
            mapping = mmap.mmap(self._file, offset, access=mmap.ACCESS_READ, offset=self._end)
        except (OSError, ValueError):  # a full or read-only temp dir, a failed mapping: keep frames in memory
            self.failed = True
            return None
        self._end += offset
        views = [np.frombuffer(mapping, a.dtype, a.size, start).reshape(a.shape)
                 for a, start in zip(arrays, spans)]  # read-only: the mapping is
        self._entries[key] = (mapping, views)
        self._mapped[key] = mapping
        return views

    def release(self) -> None:
        """Drop the pages of every entry handed out since the last call from this process's memory."""
        for mapping in self._mapped.values():
            with contextlib.suppress(OSError, ValueError):  # closed, or refused: the pages just stay mapped
                mapping.madvise(mmap.MADV_DONTNEED)
        self._mapped.clear()

    def close(self) -> None:
        """Forget the entries; views still held elsewhere keep their mapping alive until they go."""
        self._entries.clear()
        self._mapped.clear()
        if self._file is not None:
            os.close(self._file)
            self._file = None
        self._end = 0


def _unlinked_temp_file() -> int:
    """A file descriptor of a new temporary file that has no name (gone with the process, however it ends)."""
    directory = os.environ.get("TMPDIR") or "/tmp"
    if hasattr(os, "O_TMPFILE"):  # Linux: born without a name, and no tempfile import (~3 ms) on start-up's path
        try:
            return os.open(directory, os.O_TMPFILE | os.O_RDWR, 0o600)
        except OSError:  # a file system without O_TMPFILE, or no such directory: tempfile finds another
            pass
    import tempfile

    fd, path = tempfile.mkstemp(prefix="rangebearing-clip-")
    os.unlink(path)
    return fd
