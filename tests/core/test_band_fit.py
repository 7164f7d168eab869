"""band_fit: a band seen too tall for the white body (a same-hued thing past its outer edge) or too short
(hidden below) is placed from its inner edge and the white height; the proportion checks."""

import numpy as np
import pytest
from tests.core.test_luma_rows import _isp, _landmark

from rangebearing.core.band_fit import band_fits, band_height, hidden_blue, overtall, white_clear
from rangebearing.core.edges import BandEdges
from rangebearing.core.measure import measure_rows
from rangebearing.core.structure import Candidate
from rangebearing.core.types import LandmarkGeometry

GEOMETRY = LandmarkGeometry()


def _blue_below(rows_below, colour=(0.05, 0.1, 0.65), scale=0.5):
    """:func:`_landmark` (``scale`` × (15, 40, 15) px, grey 0.3, red band from row 20.3) with a thing of the
    blue paint (a neighbour's band, a blue mat) ``rows_below`` rows tall right below its blue band, through
    the ISP (1.5 px colour denoise, 4:2:0 chroma). Returns the frame, the candidate and the true spacing L."""
    img, b0 = _landmark(0.3, 20.3, scale=scale)
    start = int(np.ceil(b0 + 15 * scale))
    img[start : start + rows_below, 20:60] = colour
    band = round(15 * scale)
    cand = Candidate((20, 20, 40, band), (20, round(20 + 55 * scale), 40, band), 40.0 * scale,
                     False, False, False, False, 1.0)
    return _isp(img, 1.5), cand, 55 * scale


def test_a_blue_band_run_on_by_a_blue_thing_below_is_placed_from_its_inner_edge():
    # 4 rows of blue below a 7.5 row band: its edges span 12.5 rows on a 20 row body (7.5 expected), their
    # mean with the moment puts it 2.8 rows low (L 10 % long); the inner edge and the white height put it
    # within half a row
    img, cand, spacing = _blue_below(4)
    rows = measure_rows(img, cand, (1.0, 1.0, 1.0), GEOMETRY, 39.5)
    assert rows.blue_merged and rows.white_px == pytest.approx(20.0, abs=0.3)
    assert rows.blue_y_px - rows.red_y_px == pytest.approx(spacing, abs=0.5)


def _band(centre, inner, merged=False):
    return BandEdges(centre, inner, merged, 0.1)


def test_overtall_places_the_tall_band_only_where_the_other_one_fits_the_white_body():
    red, blue = _band(7.5, 15.0), _band(68.0, 55.0)  # red 15 rows (fits 40), blue 26
    placed = overtall(red, blue, 15.0, True)
    assert placed[0] is red and placed[1].merged and placed[1].inner == 55.0
    assert overtall(red, blue, 15.0, False) == (red, blue)  # the white body not vouched for
    assert overtall(_band(3.0, 15.0), blue, 15.0, True)[1] is blue  # both tall: chroma bleed, not judged
    assert overtall(red, _band(64.0, 55.0), 15.0, True)[1].merged is False  # 18 rows: within TALL_BAND


def test_white_clear_needs_the_body_even_from_band_to_band():
    lp = np.full(80, 0.8, np.float32)
    red, blue = _band(7.5, 15.0), _band(62.5, 55.0)
    assert white_clear(lp, red, blue)
    lp[40:50] = 0.3  # a mast across the body's lower rows
    assert not white_clear(lp, red, blue)
    lp[40:50] = 0.8
    lp[15], lp[55] = 0.3, 0.3  # the edges' own blur does not count
    assert white_clear(lp, red, blue)
    assert not white_clear(None, red, blue)


def test_a_band_fits_within_band_fit_of_its_share_and_a_short_blue_one_is_hidden():
    red = _band(7.5, 15.0)  # 15 rows
    assert band_height(red, True) == 15.0 and band_fits(red, True, 15.0) and band_fits(red, True, 17.5)
    assert not band_fits(red, True, 20.0)  # 25 % short of 20: not within BAND_FIT
    assert band_fits(_band(7.5, 15.0, merged=True), True, 40.0)  # placed from the white height: always fits
    short = _band(60.0, 55.0)  # 10 rows where the red band shows 15: its lower part hidden
    assert hidden_blue(short, 15.0).merged and hidden_blue(short, 15.0).inner == 55.0
    assert hidden_blue(_band(62.0, 55.0), 15.0) == _band(62.0, 55.0)  # 14 rows: within SHORT_BAND
