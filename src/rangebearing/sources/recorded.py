"""Recorded frames: a directory of images, a video or an MCAP file, read lazily, paced like a camera."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Callable, Dict, Optional, Tuple, Union

import numpy as np

from ..core.yuv import Yuv420
from ..errors import FrameError, SourceError
from .base import Frame, with_lores
from .clip_store import ClipStore
from .image_bytes import decode_file
from .image_damage import why_undecodable
from .mcap_frames import McapFrames, is_mcap_file
from .pacing import Pacer
from .recorded_files import IMAGE_SUFFIXES, check_recording_path, count_recorded, iter_recorded, list_images
from .video_frames import END, EndOfVideo, VideoFrames

PathLike = Union[str, Path]
_CACHE_BYTES = 64 * 1024 * 1024  # decoded frames kept in memory for looping when no ClipStore can take them


Fetched = Union[Optional[np.ndarray], EndOfVideo]


class _ImageDir:
    """Random access to a directory's images, decoded once when looping.

    Decoded frames go to ``store`` (the page cache, :mod:`.clip_store`), or into a bounded in-memory
    cache where it cannot take them. Kept frames are read-only; ``in_place`` hands them out as they
    are (a camera's buffers are not copied either), otherwise each is a copy the caller may draw on.
    """

    def __init__(self, directory: Path, cache: bool, in_place: bool = False,
                 store: Optional[ClipStore] = None) -> None:
        self.paths = list_images(directory)
        self.length: Optional[int] = len(self.paths)
        self._cache: Optional[Dict[int, Optional[np.ndarray]]] = {} if cache else None
        self._store = store if cache else None
        self._cached_bytes = 0
        self._in_place = in_place

    def name(self, pos: int) -> str:
        return self.paths[pos].name

    def why(self, pos: int) -> str:
        """Why the image at ``pos`` gives no frame."""
        return why_undecodable(self.paths[pos])

    def get(self, pos: int) -> Fetched:
        if self._cache is None:
            return decode_file(self.paths[pos])
        stored = self._store.get(("bgr", pos)) if self._store is not None else None
        if stored is not None:
            image: Optional[np.ndarray] = stored[0]
        elif pos in self._cache:
            image = self._cache[pos]
        else:
            image = decode_file(self.paths[pos])
            kept = self._store.put(("bgr", pos), [image]) if self._store is not None and image is not None else None
            if kept is not None:
                image = kept[0]
            else:
                size = 0 if image is None else image.nbytes
                if self._cached_bytes + size > _CACHE_BYTES:
                    return image  # not kept: the caller's own
                if image is not None:
                    image.setflags(write=False)
                self._cache[pos] = image
                self._cached_bytes += size
        # Else a copy, so a consumer drawing on its frame cannot alter the next loop.
        return image if image is None or self._in_place else image.copy()

    def close(self) -> None:
        self._cache = None


Reader = Union[_ImageDir, VideoFrames, McapFrames]


class RecordedSource:
    """Recorded frames served like a live camera.

    With ``fps`` set, frame *i* is "captured" at ``open() + i/fps``: ``read()``
    waits for the next frame when the consumer is early, and when it is late
    returns the newest frame already due, counting the skipped ones in
    :attr:`dropped`. With ``fps`` None or 0 it serves every frame as fast as
    the consumer reads and never drops. ``loop`` restarts at the end;
    ``Frame.index`` keeps counting across loops while ``Frame.name`` names the
    file (or the position in the video). ``clock`` (ns) and ``sleep`` (s) are
    injectable so tests can pace without real time passing. ``lores`` adds the
    YUV420 stream a Pi camera delivers beside each frame (OpenCV's I420 of
    it; kept with the decoded frame when looping, as the ISP makes it for free).
    ``in_place`` (a caller done with each frame before the next, the daemon):
    a looping clip's decoded frames are handed out read-only, uncopied. A
    looping directory's decoded frames and their YUV420 live in the page cache
    (:class:`~.clip_store.ClipStore`), mapped in only while a frame is in use.
    """

    may_block = False  # reads wait only on ``sleep`` (a stop ends them): no reader thread needed

    def __init__(
        self,
        path: PathLike,
        fps: Optional[float] = None,
        loop: bool = False,
        clock: Callable[[], int] = time.monotonic_ns,
        sleep: Callable[[float], object] = time.sleep,
        lores: bool = False,
        in_place: bool = False,
    ) -> None:
        self._path = path
        self._in_place = in_place
        self._loop = loop
        self._lores = lores
        self._yuv: Dict[str, Yuv420] = {}  # by frame name, when looping
        self._store = ClipStore()
        self._clock = clock
        self._pacer = Pacer(float(fps), clock, sleep) if fps else None
        self._reader: Optional[Reader] = None
        self._next = 0
        self._dropped = 0

    @property
    def dropped(self) -> int:
        return self._dropped

    def open(self) -> None:
        """Check the recording and start the virtual camera clock."""
        if self._reader is not None:
            return
        p = check_recording_path(self._path)
        files = McapFrames(p, END) if not p.is_dir() and is_mcap_file(p) else None
        self._reader = (_ImageDir(p, self._loop, self._in_place, self._store) if p.is_dir()
                        else files or VideoFrames(p))
        if self._pacer is not None:
            self._pacer.start()
        self._next = 0
        self._dropped = 0

    def close(self) -> None:
        if self._reader is not None:
            self._reader.close()
            self._reader = None
        self._yuv.clear()
        self._store.close()

    def read(self) -> Optional[Frame]:
        """The next (paced: newest due) frame; None at the end; FrameError for a corrupt one."""
        reader = self._reader
        if reader is None:
            raise SourceError("recorded source is not open")
        self._store.release()  # the caller is done with the frame it read last
        i = self._next
        if not self._loop and reader.length is not None and i >= reader.length:
            return None  # the end: no point waiting for a frame that will never come
        ahead, ready = None, None
        if self._pacer is not None:
            # the frame made before it is due, as a camera delivers them ready: capture-to-send is the pipeline's
            ahead = self._fetch(reader, i)
            if ahead is not None and ahead[1] is not None and (not self._lores or reader.name(ahead[0]) in self._yuv):
                ready = self._frame(reader, ahead, i)  # not with its YUV420 still to make: a late read skips it
            last = None if self._loop or reader.length is None else reader.length - 1
            i = self._pacer.next_index(i, last)
            self._dropped += i - self._next
        if ready is not None and i == self._next:
            self._next = i + 1
            return ready
        fetched = ahead if ahead is not None and i == self._next else self._fetch(reader, i)
        end = None if reader.length is None else reader.length - 1
        if fetched is None and end is not None and self._next <= end < i:
            # a paced skip ran past the end of a video of unknown length: its last frame, as a camera would give
            self._dropped -= i - end
            i = end
            fetched = self._fetch(reader, i)
        if fetched is None:
            return None
        self._next = i + 1
        if fetched[1] is None:
            why = reader.why(fetched[0])
            raise FrameError(f"{reader.name(fetched[0])}: unreadable image: {why}")
        return self._frame(reader, fetched, i)

    def _frame(self, reader: Reader, fetched: Tuple[int, Optional[np.ndarray]], i: int) -> Frame:
        t_ns = self._pacer.capture_ns(i) if self._pacer is not None else self._clock()
        frame = Frame(image=fetched[1], t_mono_ns=t_ns, index=i, name=reader.name(fetched[0]))
        return self._with_lores(frame) if self._lores else frame

    def _with_lores(self, frame: Frame) -> Frame:
        yuv = self._yuv.get(frame.name)
        if yuv is not None:
            self._store.get(("yuv", frame.name))  # mapped in again: released at the next read
            return Frame(frame.image, frame.t_mono_ns, frame.index, frame.name, yuv)
        frame = with_lores(frame)
        yuv = frame.lores_yuv420
        if not self._loop or yuv is None:
            return frame
        planes = self._store.put(("yuv", frame.name), [yuv.y, yuv.u, yuv.v])
        if planes is not None:  # handed out again every loop, read-only
            yuv = Yuv420(*planes, colour_space=yuv.colour_space)
        elif len(self._yuv) * frame.image.nbytes < _CACHE_BYTES:
            for plane in (yuv.y, yuv.u, yuv.v):
                plane.setflags(write=False)  # handed out again every loop
        else:
            return frame
        self._yuv[frame.name] = yuv
        return Frame(frame.image, frame.t_mono_ns, frame.index, frame.name, yuv)

    def _fetch(self, reader: Reader, i: int) -> Optional[Tuple[int, Optional[np.ndarray]]]:
        for _ in range(2):  # a second try once a video's length has been learned
            length = reader.length
            if length is not None:
                if length == 0 or (i >= length and not self._loop):
                    return None
                pos = i % length
            else:
                pos = i
            image = reader.get(pos)
            if not isinstance(image, EndOfVideo):
                return pos, image
            if not self._loop:
                return None
        return None


__all__ = ["IMAGE_SUFFIXES", "RecordedSource", "count_recorded", "iter_recorded", "list_images"]
