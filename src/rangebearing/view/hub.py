"""The hand-over between the capture loop and the view's browsers, off the hot path.

The capture loop asks :meth:`ViewHub.wants` (two attribute reads and a compare)
after each frame; only when a browser is watching and the capped rate allows
does it :meth:`~ViewHub.offer` the frame, which stores a reference and wakes the
encoder thread. That thread draws the overlay, makes the masks if someone asked
for them, encodes the JPEGs and the JSON state, and hands the result to every
waiting HTTP handler. With no browser connected nothing is drawn, encoded or
copied.

Frames are held by reference: sources hand out a fresh array per frame and
nothing writes to it afterwards; the encoder draws on its own copy.
"""

from __future__ import annotations

import collections
import json
import logging
import threading
import time
from contextlib import contextmanager
from typing import Any, Deque, Dict, Iterator, Mapping, Optional

import numpy as np

from .._compat import frozen
from ..core.types import FrameResult
from . import draw
from .thresholds import Thresholds

log = logging.getLogger("rangebearing.view")

LAYERS = ("frame", "masks")


@frozen
class Snapshot:
    """What the browsers get for one frame: ``seq`` counts published snapshots from 1."""

    seq: int
    jpeg: bytes
    masks_jpeg: bytes  # empty unless someone was watching the masks
    state: bytes  # JSON


@frozen
class _Job:
    image: np.ndarray
    name: str
    result: FrameResult
    detection: Any
    status: Mapping[str, Any]
    t_unix: float


EMPTY = Snapshot(0, b"", b"", b"{}")


class ViewHub:
    """Frames in from the capture loop, JPEGs and JSON out to the HTTP handlers.

    Parameters
    ----------
    thresholds : Thresholds
        The thresholds in force at start (the page's controls start there).
    max_fps : float
        At most this many frames a second are drawn and encoded.
    config_file : str, optional
        Where "save" writes the thresholds; ``None`` disables saving.
    hfov_rad, band_ratio : float
        The camera's horizontal field of view (drawn on the bird's-eye plot) and
        band height / band spacing (the size of the drawn bands).
    poll_grace_s : float
        A plain request (``/api/state``, ``/frame.jpg``) keeps frames coming this long.
    """

    def __init__(
        self,
        thresholds: Thresholds,
        max_fps: float = 10.0,
        config_file: Optional[str] = None,
        hfov_rad: float = 0.935,
        band_ratio: float = 15.0 / 55.0,
        poll_grace_s: float = 2.0,
        jpeg_quality: int = 80,
    ) -> None:
        self.max_fps = max_fps
        self.config_file = config_file
        self.hfov_rad = hfov_rad
        self.band_ratio = band_ratio
        self.jpeg_quality = jpeg_quality
        self._interval_ns = int(1e9 / max_fps) if max_fps > 0 else 0
        self._grace_ns = int(poll_grace_s * 1e9)
        self._lock = threading.Lock()
        self._new_job = threading.Condition(self._lock)
        self._published = threading.Condition(self._lock)
        self._job: Optional[_Job] = None
        self._snapshot = EMPTY
        self._viewers = 0
        self._mask_viewers = 0
        self._poll_until_ns = 0
        self._masks_until_ns = 0
        self._next_ns = 0
        self._thresholds = thresholds
        self._pending: Optional[Thresholds] = None
        self._closed = False
        self._encode_ns: Deque[int] = collections.deque(maxlen=32)
        self.encoded = 0  # snapshots published
        self._thread: Optional[threading.Thread] = None

    # --- the capture loop's side (hot path) ------------------------------------------
    def wants(self, now_ns: int) -> bool:
        """True when a browser is watching and the capped rate allows another frame."""
        return (self._viewers > 0 or now_ns < self._poll_until_ns) and now_ns >= self._next_ns

    def offer(
        self, now_ns: int, image: np.ndarray, name: str, result: FrameResult, detection: Any,
        status: Mapping[str, Any],
    ) -> None:
        """Hand one frame to the encoder thread (replacing one it has not taken yet)."""
        job = _Job(image, name, result, detection, status, time.time())
        with self._lock:
            self._job = job
            # on a fixed grid, so a 30 fps camera gives 10 fps, not every fourth frame (7.5 fps); after a gap, anew
            late = now_ns - self._next_ns >= self._interval_ns
            self._next_ns = now_ns + self._interval_ns if late else self._next_ns + self._interval_ns
            self._new_job.notify()

    def take_thresholds(self) -> Optional[Thresholds]:
        """Thresholds a browser set since the last call, or None (the loop rebuilds its pipeline)."""
        if self._pending is None:
            return None
        with self._lock:
            pending, self._pending = self._pending, None
        return pending

    # --- the HTTP handlers' side ----------------------------------------------------------
    @property
    def thresholds(self) -> Thresholds:
        return self._thresholds

    def set_thresholds(self, t: Thresholds) -> None:
        """Ask the capture loop to detect with ``t`` from its next frame."""
        with self._lock:
            self._thresholds = self._pending = t

    def reset_thresholds(self, t: Thresholds) -> None:
        """The loop's own thresholds changed (a config reload): show them, drop any pending request."""
        with self._lock:
            self._thresholds, self._pending = t, None

    @contextmanager
    def viewer(self, layer: str = "frame") -> Iterator[None]:
        """Count a streaming client (MJPEG or events) for as long as the block runs."""
        with self._lock:
            self._viewers += 1
            self._mask_viewers += layer == "masks"
        try:
            yield
        finally:
            with self._lock:
                self._viewers -= 1
                self._mask_viewers -= layer == "masks"

    def touch(self, layer: str = "frame") -> None:
        """A one-off request: keep frames (and masks) coming for the grace period."""
        until = time.monotonic_ns() + self._grace_ns
        with self._lock:
            self._poll_until_ns = max(self._poll_until_ns, until)
            if layer == "masks":
                self._masks_until_ns = max(self._masks_until_ns, until)

    @property
    def snapshot(self) -> Snapshot:
        return self._snapshot

    def wait(self, after_seq: int, timeout_s: float) -> Optional[Snapshot]:
        """The first snapshot newer than ``after_seq``, or None on timeout or close."""
        with self._lock:
            self._published.wait_for(lambda: self._snapshot.seq > after_seq or self._closed, timeout_s)
            snap = self._snapshot
        return snap if snap.seq > after_seq else None

    @property
    def closed(self) -> bool:
        return self._closed

    def figures(self) -> Dict[str, Any]:
        """The view's own cost and audience."""
        enc = sorted(self._encode_ns)
        return {
            "encode_ms": enc[len(enc) // 2] / 1e6 if enc else 0.0,
            "max_fps": self.max_fps,
            "viewers": self._viewers,
            "encoded": self.encoded,
        }

    # --- the encoder thread -----------------------------------------------------------------
    def start(self) -> None:
        if self._thread is None:
            self._thread = threading.Thread(target=self._run, name="rangebearing-view-encoder", daemon=True)
            self._thread.start()

    def close(self) -> None:
        """Stop the encoder thread and wake every waiting handler."""
        with self._lock:
            self._closed = True
            self._new_job.notify_all()
            self._published.notify_all()
        if self._thread is not None:
            self._thread.join(timeout=5.0)

    def _run(self) -> None:
        while True:
            with self._lock:
                self._new_job.wait_for(lambda: self._job is not None or self._closed)
                if self._closed:
                    return
                job, self._job = self._job, None
                want_masks = self._mask_viewers > 0 or time.monotonic_ns() < self._masks_until_ns
            try:
                snap = self._encode(job, want_masks)  # type: ignore[arg-type]
            except Exception:  # a drawing bug must not end the view (nor ever the daemon)
                log.exception("view: frame not encoded")
                continue
            with self._lock:
                self._snapshot = snap
                self._published.notify_all()

    def _encode(self, job: _Job, want_masks: bool) -> Snapshot:
        t0 = time.perf_counter_ns()
        jpeg = draw.encode_jpeg(draw.overlay(job.image, job.result, self.band_ratio), self.jpeg_quality)
        masks = draw.encode_jpeg(draw.masks(job.image, job.detection), self.jpeg_quality) if want_masks else b""
        self._encode_ns.append(time.perf_counter_ns() - t0)
        self.encoded += 1
        h, w = job.image.shape[:2]
        state = {
            "seq": self._snapshot.seq + 1,
            "frame": {"name": job.name, "width": w, "height": h, "t_unix": job.t_unix, "tracked": job.result.tracked},
            "landmarks": [draw.landmark_json(lm) for lm in job.result.landmarks],
            "stats": dict(job.status),
            "view": self.figures(),
            "thresholds": Thresholds.of(job.detection).as_json(),
            "hfov_rad": self.hfov_rad,
            "config_file": self.config_file,
        }
        return Snapshot(state["seq"], jpeg, masks, json.dumps(state, default=_plain).encode("utf-8"))  # type: ignore[arg-type]


def _plain(o: Any) -> Any:
    """numpy scalars and arrays (which the pipeline may hand out) as plain JSON numbers and lists."""
    if isinstance(o, (np.generic, np.ndarray)):
        return o.tolist()
    raise TypeError(f"{type(o).__name__} is not JSON serialisable")
