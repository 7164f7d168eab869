"""Write frames, readings and intrinsics into one MCAP file (synchronous; see ``background``).

Chunks are small (``chunk_bytes``) and finished at least every ``flush_interval_s``
and the file is unbuffered, so a process killed mid-write leaves every finished
chunk on disk: the reader recovers them (see :mod:`.mcap_reader`).
No chunk compression: PNG and JPEG are compressed already, and readings are tiny.
"""

from __future__ import annotations

import contextlib
import os
import stat
import time
from typing import IO, Any, Callable, Dict, Optional, Union

import cv2
import numpy as np

from ..core.types import CameraIntrinsics
from ..errors import FrameError, MissingExtraError, RecordingError
from .mcap_format import (
    CALIBRATION_TOPIC,
    FORMATS,
    IMAGE_TOPIC,
    PROFILE,
    READINGS_TOPIC,
    SCHEMAS,
    calibration_message,
    image_message,
    schema_bytes,
)

PathLike = Union[str, "os.PathLike[str]"]
LIBRARY = "rangebearing"


def import_mcap_writer() -> Any:
    """The ``mcap.writer`` module, or :class:`MissingExtraError` naming the extra."""
    try:
        from mcap import writer
    except ImportError:
        raise MissingExtraError("mcap", "mcap", "MCAP recordings") from None
    return writer


def encode_image(image: np.ndarray, fmt: str = "png", jpeg_quality: int = 90) -> bytes:
    """BGR uint8 pixels as PNG (lossless) or JPEG bytes; :class:`FrameError` if OpenCV cannot."""
    if fmt not in FORMATS:
        raise FrameError(f"image format {fmt!r} is not one of {', '.join(FORMATS)}")
    params = [cv2.IMWRITE_JPEG_QUALITY, int(jpeg_quality)] if fmt == "jpeg" else [cv2.IMWRITE_PNG_COMPRESSION, 1]
    ok, buf = cv2.imencode(".png" if fmt == "png" else ".jpg", image, params)
    if not ok:
        raise FrameError(f"OpenCV cannot encode a {image.shape} {image.dtype} image as {fmt}")
    return buf.tobytes()


class _Unbuffered:
    """The file as the ``mcap`` writer sees it: every write goes to the OS at once.

    (The writer wraps a raw file in its own ``BufferedWriter``, whose tail a
    killed process would lose; this object is not a ``RawIOBase``, so it does not.)
    """

    def __init__(self, raw: IO[bytes]) -> None:
        self.raw = raw
        self.count = 0

    def write(self, data: bytes) -> int:
        view = memoryview(data)
        while view:
            n = self.raw.write(view)
            view = view[n or 0:]
        self.count += len(data)
        return len(data)

    def tell(self) -> int:
        return self.count

    def flush(self) -> None:
        """Nothing to flush: nothing is buffered here."""

    def close(self) -> None:
        self.raw.close()


class McapRecorder:
    """An open MCAP file with the three rangebearing channels.

    Parameters
    ----------
    path : str or path-like
        File to create (replaced if it exists).
    image_format : {"png", "jpeg"}
        How frames are stored; PNG is bit-exact.
    """

    def __init__(
        self,
        path: PathLike,
        image_format: str = "png",
        jpeg_quality: int = 90,
        chunk_bytes: int = 256 * 1024,
        flush_interval_s: float = 1.0,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        if image_format not in FORMATS:
            raise RecordingError(f"image format {image_format!r} is not one of {', '.join(FORMATS)}")
        writer_mod = import_mcap_writer()
        self.path = os.fspath(path)
        self.image_format = image_format
        self.jpeg_quality = jpeg_quality
        self.frames = 0
        self.readings = 0
        self._clock = clock
        self._flush_s = flush_interval_s
        self._last_flush = clock()
        self._pending = 0
        try:
            mode = os.stat(self.path).st_mode
        except OSError:  # not there yet: created below (or open() words the problem)
            mode = 0
        if stat.S_ISFIFO(mode) or stat.S_ISSOCK(mode):
            raise RecordingError(f"{self.path}: a FIFO or socket, not a file to record into "
                                 "(opening it would wait for a reader for ever)")
        try:
            self._file: Optional[_Unbuffered] = _Unbuffered(open(self.path, "wb", buffering=0))  # noqa: SIM115
        except OSError as exc:
            raise RecordingError(f"{self.path}: cannot create: {exc.strerror or exc}") from None
        try:
            self._writer = writer_mod.Writer(
                self._file, chunk_size=chunk_bytes, compression=writer_mod.CompressionType.NONE)
            self._writer.start(profile=PROFILE, library=LIBRARY)
            self._channels: Dict[str, int] = {}
            for topic, (name, file_name) in SCHEMAS.items():
                schema_id = self._writer.register_schema(name, "jsonschema", schema_bytes(file_name))
                self._channels[topic] = self._writer.register_channel(topic, "json", schema_id)
        except OSError as exc:
            self._abandon()
            with contextlib.suppress(OSError):  # ours ("wb"), and not even a header in it: not left behind
                os.unlink(self.path)
            raise RecordingError(f"{self.path}: cannot write: {exc.strerror or exc}") from None

    @property
    def bytes_written(self) -> int:
        """Bytes on disk so far (the chunk being built is not counted)."""
        return 0 if self._file is None else self._file.count

    @property
    def size_bytes(self) -> int:
        """About what the file will hold once the chunk being built is written."""
        return self.bytes_written + self._pending

    def _add(self, topic: str, t_ns: int, data: bytes, sequence: int = 0) -> None:
        if self._file is None:
            raise RecordingError(f"{self.path}: recording is closed")
        on_disk = self._file.count
        self._writer.add_message(self._channels[topic], log_time=int(t_ns), data=data,
                                 publish_time=time.time_ns(), sequence=sequence)
        now = self._clock()
        if now - self._last_flush >= self._flush_s:
            self._writer.flush()
            self._last_flush = now
        # A message record costs its data plus 31 bytes of header and index.
        self._pending = 0 if self._file.count != on_disk else self._pending + len(data) + 31

    def write_image(self, image: np.ndarray, t_ns: int, index: int) -> int:
        """Encode and add one frame captured at ``t_ns`` (Unix ns); returns the message size."""
        data = image_message(encode_image(image, self.image_format, self.jpeg_quality),
                             self.image_format, t_ns)
        self.write_encoded_image(data, t_ns, index)
        return len(data)

    def write_encoded_image(self, message: bytes, t_ns: int, index: int) -> None:
        """Add a ready ``foxglove.CompressedImage`` message (encoded off the caller's thread)."""
        self._add(IMAGE_TOPIC, t_ns, message, sequence=index & 0xFFFFFFFF)
        self.frames += 1

    def write_reading(self, payload: bytes, t_ns: int) -> None:
        """Add one v1 reading, exactly the bytes that were published."""
        self._add(READINGS_TOPIC, t_ns, payload)
        self.readings += 1

    def write_calibration(self, camera: CameraIntrinsics, t_ns: int) -> None:
        """Add the camera intrinsics (once at the start is enough)."""
        self._add(CALIBRATION_TOPIC, t_ns, calibration_message(camera, t_ns))

    def _abandon(self) -> None:
        f, self._file = self._file, None
        if f is not None:
            with contextlib.suppress(OSError):
                f.close()

    def close(self) -> None:
        """Write the summary and footer and close the file. Safe to call twice."""
        if self._file is None:
            return
        try:
            self._writer.finish()
        except OSError as exc:
            raise RecordingError(f"{self.path}: cannot finish: {exc.strerror or exc}") from None
        finally:
            self._abandon()

    def __enter__(self) -> McapRecorder:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
