"""Stripes, not an object: do a candidate's band and body colours run on beside it?

A white skirting board between an orange wall and a blue mat reads red → white → blue in every
column along the wall; where something in front of the mat ends the blue for a while, the
structure finds a "landmark" there. A landmark is an object: beside it, at the rows of its red
band and of its white body, lies something else (a background, a wall), not both of its own
colours again, lined up with its red band's and its body's own rows (:func:`striped`).

Colours are medians of the sampled 8-bit pixels (a brick wall's mortar or a mast's edge in a
window moves them not), compared in linear light, per channel, on a log scale, within
``SAME_COLOUR_LOG``. Two regions of one surface differ by the noise of their medians too: a
camera at high gain (a dim room, a small sensor) gives the dark channels of a saturated colour
(a red wall's green and blue, a few 8-bit levels) a noise that is a large share of their level.
A channel under ``DARK_SHARE`` of the colour's brightest may differ by ``NOISE_Z`` standard
errors of the difference more, each median's taken from its samples' spread (the median
absolute deviation), ``NOISE_CAP`` at most: noise widens the tolerance only where it blurs the
measurement, so a clean frame and the bright channels that carry a colour are judged as
strictly as before.
"""

from __future__ import annotations

import math
from typing import List, Optional, Sequence, Tuple

import numpy as np

from .detect import BandCentroids
from .types import BBox

SAMPLES = 24  # rows and columns sampled per region, at most
# stripes: the colour beside the candidate, 0.15-0.6 of its width out, matches its own within this (log, per channel)
SIDE_REACH = (0.15, 0.6)
SIDE_WINDOWS, SIDE_STEP = 3, 0.45  # ... or in a window as wide this much farther out, up to 1.5 widths beyond a side
SAME_COLOUR_LOG = 0.25
NOISE_Z, NOISE_CAP = 2.0, 0.35  # ... plus this many standard errors of the two medians' difference, at most this
DARK_SHARE = 0.25  # ... in a channel this dark beside the colour's brightest (the noise swamps a few levels)
OFFSET = 0.01  # linear light added before the log (a black channel's ratio means nothing)

# a colour: linear B, G, R of the median 8-bit colour, and the sampled pixels (N, 3), each channel sorted
# (for the noise, when asked)
Colour = Tuple[List[float], np.ndarray]


def colour(bgr: np.ndarray, rows: Tuple[float, float], cols: Tuple[float, float]) -> Optional[Colour]:
    """Linear RGB (B, G, R order) of a region's median 8-bit colour and its samples, each channel sorted
    (``None`` when the region is empty)."""
    h, w = bgr.shape[:2]
    r0, r1 = max(0, round(rows[0])), min(h, round(rows[1]) + 1)
    c0, c1 = max(0, round(cols[0])), min(w, round(cols[1]) + 1)
    if r1 <= r0 or c1 <= c0:
        return None
    rs, cs = max(1, (r1 - r0) // SAMPLES), max(1, (c1 - c0) // SAMPLES)
    # np.median's values: the middle order statistics of each channel, each channel's samples sorted in one
    # contiguous row (a stable sort of uint8 is a radix sort: faster than np.partition across the channels)
    rows_ch = np.array(bgr[r0:r1:rs, c0:c1:cs].transpose(2, 0, 1)).reshape(3, -1)  # a copy: sorted in place
    rows_ch.sort(axis=1, kind="stable")
    n = rows_ch.shape[1]
    lin = [((lo + hi) / 510.0) ** 2.2 for lo, hi in zip(rows_ch[:, (n - 1) // 2].tolist(), rows_ch[:, n // 2].tolist())]
    return lin, rows_ch.T


def log_error(c: Colour, k: int) -> float:
    """Standard error of channel ``k`` of a colour on the log scale of :func:`same`.

    The standard error of a median of ``n`` samples is ``1.2533 σ / √n``, σ from the median
    absolute deviation (``1.4826 MAD``), an 8-bit level at least (quantisation), carried to the
    log scale through the 2.2 encoding: ``d log(lin + OFFSET) / d v = 2.2 lin / (v (lin + OFFSET))``.
    """
    lin, sub = c[0][k], c[1][:, k]
    n = len(sub)
    med = 0.5 * (float(sub[(n - 1) // 2]) + float(sub[n // 2]))
    dev = np.partition(np.abs(sub.astype(np.float64) - med), ((n - 1) // 2, n // 2))
    mad = 0.5 * (dev[(n - 1) // 2] + dev[n // 2])
    se8 = 1.2533 * max(1.4826 * float(mad), 1.0) / math.sqrt(n)
    return 2.2 * lin / (max(med, 0.5) * (lin + OFFSET)) * se8


def same(a: Optional[Colour], b: Optional[Colour]) -> bool:
    """Whether two colours of :func:`colour` are one: every channel within ``SAME_COLOUR_LOG``, a dark
    channel (under ``DARK_SHARE`` of the colour's brightest) within ``NOISE_Z`` standard errors of the
    difference more (``NOISE_CAP`` at most)."""
    if a is None or b is None:
        return False
    dark = DARK_SHARE * max(*a[0], *b[0])
    for k, (x, y) in enumerate(zip(a[0], b[0])):
        off = abs(math.log((x + OFFSET) / (y + OFFSET)))
        if off <= SAME_COLOUR_LOG:
            continue
        if max(x, y) >= dark:
            return False
        if off > SAME_COLOUR_LOG + min(NOISE_Z * math.hypot(log_error(a, k), log_error(b, k)), NOISE_CAP):
            return False
    return True


def _free(side: Tuple[float, float], boxes: Sequence[Tuple[float, float]]) -> Optional[Tuple[float, float]]:
    """The widest part of the column span ``side`` that no box's columns cover (``None``: under a third is free)."""
    cuts = sorted((max(lo, side[0]), min(hi, side[1])) for lo, hi in boxes if lo < side[1] and hi > side[0])
    best, at = (side[0], side[0]), side[0]
    for lo, hi in [*cuts, (side[1], side[1])]:
        if lo - at > best[1] - best[0]:
            best = (at, lo)
        at = max(at, hi)
    return best if best[1] - best[0] >= max(1.0, (side[1] - side[0]) / 3) else None


def _sides(c: BandCentroids, boxes: Sequence[Tuple[float, float]],
           frame_w: int) -> List[Tuple[bool, List[Tuple[float, float]]]]:
    """Per side of ``c`` judged (its nearest window free), whether its run was cut there and the free column spans
    of its windows, nearest first (farther windows only on a cut side: one that ends at its limb shows what lies
    beside it)."""
    x, _, w, _ = c.bbox_px
    cand = c.candidate
    boxes = [*boxes, (-math.inf, 0.0), (frame_w - 1.0, math.inf)]  # beyond the frame: nothing to judge
    out = []
    for sign, cut in ((-1.0, cand is not None and cand.cut_left), (1.0, cand is not None and cand.cut_right)):
        found: List[Tuple[float, float]] = []
        for k in range(SIDE_WINDOWS if cut else 1):
            near, far = SIDE_REACH[0] + k * SIDE_STEP, SIDE_REACH[1] + k * SIDE_STEP
            span = (x - far * w, x - near * w) if sign < 0 else (x + w + near * w, x + w + far * w)
            if k and (span[0] < 0 or span[1] > frame_w - 1):  # a farther window past the frame's edge: none
                break
            free = _free(span, boxes)
            if free:
                found.append(free)
            elif not k:  # a neighbour (or the frame's edge) right beside it: the side is not judged
                break
        if found:
            out.append((cut, found))
    return out


def striped(bgr: np.ndarray, c: BandCentroids, layers: Sequence[Tuple[float, float]],
            others: Sequence[BandCentroids] = (), boxes: Optional[Sequence[BBox]] = None) -> bool:
    """Whether the colours of ``layers`` (row spans) run on unchanged beyond the sides of ``c``.

    Columns where another candidate stands are not looked at (a touching
    neighbour shows its own bands and body there): a side is judged on what is
    left of its window 0.15-0.6 of the width out, and a side whose window a
    neighbour covers (two thirds or more) not at all. The layers run on beyond a
    judged side when they show unchanged in that window or, where the run was
    cut on that side (it ends at something other than a limb), in one of the
    ``SIDE_WINDOWS - 1`` as wide stepping outwards (0.45 of the width each, on
    what no neighbour covers): a thin thing in front of the stripes right beside
    it (a robot's mast and camera board, which often end the false "landmark")
    does not hide that they go on. Stripes: the layers show unchanged right
    beside one side judged (no background beside a real landmark lines up red
    and white with its band's and its body's rows), or beyond every side judged,
    and at least one is. Colours compare as :func:`same` does (medians, within their noise).
    ``boxes``: ``o.bbox_px`` of each of ``others``, when the caller has them.
    """
    own_boxes = (o.bbox_px for o in others) if boxes is None else boxes  # ``boxes``: the caller's, made once
    spans = [(b[0] - 1.0, b[0] + b[2] + 1.0) for o, b in zip(others, own_boxes) if o is not c]
    sides = _sides(c, spans, bgr.shape[1])
    if not sides:
        return False
    x, _, w, _ = c.bbox_px
    own: dict = {}  # each layer's own colour, measured when first needed

    def alike(rows: Tuple[float, float], span: Tuple[float, float]) -> bool:
        if rows not in own:
            own[rows] = colour(bgr, rows, (x + 0.2 * w, x + 0.8 * w))
        return same(own[rows], colour(bgr, rows, span))

    # body first: beside most real landmarks it is the background, and one differing layer ends the test
    def runs_on(span: Tuple[float, float]) -> bool:
        return all(alike(rows, span) for rows in reversed(layers))

    if any(not cut and runs_on(windows[0]) for cut, windows in sides):  # beside a limb that is none
        return True
    return all(any(map(runs_on, windows)) for _, windows in sides)
