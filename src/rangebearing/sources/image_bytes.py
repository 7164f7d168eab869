"""Recorded frames' bytes decoded with bounds: a hostile file costs a skipped frame, never the process.

OpenCV's ``imdecode`` allocates whatever the header claims (up to 2**30
pixels, 3 GiB of BGR, before it asserts) and raises ``cv2.error`` beyond that:
a 60 KB PNG saying 40000×40000 either ends the command with a traceback or
takes the robot's memory. The size in a PNG, JPEG or BMP header is read first
(a few bytes) and a frame over :data:`MAX_PIXELS` is refused undecoded; any
other failure of the decoder is a frame that does not decode (``None``).

libpng, libjpeg and OpenCV's own loader print their complaints straight to
file descriptor 2 ("libpng error: IDAT: CRC error", "Corrupt JPEG data: 3
extraneous bytes before marker 0xd9", "[ERROR:0@0.02] global loadsave.cpp
... imdecode_"), past Python's logging and interleaved with the replay's own
lines. Decoding captures that descriptor (:func:`_decoder_output`): the
decoder's lines go to the debug log, and the reason a frame is skipped comes
from the bytes themselves (:mod:`.image_damage`: a PNG's chunks and
their CRCs, a JPEG's markers, a BMP's size), in words a user can act on.
"""

from __future__ import annotations

import contextlib
import logging
import os
import re
import struct
import sys
import tempfile
import threading
from typing import IO, Iterator, List, Optional, Tuple, Union

import cv2
import numpy as np

MAX_PIXELS = 1 << 26  # 67 Mpx (8192×8192, 192 MiB as BGR): above the largest Pi camera sensor (64 Mpx)
MAX_FILE_BYTES = 256 << 20  # an uncompressed BMP of MAX_PIXELS is 192 MiB
log = logging.getLogger(__name__)
_JPEG_SOF = {0xC0, 0xC1, 0xC2, 0xC3, 0xC5, 0xC6, 0xC7, 0xC9, 0xCA, 0xCB, 0xCD, 0xCE, 0xCF}


def header_size(data: Union[bytes, memoryview, np.ndarray]) -> Optional[Tuple[int, int]]:
    """``(width, height)`` from a PNG, JPEG or BMP header, or ``None`` (another format, or no header)."""
    head = bytes(data[:64 * 1024]) if not isinstance(data, bytes) else data[:64 * 1024]
    if head.startswith(b"\x89PNG\r\n\x1a\n") and len(head) >= 24 and head[12:16] == b"IHDR":
        w, h = struct.unpack(">II", head[16:24])
        return w, h
    if head.startswith(b"BM") and len(head) >= 26:
        w, h = struct.unpack("<ii", head[18:26])
        return abs(w), abs(h)
    if head.startswith(b"\xff\xd8"):
        return _jpeg_size(head)
    return None


def _jpeg_size(head: bytes) -> Optional[Tuple[int, int]]:
    i = 2
    while i + 9 <= len(head):
        if head[i] != 0xFF:
            return None
        marker = head[i + 1]
        if marker == 0xFF:  # fill byte
            i += 1
            continue
        if marker in (0x01, *range(0xD0, 0xD8)):  # markers without a length
            i += 2
            continue
        (length,) = struct.unpack(">H", head[i + 2:i + 4])
        if marker in _JPEG_SOF:
            h, w = struct.unpack(">HH", head[i + 5:i + 9])
            return w, h
        i += 2 + length
    return None


def too_large(data: Union[bytes, np.ndarray]) -> bool:
    """True when the header claims more than :data:`MAX_PIXELS`."""
    size = header_size(data)
    return size is not None and size[0] * size[1] > MAX_PIXELS


_capture_lock = threading.Lock()
_capture_file: List[Tuple[int, IO[bytes]]] = []  # (pid, file): one scratch file a process, reused
# What the decoders print: libpng's "libpng error/warning: ...", OpenCV's "[ERROR:0@0.02] ..." log lines,
# libjpeg's messages (all but a few name JPEG). Anything else written meanwhile (another thread's logging or
# traceback) is passed on.
_DECODER_LINE = re.compile(r"^(libpng\b|\[\s*(WARN|ERROR|INFO|DEBUG)[:\]]|.*\bJPEG\b)")
_CV_PREFIX = re.compile(r"^\[\s*[A-Z]+:\d+@[\d.]+\]\s+global\s+\S+\s+(?:\S+\s+)?\S+\(''\):\s*")
_CV_WHERE = re.compile(r"OpenCV\([^)]*\)\s+\S+:\d+: error: \([^)]*\)\s*")


def _scratch() -> IO[bytes]:
    pid = os.getpid()
    if not _capture_file or _capture_file[0][0] != pid:  # a forked child gets a file of its own
        _capture_file[:] = [(pid, tempfile.TemporaryFile())]  # noqa: SIM115 (kept open for reuse)
    return _capture_file[0][1]


@contextlib.contextmanager
def _decoder_output() -> Iterator[List[str]]:
    """Capture what C code writes to fd 2 meanwhile; the list holds the decoder's lines afterwards.

    Only the decoders' own lines (:data:`_DECODER_LINE`) are kept: anything
    else written meanwhile (another thread's logging or traceback) goes on to
    the real stderr, so nothing is lost. Without a usable fd 2 (closed) nothing
    is captured.
    """
    lines: List[str] = []
    with _capture_lock:
        try:
            saved = os.dup(2)
        except OSError:
            yield lines
            return
        try:
            scratch = _scratch()
            with contextlib.suppress(Exception):
                sys.stderr.flush()  # Python's pending text goes out before the swap, to the real stderr
            os.dup2(scratch.fileno(), 2)
            try:
                yield lines
            finally:
                os.dup2(saved, 2)
            fd = scratch.fileno()
            size = os.fstat(fd).st_size
            if size:
                os.lseek(fd, 0, os.SEEK_SET)
                with os.fdopen(os.dup(fd), "rb") as f:
                    text = f.read(size).decode("utf-8", "replace")
                os.ftruncate(fd, 0)
                os.lseek(fd, 0, os.SEEK_SET)
                passed = []
                for line in text.splitlines():
                    if _DECODER_LINE.match(line.strip()):
                        lines.append(_tidy(line.strip()))
                    elif line.strip():
                        passed.append(line)
                if passed:
                    with contextlib.suppress(OSError):
                        os.write(saved, ("\n".join(passed) + "\n").encode())
        finally:
            os.close(saved)


def _tidy(line: str) -> str:
    """A decoder's line without OpenCV's log prefix and source location."""
    return _CV_WHERE.sub("", _CV_PREFIX.sub("", line))


def decode_verbose(data: Union[bytes, np.ndarray]) -> Tuple[Optional[np.ndarray], List[str]]:
    """:func:`decode`, and what the decoder printed while it ran (libpng/libjpeg/OpenCV lines)."""
    buf = np.frombuffer(data, np.uint8) if isinstance(data, bytes) else data
    if buf.size == 0 or too_large(buf):
        return None, []
    with _decoder_output() as said:
        try:
            image = cv2.imdecode(buf, cv2.IMREAD_COLOR)
        except cv2.error as exc:  # over OpenCV's own pixel limit, or a decoder's assertion
            image = None
            said.append(_tidy(str(exc).strip().splitlines()[-1] if str(exc).strip() else "cv2.error"))
    if image is None or image.ndim != 3 or image.shape[2] != 3:
        return None, said
    return image, said


def decode(data: Union[bytes, np.ndarray]) -> Optional[np.ndarray]:
    """PNG/JPEG/BMP… bytes as H×W×3 uint8 BGR (16-bit, grey and alpha converted), or ``None``.

    Nothing reaches stderr: what the decoder prints goes to the debug log (a
    JPEG with a few extraneous bytes still decodes, with a warning there).
    """
    image, said = decode_verbose(data)
    if said and log.isEnabledFor(logging.DEBUG):
        log.debug("image decoder: %s", "; ".join(said))
    return image


def decode_file(path: Union[str, os.PathLike[str]]) -> Optional[np.ndarray]:
    """An image file decoded by :func:`decode`; ``None`` also when it cannot be read or is over 256 MiB."""
    try:
        with open(path, "rb") as f:
            if os.fstat(f.fileno()).st_size > MAX_FILE_BYTES:
                return None
            data = f.read(MAX_FILE_BYTES + 1)
    except (OSError, ValueError):  # a directory, a symlink loop, a NUL in the name
        return None
    return None if len(data) > MAX_FILE_BYTES else decode(data)
