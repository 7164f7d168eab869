"""Whether a band's two edges are its own, judged by the landmark's proportions (15 mm bands, 40 mm body).

A band seen short (a nearer robot hiding the blue band's lower part) or alone seen far too tall (a
same-hued thing past its outer edge) is placed from its inner edge and the white height instead
(:func:`hidden_blue`, :func:`overtall`), marked merged; one whose edges span 15/40 of the white height
within ``BAND_FIT`` fits (:class:`.measure.Rows`). Pure functions of :class:`.edges.BandEdges`.
"""

from __future__ import annotations

import math
from typing import Optional, Tuple

import numpy as np

from .edges import BandEdges

SHORT_BAND = 0.8  # a blue band seen shorter than this share of the red one (both 15 mm) is partly hidden
BAND_FIT = 0.15  # a band whose edges span 15/40 of the white height within this share fits (Rows.band_y)
TALL_BAND = 1.6  # a band this many times 15/40 of the white height tall has an outer edge not its own (overtall)
TALL_WHITE = 0.25  # ... judged where the white height is the structure search's within this share
CLEAR_LUMA = 0.7  # ... and the white body's luma is this even from band to band (white_clear)
CLEAR_EDGE_PX = 1.5  # ... over its rows this far inside the bands' inner edges


def as_merged(band: BandEdges) -> BandEdges:
    """``band`` marked merged: placed from its inner edge and the white height (its outer edge not its own)."""
    return BandEdges(band.centre, band.inner, True, band.sigma, band.scatter)


def band_fits(band: BandEdges, red: bool, expected_px: float) -> bool:
    """Whether a band's edges span ``expected_px`` (15/40 of the white height) within ``BAND_FIT``; a merged
    band, placed from that height, always does."""
    return band.merged or abs(band_height(band, red) - expected_px) <= BAND_FIT * expected_px


def misfit(red: BandEdges, blue: BandEdges, white: float, share: float) -> float:
    """How far the measured bands' heights are from ``share`` (15/40) of the white height, relative."""
    heights = [h for h in (band_height(red, True), band_height(blue, False)) if h > 0]
    return abs(sum(heights) / max(len(heights), 1) / max(share * white, 1e-6) - 1.0)


def band_height(band: BandEdges, red: bool) -> float:
    """A band's height between its two edges (rows); 0 when merged (its outer edge is not its own)."""
    if band.merged:
        return 0.0
    return 2.0 * (band.inner - band.centre) if red else 2.0 * (band.centre - band.inner)


def overtall(red: BandEdges, blue: BandEdges, expected_px: float, white_ok: bool) -> Tuple[BandEdges, BandEdges]:
    """The bands, one marked merged where it alone is seen ``TALL_BAND`` times ``expected_px`` (15/40 of
    the white height) tall or more while the white height is vouched for (``white_ok``: it agrees with
    the structure search's within ``TALL_WHITE`` and the body's luma is even, :func:`white_clear`) and
    the other band's edges span 15/40 of it (or that band is merged).

    A same-hued thing just beyond a band's outer edge too faint or too short for the edges to call it
    merged (a blue wall or mat in a shadow below, a neighbour's band, a coder's smear of the colour)
    makes the band look taller and the mean of its edges, and of it with the moment, moves outward: L
    long, range short, by up to ~12 %. Its inner edge, against the clear white body, is still its own:
    the band is placed from it and the white height. Both bands too tall is chroma bleed thinning the
    white body (the luma's business), so both are kept.
    """
    tall = [not b.merged and band_height(b, r) > TALL_BAND * expected_px for b, r in ((red, True), (blue, False))]
    if tall[0] == tall[1] or not white_ok:
        return red, blue
    other, r_other = (blue, False) if tall[0] else (red, True)
    if not (other.merged or band_fits(other, r_other, expected_px)):
        return red, blue
    return (as_merged(red), blue) if tall[0] else (red, as_merged(blue))


def white_clear(lp: Optional[np.ndarray], red: BandEdges, blue: BandEdges) -> bool:
    """Whether the white body's luma ``lp`` (the tile's row profile) is even between the bands' inner edges:
    its darkest row inside (``CLEAR_EDGE_PX`` off each edge, the edges' blur) at least ``CLEAR_LUMA`` of its
    brightest. A cylinder's white is lit alike from band to band; a darker stretch is something in front
    (a mast, a nearer robot's part) whose edge a band's inner edge may have taken. No luma: not judged."""
    if lp is None:
        return False
    i0, i1 = math.ceil(red.inner + CLEAR_EDGE_PX), math.floor(blue.inner - CLEAR_EDGE_PX) + 1
    inside = lp[max(i0, 0) : min(i1, lp.shape[0])]
    return inside.size >= 3 and float(inside.min()) >= CLEAR_LUMA * float(inside.max())


def hidden_blue(blue: BandEdges, expected_px: float) -> BandEdges:
    """The blue band, marked merged when it is seen shorter than ``SHORT_BAND`` of ``expected_px``.

    A nearer robot's body in front hides the lower part of a landmark behind it: the blue band's
    outer edge is then the occluder's, and the mean of its edges sits too high (L short, range long,
    by up to ~10 %). Both bands are 15 mm on one cylinder at one depth, so the red band's height (or,
    when it merged, 15/40 of the white body's) is what the blue one should measure. A red band cannot
    be hidden so: whatever hides its top hides the white body below it.
    """
    if blue.merged or band_height(blue, False) >= SHORT_BAND * expected_px:
        return blue
    return as_merged(blue)
