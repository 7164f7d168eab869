"""Where a band's rows are in its row profile: the band-sized run of strongest colour, next to the body.

:func:`.edges.band_rows` measures a band's edges from rows known to lie inside it; this finds
those rows in a profile that may also hold a background of the band's hue beyond its outer
edge, a bright background's demosaic fringe, or a neighbour's part.
"""

from __future__ import annotations

import dataclasses
import functools
from typing import Optional

import numpy as np

from .edges import BandEdges, band_rows

RUN_SLACK_PX = 2  # a band's run of strong colour may be this much longer than the band (blur)


@functools.lru_cache(maxsize=64)
def box_kernel(k: int) -> np.ndarray:
    """The ``k``-row box kernel of :func:`seeded_band` (float32, read-only)."""
    box = np.full(k, 1.0 / k, np.float32)
    box.flags.writeable = False
    return box


def seeded_band(p2d: np.ndarray, p: np.ndarray, expected: float, hb: float, hw: float, red: bool,
                column_sigma: bool = True) -> Optional[BandEdges]:
    """:func:`.edges.band_rows` of one band around its rows of strongest colour near ``expected``.

    ``p2d``: the band's weighted excess tile (rows, columns), ``p`` its row profile; ``hb``/``hw``:
    the band's and the white body's expected heights (rows); ``red``: the white body lies below.
    ``None`` when the band shows no colour step at the body.
    """
    n = p2d.shape[0]
    lo, hi = max(0, int(expected - 0.5 * hb - 3)), min(n, int(expected + 0.5 * hb + 4))
    if hi <= lo:
        return None
    prof = p[lo:hi]  # rows' means do not depend on the other rows
    # seed on the band-sized run of strongest colour, not the strongest row: a bright background
    # beyond the outer edge leaves a one-row demosaic fringe that can beat the band's own level
    k = max(1, int(0.5 * hb + 0.5))
    k = min(k, len(prof))  # a tile cut short at the frame edge: np.convolve "same" returns the longer length
    smooth = np.convolve(prof, box_kernel(k), mode="same") if k > 1 else prof
    top = int(np.argmax(smooth))
    strong = (prof >= 0.5 * smooth[top]).tolist()  # Python bools: the walks below index them one by one
    first, last = top, top  # the band's rows: the run of strong colour around the strongest row
    while first > 0 and strong[first - 1]:
        first -= 1
    while last < len(strong) - 1 and strong[last + 1]:
        last += 1
    half = max(0, int(0.5 * hb - 1.5))
    into_white = round(min(0.5 * hb + 4, 0.5 * hb + 0.4 * hw))  # past the blurred edge, no farther
    beyond = round(0.5 * hb + 3)

    def measured(mid: int) -> Optional[BandEdges]:
        if red:
            return band_rows(p2d, mid - half, mid + half, True, mid + into_white, mid - beyond, p, column_sigma)
        return band_rows(p2d, mid - half, mid + half, False, mid - into_white, mid + beyond, p, column_sigma)

    band = measured(lo + (first + last) // 2)
    # a run much longer than a band that ends merged may hold a background of the band's hue beyond its outer
    # edge (behind a backlit, dark band it can reach half the band's level): the run's centre then sits off
    # the band, its level is read half on that background and its inner edge a row into the white body.
    # The band's own rows are then the band's height of the run next to the body
    if band is not None and band.merged and last - first + 1 > hb + RUN_SLACK_PX:
        size = int(hb + 0.5)
        anchored = measured(lo + ((2 * last - size + 1) if red else (2 * first + size - 1)) // 2)
        band = anchored if anchored is not None else band
    return band


BODY_RISE = 1.5  # the white body's luma over a band's, at the least (paint: 3-10×; blur and noise eat some)


def body_side(p: np.ndarray, band: BandEdges, red: bool, hb: float) -> BandEdges:
    """A merged band as its luma profile ``p`` shows it against the white body (``red``: the body lies below).

    The white body outshines a band in any light, so the luma rises across every band's inner edge.
    Where it clearly falls instead (by ``BODY_RISE``: a shadow or a part in front of the body dims it
    less), the run of strong colour the seed took was a background of the band's hue and stronger in
    colour than it (an orange brick wall behind a crimson band, a cyan wall behind a navy
    one), and its edge was the band's outer one: the band is the darker run between it and the body,
    its inner edge where the luma rises to the body within ``1.5·hb + 2`` rows (half-level crossing).
    Where the luma neither rises nor falls across the edge, the edge sits inside the band (the seed's run
    went on into a dim band before a redder wall) or inside the body (the chroma bled 2-4 rows into it):
    the search then starts a band's height on the band's side, past the band's darkest rows, and the band
    is placed the same way. Placed as merged all the same. Bands seen whole, bands whose luma rises across
    the edge (the body's) or with no such rise are returned unchanged.
    """
    s, n = (1 if red else -1), len(p)
    a, b = round(band.inner - 1.5 * s), round(band.inner + 1.5 * s)  # a row on each side of the edge
    if not band.merged or not (min(a, b) >= 0 and max(a, b) < n) or p[b] >= BODY_RISE * p[a]:
        return band  # the luma rises across the edge: the body's
    # it falls (the seed's run ended at the band's outer edge) or stays level (it ended inside the band or
    # the body): the search then starts a band's height on the band's side, past its darkest rows
    falls = BODY_RISE * p[b] < p[a]
    start = b if falls else min(n - 1, max(0, round(band.inner - s * hb)))
    end = min(n - 1, max(0, round(band.inner + s * (1.5 * hb + 2))))
    seg = p[start : end + 1] if red else p[end : start + 1][::-1]  # from the edge into the body
    k = int(np.argmin(seg))
    low, white = float(seg[k]), float(seg[k:].max())
    if not white > BODY_RISE * max(low, 1e-6):
        return band
    half = 0.5 * (low + white)
    j = k + int(np.argmax(seg[k:] >= half))  # the first row at half the body's luma, past the band's darkest
    if j == 0:
        return band
    x = j - 1 + float((half - seg[j - 1]) / (seg[j] - seg[j - 1]))  # ... interpolated from the row before
    inner = start + s * x
    return dataclasses.replace(band, inner=inner, centre=inner)
