"""When the whole frame is scanned instead of windows, and how its landmarks continue the tracks.

:func:`scan_due` says when the periodic full scan is due (:class:`Cadence`: in
capture time, ``full_scan_interval_s``, or every ``full_scan_every`` frames);
:func:`crossing` says when followed landmarks are about to meet in the image
(the caller then scans the whole frame); :func:`rescanned` turns a full scan's
landmarks into tracks that keep the image velocity of the ones they continue.
"""

from __future__ import annotations

from typing import List, Optional, Sequence

from .._compat import frozen
from .detect import BandCentroids
from .tracking import Track, search_boxes
from .types import XY

WIDTH_RATIO = 1.6  # a landmark found again by a full scan: about as wide as it was
DUE_SLACK_S = 1e-6  # a scan due at exactly the interval is due whatever the rounding of the frames' times


@frozen
class Cadence:
    """Where the periodic full scan stands between frames."""

    tracked: int = 0  # frames tracked since the last full scan
    scan_t_s: Optional[float] = None  # the capture time of the last full scan (None: the frames carry none)
    forced: bool = False  # the next frame is scanned whole (a track was lost; a scan left unfinished)
    held: bool = False  # this frame's periodic scan is left for after its readings (Pipeline.process_scan_later)


def scan_due(c: Cadence, t_s: Optional[float], every: int, interval_s: float, nominal_dt_s: float) -> bool:
    """Whether the frame captured at ``t_s`` is scanned whole for the cadence's sake (tracks or not).

    With ``interval_s`` > 0 the periodic scan is due once that much capture
    time has passed since the last full scan, whatever the frame rate (a
    newcomer in mid-view shows within ``interval_s`` plus a frame); frames
    without a time are ``nominal_dt_s`` apart, and a clock that went back
    (another run) makes it due. With ``interval_s`` = 0 it is due every
    ``every`` frames.
    """
    if c.forced:
        return True
    if c.held:
        return False
    if interval_s <= 0:
        return c.tracked >= every - 1
    if t_s is None or c.scan_t_s is None:
        elapsed = (c.tracked + 1) * nominal_dt_s
    else:
        elapsed = t_s - c.scan_t_s
        if elapsed < 0:
            return True
    return elapsed >= interval_s - DUE_SLACK_S


def periodic(c: Cadence) -> bool:
    """Whether a due scan (:func:`scan_due`) would be the periodic one only, which may be left for later.

    Not when forced, nor when no frame was tracked since the last full scan: then every frame is scanned
    (``full_scan_every: 1``, or an interval shorter than a frame), and leaving each frame's scan for after
    its send would only add a tracked step to every frame.
    """
    return not c.forced and c.tracked >= 1


def crossing(tracks: Sequence[Track], slack_px: float = 2.0) -> bool:
    """Whether two landmarks may overlap in the image this frame: their predicted columns meet.

    Each landmark's columns are its bands' boxes moved by its velocity and grown
    by its speed and ``slack_px``. Where two meet, one passes in front of the
    other: windows then hold parts of both (a track slides onto its neighbour or
    measures the merged pair), and the one behind is partly hidden in a way
    that only a full scan measures (or that ends a robot's occlusion). The
    caller scans the whole frame instead.
    """
    if len(tracks) < 2:
        return False
    spans = []
    for t in tracks:
        red, blue = search_boxes(t)
        grow = abs(t.velocity_px[0]) + slack_px
        spans.append((min(red[0], blue[0]) - grow, max(red[0] + red[2], blue[0] + blue[2]) + grow))
    spans.sort()
    reach = spans[0][1]  # the farthest right any landmark so far reaches
    for start, end in spans[1:]:
        if start < reach:
            return True
        reach = max(reach, end)
    return False


def rescanned(before: Sequence[Track], found: Sequence[BandCentroids], lost: Sequence[Track] = ()) -> List[Track]:
    """Tracks for a full scan's landmarks, each moving as the track it continues moved (a newcomer stands still).

    ``before`` are the tracks of the last frame, ``lost`` those the frame before
    it lost (a track lost in a window is scanned for the next frame). The
    landmark a track continues is the one nearest its predicted place, within
    half a width of it and about as wide; its velocity is its step since the
    track was last measured. Started from rest, a moving landmark's first
    windows would lag it by its speed.
    """
    known = [(t, 1) for t in before] + [(t, 2) for t in lost]
    out, used = [], set()
    for c in found:
        cx, cy = _middle(c)
        best, gap = None, 0.5 * c.width_px
        for k, (t, age) in enumerate(known):
            tx, ty = _middle(t.bands)
            d = max(abs(tx + age * t.velocity_px[0] - cx), abs(ty + age * t.velocity_px[1] - cy))
            ratio = c.width_px / max(t.bands.width_px, 1e-6)
            if k not in used and d <= gap and 1 / WIDTH_RATIO <= ratio <= WIDTH_RATIO:
                best, gap = k, d
        if best is None:
            out.append(Track(c))
            continue
        used.add(best)
        t, age = known[best]
        tx, ty = _middle(t.bands)
        out.append(Track(c, ((cx - tx) / age, (cy - ty) / age)))
    return out


def _middle(c: BandCentroids) -> XY:
    return 0.5 * (c.red_xy_px[0] + c.blue_xy_px[0]), 0.5 * (c.red_xy_px[1] + c.blue_xy_px[1])
