"""Why recorded image bytes give no frame, in words a user can act on.

The header first (a size over :data:`~.image_bytes.MAX_PIXELS`, no pixels, not
an image at all), then the file's own structure (a PNG's chunks with their
CRCs and the IEND that ends it, a JPEG's markers up to its scan and its
end-of-image marker, a BMP's pixel array against its size), then what the
decoder itself printed. Called only for a frame that did not decode.
"""

from __future__ import annotations

import os
import struct
import zlib
from typing import Optional, Union

import numpy as np

from .image_bytes import _JPEG_SOF, MAX_FILE_BYTES, MAX_PIXELS, decode_verbose, header_size


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
