"""Landmarks gone behind a nearer one: remembered, so the full scan finds them as they come out.

Window tracking finds no newcomer, and a landmark that a nearer one passes in
front of leaves the tracks at the full scan that no longer sees it. When it
comes out again it would stay unreported until the next scheduled full scan.
A landmark that vanishes where a found landmark now stands is therefore kept
here, where it was last seen, for up to ``full_scan_every`` full scans: while a
tracked landmark covers that place, the pipeline scans the whole frame
(:func:`.scans.crossing` over tracks and hidden ones), and the first scan
that sees it again makes it a track.
"""

from __future__ import annotations

from typing import List, Sequence, Tuple

from .._compat import frozen
from .detect import BandCentroids
from .scans import crossing
from .tracking import Track

WIDTH_RATIO = 1.6  # a landmark found again: about as wide as it was


@frozen
class Hidden:
    """A landmark last seen ``age`` full scans ago, at its track's place."""

    track: Track
    age: int = 0


def _seen(t: Track, found: Sequence[BandCentroids]) -> bool:
    """Whether a found landmark is this one: its red band where the track has it, about as wide."""
    x, w = t.bands.red_xy_px[0], t.bands.width_px
    return any(abs(c.red_xy_px[0] - x) <= max(w, c.width_px)
               and 1 / WIDTH_RATIO <= c.width_px / max(w, 1e-6) <= WIDTH_RATIO for c in found)


def still_hidden(
    before: Sequence[Track], hidden: Sequence[Hidden], found: Sequence[BandCentroids], max_age: int
) -> List[Hidden]:
    """After a full scan: the landmarks of ``before`` and ``hidden`` it did not find, behind one it did.

    Parameters
    ----------
    before : sequence of Track
        The tracks going into the scan.
    hidden : sequence of Hidden
        The landmarks hidden before it.
    found : sequence of BandCentroids
        What the scan found.
    max_age : int
        How many full scans a landmark is looked for (``full_scan_every``).
    """
    now = [Track(c) for c in found]
    out: List[Hidden] = []
    for h in [Hidden(t) for t in before] + [Hidden(h.track, h.age + 1) for h in hidden]:
        if h.age < max_age and not _seen(h.track, found) and crossing([*now, h.track]):
            out.append(h)
    return out


def tracks_of(hidden: Sequence[Hidden]) -> Tuple[Track, ...]:
    """The hidden landmarks' tracks, standing still where they were last seen."""
    return tuple(Track(h.track.bands) for h in hidden)
