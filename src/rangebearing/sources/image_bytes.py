"""Recorded frames' bytes decoded with bounds: a hostile file costs a skipped frame, never the process.

OpenCV's ``imdecode`` allocates whatever the header claims (up to 2**30
pixels, 3 GiB of BGR, before it asserts) and raises ``cv2.error`` beyond that:
a 60 KB PNG saying 40000×40000 either ends the command with a traceback or
takes the robot's memory. The size in a PNG, JPEG or BMP header is read first
(a few bytes) and a frame over :data:`MAX_PIXELS` is refused undecoded; any
other failure of the decoder is a frame that does not decode (``None``).
"""

from __future__ import annotations

import os
import struct
from typing import Optional, Tuple, Union

import cv2
import numpy as np

MAX_PIXELS = 1 << 26  # 67 Mpx (8192×8192, 192 MiB as BGR): above the largest Pi camera sensor (64 Mpx)
MAX_FILE_BYTES = 256 << 20  # an uncompressed BMP of MAX_PIXELS is 192 MiB
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


def decode(data: Union[bytes, np.ndarray]) -> Optional[np.ndarray]:
    """PNG/JPEG/BMP… bytes as H×W×3 uint8 BGR (16-bit, grey and alpha converted), or ``None``."""
    buf = np.frombuffer(data, np.uint8) if isinstance(data, bytes) else data
    if buf.size == 0 or too_large(buf):
        return None
    try:
        image = cv2.imdecode(buf, cv2.IMREAD_COLOR)
    except cv2.error:  # over OpenCV's own pixel limit, or a decoder's assertion
        return None
    if image is None or image.ndim != 3 or image.shape[2] != 3:
        return None
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
    except OSError as exc:
        return exc.strerror or type(exc).__name__
    except ValueError as exc:  # a NUL in the name
        return str(exc)
    if size == 0:
        return "an empty file (0 bytes)"
    if size > MAX_FILE_BYTES:
        return f"{size} bytes, over the {MAX_FILE_BYTES >> 20} MiB an image file may take"
    claimed = header_size(head)
    if claimed is not None and claimed[0] * claimed[1] > MAX_PIXELS:
        w, h = claimed
        return f"its header says {w}×{h} = {w * h} px, over the {MAX_PIXELS} px (8192×8192) a frame may have"
    if claimed is not None and 0 in claimed:
        return f"its header says {claimed[0]}×{claimed[1]}: no pixels"
    if claimed is None and not head.startswith((b"\x89PNG", b"BM", b"\xff\xd8")):
        return "not an image (no PNG, JPEG or BMP header)"
    return "corrupt or truncated: the decoder gives no image"
