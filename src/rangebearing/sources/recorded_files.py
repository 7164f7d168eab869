"""Recorded frames read in one pass: which files a folder holds, every frame in order, how many there are."""

from __future__ import annotations

from pathlib import Path
from typing import Dict, Iterator, List, Optional, Tuple, Union

import cv2
import numpy as np

from ..errors import SourceError
from .image_bytes import decode_file
from .image_damage import why_undecodable
from .mcap_frames import count_mcap, is_mcap_file, iter_mcap
from .video_frames import open_video

IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp")
PathLike = Union[str, Path]


def list_images(directory: Path) -> List[Path]:
    """Image files in ``directory`` sorted by name (a broken link too: a bad frame, counted); others ignored."""
    return sorted(
        (p for p in directory.iterdir() if p.suffix.lower() in IMAGE_SUFFIXES
         and (p.is_file() or (p.is_symlink() and not p.exists()))),
        key=lambda p: p.name,
    )


def check_recording_path(path: PathLike) -> Path:
    p = Path(path)
    if not str(path):
        raise SourceError("no recording path given (source.path is empty)")
    if not p.exists():
        raise SourceError(f"{p}: no such file or directory")
    if p.is_fifo() or p.is_socket():  # opening one would wait for a writer for ever
        raise SourceError(f"{p}: a {'FIFO' if p.is_fifo() else 'socket'}, not a recording (a folder of images, "
                          "a video or an MCAP file)")
    if p.is_dir() and not list_images(p):
        raise SourceError(f"{p}: holds no images ({', '.join(IMAGE_SUFFIXES)})")
    if p.suffix.lower() == ".mcap" and p.is_file() and not is_mcap_file(p):
        raise SourceError(f"{p}: not an MCAP file (no MCAP magic at its start: empty, or another format)")
    return p


def iter_recorded(
    path: PathLike, reasons: Optional[Dict[str, str]] = None
) -> Iterator[Tuple[str, Optional[np.ndarray]]]:
    """Yield ``(name, image)`` for every recorded frame, decoding one at a time.

    A directory yields its images sorted by file name, an unreadable image as
    ``(name, None)``; a video or an MCAP recording yields ``(str(i), image)``
    for frame ``i``. ``reasons`` (when given) gets ``name: why`` for every
    frame yielded as ``None``, before it is yielded.

    Raises
    ------
    SourceError
        The path does not exist, the directory holds no images, or OpenCV
        cannot open the video.
    """
    p = check_recording_path(path)
    if p.is_dir():
        for img_path in list_images(p):
            image = decode_file(img_path)  # None, not an exception, for a corrupt, huge or unreadable file
            if image is None and reasons is not None:
                reasons[img_path.name] = why_undecodable(img_path)
            yield img_path.name, image
        return
    if is_mcap_file(p):
        yield from iter_mcap(p, reasons)
        return
    cap = open_video(p)
    try:
        i = 0
        while True:
            ok, image = cap.read()
            if not ok:
                return
            yield str(i), image
            i += 1
    finally:
        cap.release()


def count_recorded(path: PathLike) -> Optional[int]:
    """How many frames :func:`iter_recorded` will yield, or None if the video does not say."""
    p = check_recording_path(path)
    if p.is_dir():
        return len(list_images(p))
    if is_mcap_file(p):
        return count_mcap(p)
    cap = open_video(p)
    try:
        n = int(cap.get(cv2.CAP_PROP_FRAME_COUNT))
    finally:
        cap.release()
    return n if n > 0 else None
