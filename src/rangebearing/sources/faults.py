"""How camera sources turn capture timeouts into errors: one policy for every backend.

A single timeout is a skipped frame (:class:`~rangebearing.errors.FrameError`:
the loop counts it and goes on); ``limit`` timeouts in a row mean the camera
has gone (:class:`~rangebearing.errors.CameraError`: the run ends and the
service manager restarts it).
"""

from __future__ import annotations

from typing import Union

from ..errors import CameraError, FrameError


class TimeoutBudget:
    """Counts consecutive capture timeouts of one camera.

    Parameters
    ----------
    what : str
        The camera as messages name it (``"camera 0"``, ``"/dev/video0"``).
    timeout_s : float
        How long one capture may wait; only used in messages.
    limit : int
        Timeouts in a row that mean the camera is gone (at least 1).
    """

    def __init__(self, what: str, timeout_s: float, limit: int) -> None:
        self.what = what
        self.timeout_s = timeout_s
        self.limit = max(1, limit)
        self.count = 0

    def frame_arrived(self) -> None:
        self.count = 0

    def timed_out(self) -> Union[FrameError, CameraError]:
        """Count a timeout; the error to raise: FrameError, or CameraError at the limit."""
        self.count += 1
        msg = f"{self.what}: no frame within {self.timeout_s:g} s"
        if self.count >= self.limit:
            return CameraError(f"{msg} ({self.count} times in a row); giving up")
        return FrameError(f"{msg} (timeout {self.count} of {self.limit})")
