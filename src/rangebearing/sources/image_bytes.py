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
from the bytes themselves (:func:`why_bytes_undecodable`: a PNG's chunks and
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
import zlib
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
_OUR_LOG_LINE = re.compile(r"^\d{4}-\d\d-\d\d \d\d:\d\d:\d\d")  # another thread's logging: not the decoder's
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

    Lines that look like Python logging (another thread writing while a frame
    decodes) are written on to the real stderr. Without a usable fd 2 (closed)
    nothing is captured.
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
                text = os.read(fd, min(size, 1 << 16)).decode("utf-8", "replace")
                os.ftruncate(fd, 0)
                os.lseek(fd, 0, os.SEEK_SET)
                passed = []
                for line in text.splitlines():
                    if _OUR_LOG_LINE.match(line):
                        passed.append(line)
                    elif line.strip():
                        lines.append(_tidy(line.strip()))
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


def why_undecodable(path: Union[str, os.PathLike[str]]) -> str:
    """Why :func:`decode_file` gives ``None`` for ``path``, in a few words (called only once it has)."""
    try:
        with open(path, "rb") as f:
            size = os.fstat(f.fileno()).st_size
            head = f.read(64 * 1024)
            if 0 < size <= MAX_FILE_BYTES and head.startswith((b"\x89PNG", b"BM", b"\xff\xd8")):
                head += f.read(MAX_FILE_BYTES)  # the structure walk reads it all (a PNG's CRCs, a JPEG's end)
    except OSError as exc:
        return exc.strerror or type(exc).__name__
    except ValueError as exc:  # a NUL in the name
        return str(exc)
    if size == 0:
        return "an empty file (0 bytes)"
    if size > MAX_FILE_BYTES:
        return f"{size} bytes, over the {MAX_FILE_BYTES >> 20} MiB an image file may take"
    return why_bytes_undecodable(head)


def why_bytes_undecodable(data: Union[bytes, memoryview, np.ndarray]) -> str:
    """Why :func:`decode` gives ``None`` for these bytes: the header, then the file's structure, then the decoder."""
    data = data if isinstance(data, bytes) else bytes(data)
    if not data:
        return "no bytes (an empty image)"
    if data.startswith(b"\x89PNG") and len(data) >= 33 and data[12:16] == b"IHDR" and \
            zlib.crc32(data[12:29]) != struct.unpack(">I", data[29:33])[0]:
        return "corrupt: the PNG's IHDR chunk at byte 8 fails its CRC check (its size and depth are not to be trusted)"
    claimed = header_size(data)
    if claimed is not None and claimed[0] * claimed[1] > MAX_PIXELS:
        w, h = claimed
        return f"its header says {w}×{h} = {w * h} px, over the {MAX_PIXELS} px (8192×8192) a frame may have"
    if claimed is not None and 0 in claimed:
        return f"its header says {claimed[0]}×{claimed[1]}: no pixels"
    if claimed is None and not data.startswith((b"\x89PNG", b"BM", b"\xff\xd8")):
        return "not an image (no PNG, JPEG or BMP header)"
    problem = (_png_problem(data) if data.startswith(b"\x89PNG") else
               _jpeg_problem(data) if data.startswith(b"\xff\xd8") else _bmp_problem(data))
    if problem is not None:
        return problem
    image, said = decode_verbose(data)
    if image is not None:
        return "it decodes (read again, it was changed meanwhile?)"
    if said:
        return "corrupt: the decoder says " + "; ".join(dict.fromkeys(said))[:300]
    return "corrupt or truncated: the decoder gives no image"


def _png_problem(data: bytes) -> Optional[str]:
    """What is wrong with a PNG's chunks (order, length, CRC, the IEND that ends it), or ``None``."""
    n, i, last, pixels = len(data), 8, "", False
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        return "corrupt: a damaged PNG signature (the file went through a text-mode copy?)"
    while True:
        if i == n:
            return f"truncated: the PNG ends after its {last or 'signature'} at byte {n}, with no IEND chunk"
        if i + 8 > n:
            return f"truncated: the PNG is cut short in a chunk header at byte {i} of {n}"
        length, kind = struct.unpack(">I4s", data[i:i + 8])
        name = kind.decode("latin-1")
        if not kind.isalpha():
            return f"corrupt: the PNG chunk at byte {i} has no valid type ({kind!r})"
        if length > 0x7FFFFFFF:
            return f"corrupt: the PNG's {name} chunk at byte {i} claims {length} bytes"
        if not last and kind != b"IHDR":
            return f"corrupt: the PNG starts with a {name} chunk, not IHDR"
        end = i + 12 + length
        if end > n:
            return f"truncated: the PNG is cut short in its {name} chunk ({n} bytes of the {end} it needs)"
        if zlib.crc32(data[i + 4:end - 4]) != struct.unpack(">I", data[end - 4:end])[0]:
            return f"corrupt: the PNG's {name} chunk at byte {i} fails its CRC check"
        if kind == b"IEND":
            return None if pixels else "corrupt: the PNG has no IDAT chunk (no pixel data)"
        pixels = pixels or kind == b"IDAT"
        last, i = f"{name} chunk", end


def _jpeg_problem(data: bytes) -> Optional[str]:
    """What is wrong with a JPEG's markers up to its scan, and whether it reaches end-of-image, or ``None``."""
    n, i, frame = len(data), 2, False
    while True:
        if i + 4 > n:
            return f"truncated: the JPEG is cut short in its headers at byte {n}"
        if data[i] != 0xFF:
            return f"corrupt: the JPEG has no marker where one belongs (byte {i})"
        marker = data[i + 1]
        if marker == 0xFF:
            i += 1
            continue
        if marker == 0xD9:
            return "corrupt: the JPEG ends before any image data"
        if marker in (0x01, *range(0xD0, 0xD8)):
            i += 2
            continue
        (length,) = struct.unpack(">H", data[i + 2:i + 4])
        if i + 2 + length > n:
            return f"truncated: the JPEG is cut short in its headers ({n} bytes of the {i + 2 + length} they need)"
        frame = frame or marker in _JPEG_SOF
        if marker == 0xDA:  # start of scan: the entropy-coded data follows up to EOI
            if not frame:
                return "corrupt: the JPEG's scan comes before any frame header (SOF)"
            if data.rfind(b"\xff\xd9", i) < 0:
                return f"truncated: the JPEG's image data is cut short at byte {n} (no end-of-image marker)"
            return None
        i += 2 + length


def _bmp_problem(data: bytes) -> Optional[str]:
    """A BMP shorter than its header's pixel array, or ``None``."""
    if len(data) < 30:
        return f"truncated: the BMP is cut short in its header ({len(data)} bytes)"
    offset = struct.unpack("<I", data[10:14])[0]
    w, h = struct.unpack("<ii", data[18:26])
    bits = struct.unpack("<H", data[28:30])[0]
    compression = struct.unpack("<I", data[30:34])[0] if len(data) >= 34 else 0
    if compression == 0 and bits in (1, 4, 8, 16, 24, 32):
        need = offset + ((abs(w) * bits + 31) // 32) * 4 * abs(h)
        if len(data) < need:
            return f"truncated: the BMP has {len(data)} of the {need} bytes its header says"
    return None
