"""CompletedRequest and MappedArray (picamera2/request.py): buffers shared with the camera until released."""

from __future__ import annotations

from typing import Any, Optional

import numpy as np

from . import formats


class LibcameraRequest:
    """One libcamera request: a buffer per stream (flat uint8, `framesize` bytes) and the frame's metadata."""

    def __init__(self, buffers: dict[str, np.ndarray]) -> None:
        self.buffers = buffers
        self.metadata: dict[str, Any] = {}


def make_array_shared(buffer: np.ndarray, config: dict[str, Any]) -> np.ndarray:
    """A 2-D/3-D view of a flat buffer, padding sliced off, never a copy (request.py:290-335)."""
    fmt = config["format"]
    w, h = config["size"]
    stride = config["stride"]
    if fmt in ("BGR888", "RGB888", "XBGR8888", "XRGB8888"):
        channels = 3 if fmt in ("BGR888", "RGB888") else 4
        array = buffer
        if stride != w * channels:
            array = array.reshape((h, stride))[:, : w * channels]
        return array.reshape((h, w, channels))
    if fmt in ("YUV420", "YVU420"):
        # request.py:316-321: "an image of 50% greater height", padding left in.
        return buffer.reshape((h * 3 // 2, stride))
    if formats.is_raw(fmt):
        return buffer.reshape((h, stride))
    raise RuntimeError("Format " + fmt + " not supported")


class MappedArray:
    """Context manager: `.array` is the stream's buffer in place (request.py:53-89)."""

    def __init__(self, request: CompletedRequest, stream: str, reshape: bool = True, write: bool = True) -> None:
        self.__request = request
        self.__stream = stream
        self.__reshape = reshape
        self.__write = write
        self.__array: Optional[np.ndarray] = None
        if request.request is None:  # _MappedBuffer asserts request.request is not None (request.py:34)
            raise AssertionError("request already released")

    def __enter__(self) -> MappedArray:
        request = self.__request
        if request.request is None:
            raise AssertionError("request already released")
        buffer = request.request.buffers.get(self.__stream)
        if buffer is None:  # the real one fails looking the stream up in stream_map (request.py:32)
            raise KeyError(self.__stream)
        array = make_array_shared(buffer, request.config[self.__stream]) if self.__reshape else buffer
        if not self.__write:  # _MappedBuffer: allocator.sync(..., write) maps PROT_READ only: a read-only array
            array = array.view()
            array.setflags(write=False)
        self.__array = array
        return self

    def __exit__(self, *exc: Any) -> None:
        self.__array = None

    @property
    def array(self) -> Optional[np.ndarray]:
        return self.__array


class CompletedRequest:
    """A completed frame the caller holds until release() (request.py:92-190)."""

    def __init__(self, request: LibcameraRequest, picam2: Any) -> None:
        self.request: Optional[LibcameraRequest] = request
        self.ref_count = 1
        self.lock = picam2.request_lock
        self.picam2 = picam2
        self.stop_count = picam2.stop_count
        self.configure_count = picam2.configure_count
        self.config = picam2.camera_config.copy()
        self.stream_map = picam2.stream_map.copy()

    def acquire(self) -> None:
        """One more reference (request.py:106-111)."""
        with self.lock:
            if self.ref_count == 0:
                raise RuntimeError("CompletedRequest: acquiring lock with ref_count 0")
            self.ref_count += 1

    def release(self) -> None:
        """Give the buffers back; the camera reuses them only if it was not stopped since (request.py:113-150)."""
        with self.lock:
            self.ref_count -= 1
            if self.ref_count < 0:
                raise RuntimeError("CompletedRequest: lock now has negative ref_count")
            if self.ref_count == 0:
                picam2 = self.picam2
                if picam2.camera is not None and self.stop_count == picam2.stop_count and picam2.started:
                    picam2._queue_request(self.request)
                self.request = None
                self.config = {}
                self.stream_map = {}

    def make_buffer(self, name: str) -> np.ndarray:
        """The stream's bytes, 1-D copy (request.py:152-158)."""
        if self.stream_map.get(name) is None:
            raise RuntimeError(f"Stream {name!r} is not defined")
        return np.array(self.request.buffers[name], dtype=np.uint8)

    def get_metadata(self) -> dict[str, Any]:
        """The frame's metadata (request.py:161-167); asserts the request is not released."""
        if self.request is None:
            raise AssertionError("request already released")
        return dict(self.request.metadata)

    def make_array(self, name: str) -> np.ndarray:
        """A contiguous copy of the stream (request.py:169-182)."""
        config = self.config.get(name, None)
        if config is None:
            raise RuntimeError(f"Stream {name!r} is not defined")
        with MappedArray(self, name) as m:
            if m.array.data.c_contiguous:
                return np.copy(m.array)
            return np.ascontiguousarray(m.array)
