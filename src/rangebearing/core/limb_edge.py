"""A band's limb: where its chromaticity falls off at the side of the cylinder, to a fraction of a column.

Split from :mod:`.edges` (the rows' edges), whose two-level integral it uses.
"""

from __future__ import annotations

from typing import Optional, Tuple

import numpy as np

from .edges import BG_ROWS, MERGE_CONTRAST, edge_down
from .stats import median

CHROMA_SPREAD_PX = 2  # a limb's chromaticity falling over more columns than this (80 % to 20 %): chroma blurred
LIMB_BLUR_PX = 3  # columns a limb's edge may be spread over (optics, sensor, the ½-resolution search)


def limb(profile: np.ndarray, core: int, end: int, level: float,
         mix: Optional[Tuple[np.ndarray, np.ndarray]] = None) -> float:
    """Sub-pixel limb column from a column profile of a band's chromaticity, going right when
    ``end > core``, else left; NaN when the band never falls to half its ``level`` (no limb to see).

    The limb is the first fall below half the band's level past ``core``; the two-level
    integral runs from just inside it to ``LIMB_BLUR_PX`` past it, against the level
    right beyond it (the median of the next ``BG_ROWS`` columns: past the blur, short
    of whatever may follow). Whatever lies farther out (a neighbour's band of the same colour,
    only partly in these rows) does not count: a band beside it can make this band look
    wider, never narrower.

    ``mix``: the column profiles ``(excess, sum)`` of the band's excess and of the linear
    channels' sum, whose ratio ``profile`` is. A chromaticity is no mix of its two sides by
    coverage: a column a share ``c`` on the band reads ``(c·E + (1−c)·E_g) / (c·S + (1−c)·S_g)``,
    which the brighter side dominates, and a cylinder's band darkens towards its limb, so a
    background brighter than the limb pulled the edge inwards (bearing 0.05-0.15° towards the
    inside on touching/crowd landmarks placed from one limb). With ``mix`` each column's
    coverage is solved from that mixture, knowing the band's chromaticity (``level``) and the
    background's brightness and chromaticity, whatever the band's own brightness there. That
    takes the chroma and the luma blurred alike: where the chromaticity takes more than
    ``CHROMA_SPREAD_PX`` columns from 80 % to 20 % of its step (a camera's 4:2:0 chroma or colour
    denoise spreads it over 5-8 px while the luma stays sharp) the mixture does not hold and the
    chromaticity's own two-level edge is taken.
    """
    step = 1 if end > core else -1
    seg = profile[core : end + 1] if step > 0 else profile[core : (end - 1 if end > 0 else None) : -1]
    fall = np.flatnonzero(seg < 0.5 * level)
    if len(fall) == 0 or fall[0] == 0:
        return float("nan")
    k = int(fall[0])
    stop = min(len(seg) - 1, k + LIMB_BLUR_PX)
    start = max(0, k - LIMB_BLUR_PX - 1)
    bg = median(seg[k + 1 : k + 1 + BG_ROWS]) if k + 1 < len(seg) else float(seg[k])
    if not level - bg > MERGE_CONTRAST * abs(level):
        return float("nan")
    rel = (seg[start : min(len(seg), stop + 2)] - bg) / (level - bg)
    if mix is None or np.count_nonzero((rel > 0.2) & (rel < 0.8)) > CHROMA_SPREAD_PX:
        edge = edge_down(seg, start, stop, level, bg)  # columns counted outwards from ``core``
    else:
        edge = _mixed_edge(*(_outwards(m, core, end, step) for m in mix), start, stop, k, level, bg)
    return core + step * edge


def _outwards(profile: np.ndarray, core: int, end: int, step: int) -> np.ndarray:
    """``profile`` from column ``core`` to ``end``, outwards (as :func:`limb` reads it)."""
    return profile[core : end + 1] if step > 0 else profile[core : (end - 1 if end > 0 else None) : -1]


def _mixed_edge(e: np.ndarray, s: np.ndarray, start: int, stop: int, k: int, level: float, bg: float) -> float:
    """:func:`limb`'s edge (columns outwards) from each column's band coverage in the chromaticity mixture
    ``q = (c·E + (1−c)·E_g) / (c·S + (1−c)·S_g)`` with the band's chromaticity ``level`` and the
    background's ``bg``: ``c = 1 − (level·S − E) / (S_g·(level − bg))``, ``S_g`` the background's sum, from a
    column farther out than ``bg``'s: a band darker than its background has its chromaticity fall below half
    while the column is still mostly band, so the next column or two are still mixed in brightness."""
    s_g = median(s[k + 2 : k + 2 + BG_ROWS]) if k + 2 < len(s) else float(s[-1])
    if not s_g > 0:
        return edge_down(e / np.maximum(s, 1e-6), start, stop, level, bg)
    c = 1.0 - (level * s[start : stop + 1] - e[start : stop + 1]) / (s_g * (level - bg))
    return (start - 0.5) + float(np.add.reduce(np.clip(c, 0.0, 1.0)))
