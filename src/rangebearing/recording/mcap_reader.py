"""Read rangebearing MCAP files back: frames for replay, readings, intrinsics.

Records are streamed in file order with the ``mcap`` library's ``StreamReader``,
so a file cut short (the recorder killed, the disk full) yields everything up
to its last complete chunk and then stops, setting :attr:`McapRecording.truncated`,
where an index-based reader would refuse a file without a footer.
"""

from __future__ import annotations

import logging
import os
import struct
from typing import Any, Iterable, Iterator, List, Optional, Tuple, Union

import numpy as np

from .._compat import frozen
from ..core.types import CameraIntrinsics
from ..errors import MissingExtraError, RecordingError
from .mcap_format import (
    CALIBRATION_TOPIC,
    IMAGE_TOPIC,
    READINGS_TOPIC,
    ImageMessage,
    parse_calibration,
    parse_image,
)

PathLike = Union[str, "os.PathLike[str]"]
log = logging.getLogger("rangebearing.recording")
MAGIC = b"\x89MCAP0\r\n"
_WARNED: set = set()  # (path, size, mtime) of damaged files already warned about (_damaged)


def is_mcap(path: PathLike) -> bool:
    """True when ``path`` is a file starting with the MCAP magic bytes (or named ``*.mcap``)."""
    p = os.fspath(path)
    if not os.path.isfile(p):
        return p.lower().endswith(".mcap")
    try:
        with open(p, "rb") as f:
            return f.read(len(MAGIC)) == MAGIC
    except OSError:
        return False


@frozen
class RecordedMessage:
    """One message as stored: its topic, log time (Unix ns), sequence and raw bytes."""

    topic: str
    log_time_ns: int
    sequence: int
    data: bytes


@frozen
class RecordedFrame:
    """One frame from ``/camera/image``: position in the file, source index, capture time, pixels.

    ``image`` is H×W×3 uint8 BGR, or ``None`` when the stored bytes do not decode.
    """

    position: int
    index: int
    t_ns: int
    image: Optional[np.ndarray]
    why: str = ""  # with ``image`` None (decoded): why the message gives no image


def _stream_reader(f: Any) -> Any:
    try:
        from mcap.exceptions import McapError
        from mcap.records import Channel, Message
        from mcap.stream_reader import StreamReader
    except ImportError:
        raise MissingExtraError("mcap", "mcap", "MCAP recordings") from None
    return StreamReader(f), McapError, Channel, Message


def decode_image(img: ImageMessage) -> Optional[np.ndarray]:
    """The stored PNG/JPEG as H×W×3 uint8 BGR, or ``None`` when it does not decode (or claims too many pixels)."""
    from ..sources.image_bytes import decode

    return decode(img.data)


def why_image_undecodable(img: Union[ImageMessage, str]) -> str:
    """Why an image message gives no image: the message is not one (``img`` is then that reason), or its bytes."""
    from ..sources.image_damage import why_bytes_undecodable

    if isinstance(img, str):
        return img
    return f"its {img.fmt or 'unnamed'} data: {why_bytes_undecodable(img.data)}"


def _damaged(path: str, offset: int, exc: BaseException) -> None:
    """Say once per file (a looping replay reads it again and again) where its readable part ends."""
    try:
        key = (path, os.stat(path).st_size, os.stat(path).st_mtime_ns)
    except OSError:
        key = (path, -1, -1)
    if key in _WARNED:
        return
    _WARNED.add(key)
    what = str(exc).splitlines()[0][:120] if str(exc) else type(exc).__name__
    log.warning("%s: cut short or damaged near byte %d (%s): nothing after it can be read", path, offset, what)



class McapRecording:
    """A recording on disk; every iteration reads the file afresh from the start."""

    def __init__(self, path: PathLike) -> None:
        self.path = os.fspath(path)
        self.truncated = False
        try:
            with open(self.path, "rb") as f:
                magic = f.read(len(MAGIC))
        except OSError as exc:
            raise RecordingError(f"{self.path}: cannot read: {exc.strerror or exc}") from None
        if magic != MAGIC:
            raise RecordingError(f"{self.path}: not an MCAP file (no MCAP magic)")

    def messages(self, topics: Optional[Iterable[str]] = None) -> Iterator[RecordedMessage]:
        """Every message on ``topics`` (all when None), in file order, up to the last complete chunk."""
        wanted = None if topics is None else set(topics)
        self.truncated = False
        with open(self.path, "rb") as f:
            reader, mcap_error, channel_type, message_type = _stream_reader(f)
            channels = {}
            records = reader.records
            while True:
                try:
                    record = next(records)
                except StopIteration:
                    return
                except (mcap_error, struct.error, ValueError, EOFError, MemoryError, OverflowError) as exc:
                    self.truncated = True  # the rest of the file is cut short or damaged
                    _damaged(self.path, f.tell(), exc)
                    return
                if isinstance(record, channel_type):
                    channels[record.id] = record.topic
                elif isinstance(record, message_type):
                    topic = channels.get(record.channel_id)
                    if topic is not None and (wanted is None or topic in wanted):
                        yield RecordedMessage(topic, record.log_time, record.sequence, bytes(record.data))

    def images(self) -> Iterator[Tuple[int, int, Union[ImageMessage, str]]]:
        """``(position, source index, image message)`` per frame, not decoded (a ``str``: why it is not an image)."""
        for pos, msg in enumerate(self.messages([IMAGE_TOPIC])):
            try:
                yield pos, msg.sequence, parse_image(msg.data)
            except RecordingError as exc:
                yield pos, msg.sequence, f"the message on {IMAGE_TOPIC} is {exc}"

    def frames(self, decode: bool = True) -> Iterator[RecordedFrame]:
        """The frames in file order; ``decode=False`` leaves ``image`` None (timestamps only)."""
        for pos, index, img in self.images():
            if isinstance(img, str):
                yield RecordedFrame(pos, index, 0, None, img)
                continue
            image = decode_image(img) if decode else None
            why = why_image_undecodable(img) if decode and image is None else ""
            yield RecordedFrame(pos, index, img.t_ns, image, why)

    def frame_times_ns(self) -> List[int]:
        """The capture time of every frame, by position in the file."""
        return [f.t_ns for f in self.frames(decode=False)]

    def readings(self) -> Iterator[RecordedMessage]:
        """The v1 readings exactly as published (decode them with ``net.decode_reading``)."""
        return self.messages([READINGS_TOPIC])

    def calibration(self) -> Optional[CameraIntrinsics]:
        """The first ``/camera/calibration`` message's intrinsics, or ``None``."""
        for msg in self.messages([CALIBRATION_TOPIC]):
            return parse_calibration(msg.data)
        return None
