"""Newcomers at the frame's sides: band colour appearing where no followed landmark is.

Window tracking measures only the landmarks it follows, so a landmark coming
into view waits for the next scheduled full scan, up to ``full_scan_interval_s``
(or ``full_scan_every - 1`` frames), though it is findable from the frame it is 60 % in view. Landmarks
come into view at the frame's left and right sides (a neighbour driving in, the
observer turning). Each frame the two side strips are classified at the full
scan's half resolution (a few small calls: two strips of ``EDGE_STRIP_PX``
columns), the followed landmarks' boxes are blanked, and the columns left that
hold both red and blue, as a landmark's do, are counted. A full scan records the
counts it leaves; when a side gains ``NEW_COLUMNS`` of them, something like a
landmark came in there, and the caller scans the whole frame.

A wall of one colour, or a robot's body passing in front of it, makes no such
column. Red and blue things at the side only raise the counts the scan
records; they trigger nothing until they change. A landmark not yet findable
when the scan runs is in the recorded counts, and triggers the next scan by
growing further as it comes in.

Between scans the counts are classified again only when the strips changed
(:func:`side_view`): a probe of every ``PROBE_STEP``-th row of them is compared
with the probe the counts were last made from, and when no probe pixel moved
by more than ``PROBE_CHANGE`` levels and the same parts of the strips are
blanked, the counts are the last ones. Anything that can come in (a robot
with its landmark is more than 40 rows tall at 2.2 m) crosses several probe
rows, and a band's colour against any background differs by far more than
``PROBE_CHANGE``; camera noise stays below it. Reading the strips from a new
frame is most of their cost (their rows are scattered over the frame's
memory): the probe reads a quarter of them.
"""

from __future__ import annotations

from typing import List, Optional, Sequence, Tuple

import cv2
import numpy as np

from .._compat import frozen
from .color import Gains, apply_gains, class_masks, to_hsv
from .params import DetectionParams
from .types import BBox

EDGE_STRIP_PX = 48  # full-resolution columns: 60 % of the nearest landmark's width (0.45 m) fits in
NEW_COLUMNS = 2  # half-resolution columns: 60 % of a landmark at 2 m is about 3
MIN_PX = 2  # a column holds a colour when it has this many of its pixels (half resolution): not one noisy pixel

PROBE_STEP = 8  # full-resolution rows between the change probe's rows (a robot crosses 5 or more of them)
PROBE_CHANGE = 32  # a probe pixel that moved by more than this (any channel, 0-255) is a change of the strips

SideCounts = Tuple[int, int]  # landmark-like columns on the left and on the right
Cut = Tuple[int, int, int, int]  # a blanked part of the strips: half-resolution rows y0:y1, columns c0:c1


@frozen
class SideView:
    """Side counts with what they were made from: the strips' change probe, the blanked parts, the gains."""

    counts: SideCounts
    probe: Optional[np.ndarray] = None  # (rows, 2·half, 3) uint8: every PROBE_STEP-th row of both strips
    cuts: Tuple[Cut, ...] = ()
    gains: Optional[Gains] = None


def side_colour(bgr: np.ndarray, cfg: DetectionParams, gains: Gains, boxes: Sequence[BBox]) -> SideCounts:
    """Columns (half resolution) of the frame's two side strips that hold both band colours, outside ``boxes``.

    A column counts when it has at least ``MIN_PX`` red and ``MIN_PX`` blue class
    pixels, as a landmark's columns do; a wall of one colour, or a robot's body
    in front of it, changes no count.

    Parameters
    ----------
    bgr : (H, W, 3) uint8
        The full-resolution frame.
    cfg : DetectionParams
        Hue ranges and the S/V thresholds of the full scan.
    gains : Gains
        The balance the full scan classified with.
    boxes : sequence of BBox
        Full-resolution boxes of the landmarks already known (blanked).
    """
    return side_view(bgr, cfg, gains, boxes).counts


def side_view(
    bgr: np.ndarray, cfg: DetectionParams, gains: Gains, boxes: Sequence[BBox], last: Optional[SideView] = None
) -> SideView:
    """:func:`side_colour` with what its counts were made from; ``last``'s counts again when nothing changed.

    ``last`` is the view of an earlier frame (of this size): when the strips' probe
    rows moved by no more than ``PROBE_CHANGE`` since it, the same parts of them
    are blanked and the gains are the same, its counts stand (see the module's notes).
    """
    h, w = bgr.shape[:2]
    s = min(EDGE_STRIP_PX, w // 4) // 2 * 2
    if s < 2 or h < 2:
        return SideView((0, 0))
    half = s // 2
    cuts = _cuts(boxes, w, h, s)
    probe = np.concatenate((bgr[::PROBE_STEP, :s:2], bgr[::PROBE_STEP, w - s :: 2]), axis=1)
    if (last is not None and last.probe is not None and last.probe.shape == probe.shape and last.cuts == cuts
            and last.gains == gains and cv2.norm(probe, last.probe, cv2.NORM_INF) <= PROBE_CHANGE):
        return last
    # every other pixel of each strip (the full scan's resolution), as a nearest-neighbour halving picks them
    rows = h // 2 * 2
    strips = np.concatenate((bgr[:rows:2, :s:2], bgr[:rows:2, w - s :: 2]), axis=1)
    both = _both_colours(strips, cfg, gains, cuts)
    counts = (int(np.count_nonzero(both[:half])), int(np.count_nonzero(both[half:])))
    return SideView(counts, probe, cuts, gains)


def _cuts(boxes: Sequence[BBox], w: int, h: int, s: int) -> Tuple[Cut, ...]:
    """The parts of the two strips (half resolution, left strip then right) that ``boxes`` blank."""
    half = s // 2
    out: List[Cut] = []
    for bx, by, bw, bh in boxes:
        y0, y1 = max(0, by // 2), max(0, -(-(by + bh) // 2))
        for x0, off in ((0, 0), (w - s, half)):  # the box's columns inside each strip
            c0, c1 = max(bx, x0), min(bx + bw, x0 + s)
            if c1 > c0 and y1 > y0:
                out.append((y0, y1, off + (c0 - x0) // 2, off + -(-(c1 - x0) // 2)))
    return tuple(out)


def came_in(now: SideCounts, recorded: SideCounts) -> bool:
    """Whether a side gained ``NEW_COLUMNS`` landmark-like columns since the counts a full scan recorded."""
    return any(n >= r + NEW_COLUMNS for n, r in zip(now, recorded))


# Landmarks coming out from behind a followed one. A nearer landmark moving sideways uncovers what stands
# behind it, and a farther one walks out from behind it: either comes out right beside the nearer one's limb,
# where no window looks. The same landmark-like columns are counted in two strips beside every followed
# landmark's box (each as wide as the box, its rows grown by half its height: one farther away is smaller and
# nearer the horizon), the followed landmarks' columns blanked. A full scan records the count it leaves; a
# frame whose count gained ``NEW_COLUMNS`` is scanned whole.
BESIDE_GAP_PX = 2  # full-resolution columns between a box and its strips: its own limb's mixed pixels


def beside_count(bgr: np.ndarray, cfg: DetectionParams, gains: Gains, boxes: Sequence[BBox]) -> int:
    """Landmark-like columns (half resolution, as :func:`side_colour` counts them) right beside ``boxes``.

    The parameters are :func:`side_colour`'s; ``boxes`` are the followed landmarks' (full-resolution),
    and their own columns are not counted.
    """
    h, w = bgr.shape[:2]
    strips: List[Tuple[int, int, int, int]] = []  # full-resolution rows y0:y1 and columns x0:x1, every other one
    for bx, by, bw, bh in boxes:
        y0, y1 = max(0, by - bh // 2), min(h, by + bh + bh // 2)
        left, right = bx - BESIDE_GAP_PX, bx + bw + BESIDE_GAP_PX
        for x0, x1 in ((left - bw, left), (right, right + bw)):
            x0, x1 = max(0, x0), min(w, x1)
            if x1 - x0 >= 2 and y1 - y0 >= 2:
                strips.append((y0, y1, x0, x1))
    if not strips:
        return 0
    rows = max(-(-(y1 - y0) // 2) for y0, y1, _, _ in strips)
    img = np.zeros((rows, sum(-(-(x1 - x0) // 2) for _, _, x0, x1 in strips), 3), np.uint8)  # black pads
    at = 0
    for y0, y1, x0, x1 in strips:
        n = -(-(x1 - x0) // 2)
        img[: -(-(y1 - y0) // 2), at : at + n] = bgr[y0:y1:2, x0:x1:2]
        at += n
    followed = np.zeros(w, bool)  # the followed landmarks' columns (full resolution)
    for bx, _, bw, _ in boxes:
        followed[max(0, bx) : max(0, bx + bw)] = True
    xs = np.concatenate([np.arange(x0, x1, 2) for _, _, x0, x1 in strips])  # img's columns, in the frame
    both = _both_colours(img, cfg, gains) & ~followed[xs]
    return int(np.count_nonzero(both))


def _both_colours(strips: np.ndarray, cfg: DetectionParams, gains: Gains, cuts: Sequence[Cut] = ()) -> np.ndarray:
    """(columns,) bool: which columns of ``strips`` (BGR) hold ``MIN_PX`` red and ``MIN_PX`` blue class pixels,
    the ``cuts`` (rows and columns of ``strips``) blanked first."""
    red, blue = class_masks(to_hsv(apply_gains(strips, gains)), cfg.red_hue, cfg.blue_hue, cfg.s_min, cfg.v_min)
    for y0, y1, c0, c1 in cuts:
        red[y0:y1, c0:c1] = 0
        blue[y0:y1, c0:c1] = 0
    n_red = cv2.reduce(red, 0, cv2.REDUCE_SUM, dtype=cv2.CV_32S)[0]
    n_blue = cv2.reduce(blue, 0, cv2.REDUCE_SUM, dtype=cv2.CV_32S)[0]
    return (n_red >= 255 * MIN_PX) & (n_blue >= 255 * MIN_PX)
