"""Decoded frames of a looping recording, kept in the page cache rather than in the process.

A looped clip is decoded once (a camera hands over decoded buffers too), but
holding it decoded in the heap made it most of the daemon's resident memory
(60 VGA frames with their YUV420: 79 MiB of 138). Here each decoded frame is
written once to an unlinked temporary file and handed out as a read-only view
of a shared mapping of it. After the caller is done with a frame (its next
read), :meth:`ClipStore.release` drops those pages from the process
(``MADV_DONTNEED``) once the frames handed out since the last drop span
:data:`BATCH_BYTES` (one call for ~6 VGA frames: the call, not the pages, is
most of its cost, ~40 µs a frame): the next use maps them in again from the page cache,
which the kernel may also reclaim and read back from the file. On a tmpfs
temp dir the clip stays in RAM, as shared memory outside the process's RSS
(``TMPDIR`` picks the directory). Dropping pages never changes what a view
holds, so a frame kept longer (a recorder, the view page) stays valid.

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
CHUNK_BYTES = 64 * 1024 * 1024  # mapped at a time (address space, on 32-bit Raspberry Pi OS too)
BATCH_BYTES = 8 * 1024 * 1024  # frames handed out before their pages are dropped: the RSS they may add


class ClipStore:
    """Arrays written once under a key, read back as read-only views of a file mapping.

    The file is mapped in chunks of :data:`CHUNK_BYTES`; a frame's arrays (its
    BGR image, then its YUV420 planes) are written one after the other, so the
    pages a read used are one span and :meth:`release` is one ``madvise`` call.
    """

    def __init__(self, limit_bytes: int = LIMIT_BYTES, chunk_bytes: int = CHUNK_BYTES,
                 batch_bytes: int = BATCH_BYTES) -> None:
        self.limit_bytes = limit_bytes
        self.chunk_bytes = chunk_bytes
        self.batch_bytes = batch_bytes
        self.failed = not CAN_RELEASE
        self._file: Optional[int] = None
        self._chunks: List[mmap.mmap] = []
        self._used = 0  # bytes of the last chunk taken
        self._entries: Dict[Hashable, Tuple[int, int, int, List[np.ndarray]]] = {}  # chunk, start, end, views
        self._spans: Dict[int, Tuple[int, int]] = {}  # chunk -> pages handed out since the last release

    @property
    def nbytes(self) -> int:
        """Bytes of the file taken so far (whole chunks but the last)."""
        return max(0, len(self._chunks) - 1) * self.chunk_bytes + self._used

    def get(self, key: Hashable) -> Optional[List[np.ndarray]]:
        """The arrays stored under ``key`` (the same objects every time), or None."""
        entry = self._entries.get(key)
        if entry is None:
            return None
        self._handed_out(*entry[:3])
        return entry[3]

    def put(self, key: Hashable, arrays: Sequence[np.ndarray]) -> Optional[List[np.ndarray]]:
        """Store ``arrays`` (C-contiguous or not) under ``key``; their read-only views, or None if not kept."""
        if self.failed:
            return None
        spans, size = [], 0
        for a in arrays:  # each array page-aligned within the entry
            spans.append(size)
            size += -(-a.nbytes // mmap.PAGESIZE) * mmap.PAGESIZE
        if size == 0 or size > self.chunk_bytes:
            return None
        new_chunk = not self._chunks or self._used + size > self.chunk_bytes
        if new_chunk and (len(self._chunks) + 1) * self.chunk_bytes > self.limit_bytes:
            return None
        try:
            if self._file is None:
                self._file = _unlinked_temp_file()
            if new_chunk:
                base = len(self._chunks) * self.chunk_bytes
                os.ftruncate(self._file, base + self.chunk_bytes)  # sparse: the disk holds what is written
                self._chunks.append(mmap.mmap(self._file, self.chunk_bytes, access=mmap.ACCESS_READ, offset=base))
                self._used = 0
            at = (len(self._chunks) - 1) * self.chunk_bytes + self._used
            for a, start in zip(arrays, spans):
                data = memoryview(np.ascontiguousarray(a)).cast("B")
                done = 0
                while done < len(data):
                    done += os.pwrite(self._file, data[done:], at + start + done)
        except (OSError, ValueError):  # a full or read-only temp dir, a failed mapping: keep frames in memory
            self.failed = True
            return None
        chunk, mapping, first = len(self._chunks) - 1, self._chunks[-1], self._used
        views = [np.frombuffer(mapping, a.dtype, a.size, first + start).reshape(a.shape)
                 for a, start in zip(arrays, spans)]  # read-only: the mapping is
        self._used += size
        self._entries[key] = (chunk, first, first + size, views)
        self._handed_out(chunk, first, first + size)
        return views

    def _handed_out(self, chunk: int, start: int, end: int) -> None:
        lo, hi = self._spans.get(chunk, (start, end))
        self._spans[chunk] = (min(lo, start), max(hi, end))

    def release(self, now: bool = False) -> None:
        """The caller is done with what it was handed: drop those pages from this process's memory (one span a
        chunk) once they span ``batch_bytes`` since the last drop, or ``now``."""
        if not now and sum(hi - lo for lo, hi in self._spans.values()) < self.batch_bytes:
            return
        for chunk, (lo, hi) in self._spans.items():
            with contextlib.suppress(OSError, ValueError):  # refused: the pages just stay mapped
                self._chunks[chunk].madvise(mmap.MADV_DONTNEED, lo, hi - lo)
        self._spans.clear()

    def close(self) -> None:
        """Forget the entries; views still held elsewhere keep their mapping alive until they go."""
        self._entries.clear()
        self._spans.clear()
        self._chunks = []
        self._used = 0
        if self._file is not None:
            os.close(self._file)
            self._file = None


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
