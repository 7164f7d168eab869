"""Band rows under a camera's colour denoise and 4:2:0 chroma: the inner edges come from luma."""

import cv2
import numpy as np
import pytest

from rangebearing.core.edges import edge_down, excess_luma, luma_inner
from rangebearing.core.measure import _rows, measure_rows
from rangebearing.core.structure import Candidate
from rangebearing.core.types import LandmarkGeometry
from rangebearing.synth.isp import chroma_denoise, sharpen, subsample_chroma

GEOMETRY = LandmarkGeometry()


def _landmark(bg, r0, scale=1.0, dark_rows=0.0, dark=0.05):
    """A landmark ``scale`` × (15, 40, 15) px tall from row ``r0`` on a grey ``bg`` (linear, 8× supersampled
    rows), with a dark part (``dark``, linear) across the white body's top ``dark_rows`` rows. Returns the
    120 × 80 px linear image, columns 20-59 the landmark, and the blue band's top row."""
    ss, rows = 8, 120
    y = (np.arange(rows * ss) + 0.5) / ss
    r1, b0, b1 = r0 + 15 * scale, r0 + 55 * scale, r0 + 70 * scale
    lin = np.full((rows * ss, 3), bg)
    lin[(y >= r0) & (y < r1)] = (0.70, 0.07, 0.06)
    lin[(y >= r1) & (y < b0)] = 0.85
    lin[(y >= r1) & (y < r1 + dark_rows)] = dark
    lin[(y >= b0) & (y < b1)] = (0.06, 0.12, 0.65)
    img = np.repeat(lin.reshape(rows, ss, 3).mean(axis=1)[:, None], 80, axis=1).astype(np.float32)
    img[:, :20] = img[:, 60:] = bg
    return img, b0


def _isp(img, denoise_px):
    """A linear image blurred by the lens (1 px, linear light), then through the ISP: luma sharpening,
    colour denoise (``denoise_px``) and 4:2:0 chroma."""
    img = cv2.GaussianBlur(img, (0, 0), 1.0)
    bgr = np.round(255 * np.clip(img[..., ::-1], 0, 1) ** (1 / 2.2)).astype(np.uint8)
    bgr = cv2.cvtColor(sharpen(cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB), 1.0), cv2.COLOR_RGB2BGR)
    return subsample_chroma(chroma_denoise(bgr, denoise_px))


def _camera(bg, offset_px, scale):
    """A landmark ``scale`` × (15, 40, 15) px tall on a grey ``bg`` (linear), its edges ``offset_px``
    below whole rows, blurred by the lens (1 px, linear light), then through the ISP: luma
    sharpening, colour denoise (1.5 px) and 4:2:0 chroma. Returns the frame, the candidate and
    the true band spacing L (rows)."""
    img, _ = _landmark(bg, 20 + offset_px, scale)
    band = round(15 * scale)
    cand = Candidate((20, 20, 40, band), (20, round(20 + 55 * scale), 40, band), 40.0 * scale,
                     False, False, False, False, 1.0)
    return _isp(img, 1.5), cand, 55 * scale


@pytest.mark.parametrize("scale", [1.0, 0.4])
def test_luma_edges_undo_the_pull_of_chroma_bleed_on_the_band_spacing(scale):
    chroma, luma = [], []
    for bg in (0.05, 0.3, 0.8):
        for offset in (0.0, 0.5):
            img, cand, spacing = _camera(bg, offset, scale)
            er, eb, lu = excess_luma(img[:, 33:47], (1.0, 1.0, 1.0))
            a, b = _rows(cand, GEOMETRY, 0, er, eb), _rows(cand, GEOMETRY, 0, er, eb, lu=lu)
            chroma.append(a.blue_y_px - a.red_y_px - spacing)
            luma.append(b.blue_y_px - b.red_y_px - spacing)
    # the chroma edges alone put the bands closer together (range long); luma keeps L within ~0.2 px
    assert np.mean(chroma) < -0.2
    assert abs(np.mean(luma)) < 0.1 and np.mean(np.abs(luma)) < 0.5 * np.mean(np.abs(chroma))


def test_measure_rows_keeps_the_band_spacing_and_white_height_through_the_isp():
    img, cand, spacing = _camera(0.3, 0.3, 1.0)
    rows = measure_rows(img, cand, (1.0, 1.0, 1.0), GEOMETRY, 39.5)
    assert rows.blue_y_px - rows.red_y_px == pytest.approx(spacing, abs=0.3)
    assert rows.white_px == pytest.approx(40.0, abs=0.3)


def _luma_profile(edge, band=0.2, white=0.8, n=40):
    """Band luma above row ``edge`` (sub-pixel, linear mixing), white body below."""
    cover = np.clip(edge - (np.arange(n) - 0.5), 0.0, 1.0)
    return (white + (band - white) * cover).astype(np.float32)


@pytest.mark.parametrize("offset", [0.0, 0.7, 1.6])
def test_the_luma_edge_is_taken_when_the_chroma_edge_lies_a_little_into_the_body(offset):
    p = _luma_profile(20.3)
    assert luma_inner(p, 20.3 + offset, True, 8.0) == pytest.approx(20.3, abs=1e-4)
    q = p[::-1].copy()  # the blue band's inner edge: the body above it
    assert luma_inner(q, 39 - 20.3 - offset, False, 8.0) == pytest.approx(39 - 20.3, abs=1e-4)


@pytest.mark.parametrize("offset", [2.5, 3.0, 3.5])
def test_a_chroma_edge_bled_3_px_into_the_body_still_takes_the_luma_edge_in_a_tall_enough_band(offset):
    # video coding smears chroma 3-4 px into the body: the luma edge lies inside the chroma-bled band
    p = _luma_profile(20.3)
    assert luma_inner(p, 20.3 + offset, True, 10.0) == pytest.approx(20.3, abs=0.35)
    q = p[::-1].copy()
    assert luma_inner(q, 39 - 20.3 - offset, False, 10.0) == pytest.approx(39 - 20.3, abs=0.35)
    # ... but never past the band's middle: a 5 px band cannot have bled 2.5 px or more
    assert luma_inner(p, 20.3 + offset, True, 5.0) is None


@pytest.mark.parametrize("offset", [1.0, 2.0, 3.0])
def test_the_luma_edge_is_taken_when_coarse_coding_drew_the_chroma_edge_back_into_the_band(offset):
    # MJPEG and video blocks move a band's chroma edge into the band as well as into the body
    p = _luma_profile(20.3)
    assert luma_inner(p, 20.3 - offset, True, 8.0) == pytest.approx(20.3, abs=1e-4)
    q = p[::-1].copy()
    assert luma_inner(q, 39 - 20.3 + offset, False, 8.0) == pytest.approx(39 - 20.3, abs=1e-4)


def test_a_luma_edge_far_from_the_chroma_one_is_not_taken():
    # a dark part in front of the body, below the band: luma steps 5 rows lower than the band ends,
    # past the middle of an 8-row band either way
    p = _luma_profile(25.3)
    assert luma_inner(p, 20.3, True, 8.0) is None
    assert luma_inner(_luma_profile(15.3), 20.3, True, 8.0) is None
    assert luma_inner(_luma_profile(20.3, band=0.7), 20.3, True, 8.0) is None  # no luma step at all


def _dark_below_red(rows_dark, part=0.05):
    """:func:`_camera`'s landmark (scale 1, grey 0.3, 1.5 px colour denoise) with a dark part in front
    of the white body's top ``rows_dark`` rows, right below the red band (a nearer robot's board)."""
    img, _ = _landmark(0.3, 20.3, dark_rows=rows_dark, dark=part)
    cand = Candidate((20, 20, 40, 15), (20, 75, 40, 15), 40.0, False, False, False, False, 1.0)
    return _isp(img, 1.5), cand


@pytest.mark.parametrize("rows_dark", [2.0, 3.0])
def test_a_dark_part_across_the_body_below_the_red_band_is_not_taken_for_its_edge(rows_dark):
    # its luma step lies within the inner edge's reach, but the red band would read 17-18 rows on a
    # 37-38 row body: the proportions keep the chroma's edge
    img, cand = _dark_below_red(rows_dark)
    rows = measure_rows(img, cand, (1.0, 1.0, 1.0), GEOMETRY, 39.5)
    assert not rows.red_luma and rows.red_px == pytest.approx(15.0, abs=0.6)
    assert rows.blue_y_px - rows.red_y_px == pytest.approx(55.0, abs=0.6)


def _sharpened(edge, band=0.1, white=0.4, n=40):
    """Band luma above row ``edge``, the white body below, blurred by the lens (0.5 px) and sharpened
    by the camera (unsharp mask, amount 2, radius 1 px): a bright lobe beside the edge on the body's
    side, a dark one on the band's."""
    ss = 16
    y = (np.arange(n * ss) + 0.5) / ss - 0.5
    f = cv2.GaussianBlur(np.where(y < edge, band, white).astype(np.float32).reshape(-1, 1), (0, 0), 0.5 * ss)
    p = f.reshape(n, ss).mean(axis=1)
    return (p + 2.0 * (p - cv2.GaussianBlur(p.reshape(-1, 1), (0, 0), 1.0).ravel())).astype(np.float32)


@pytest.mark.parametrize("edge", [20.0, 20.25, 20.5, 20.75])
def test_a_sharpened_luma_edge_is_its_half_level_crossing(edge):
    # lobes of ~20 % of the step: the two-level integral over the window (which holds them unevenly) put
    # the edge up to 0.17 row into the band; the crossing of the half level stays within a tenth of a row
    p = _sharpened(edge)
    a, z = round(edge + 0.8 - 4), round(edge + 0.8 + 4)
    integral = edge_down(p, a, z, float(p[a - 1 : a + 2].mean()), float(p[z : z + 4].mean()))
    assert luma_inner(p, edge + 0.8, True, 8.0) == pytest.approx(edge, abs=0.1)
    assert abs(luma_inner(p, edge + 0.8, True, 8.0) - edge) < abs(integral - edge)
    q = p[::-1].copy()  # the blue band's inner edge: the body above it
    assert luma_inner(q, 39 - edge - 0.8, False, 8.0) == pytest.approx(39 - edge, abs=0.1)


def test_an_unsharpened_luma_edge_stays_the_two_level_integral():
    p = _luma_profile(20.3)  # no lobes: the integral is exact, the crossing of linear interpolation is not
    assert luma_inner(p, 20.8, True, 8.0) == pytest.approx(20.3, abs=1e-4)


def _hidden_blue(denoise_px, hide_from_px=8.0, front=0.55):
    """:func:`_camera`'s landmark (scale 1, grey 0.3) with a nearer robot's pale body hiding the blue band
    below ``hide_from_px`` of it, through a colour denoise of ``denoise_px``."""
    img, b0 = _landmark(0.3, 20.3)
    img[int(b0 + hide_from_px) + 1 :, :] = front
    cand = Candidate((20, 20, 40, 15), (20, 75, 40, 15), 40.0, False, False, False, False, 1.0)
    return _isp(img, denoise_px), cand


def test_a_partly_hidden_blue_band_is_known_from_the_luma_when_chroma_bled_the_white_body_short():
    # a 3 px colour denoise bleeds the bands 1.5 px each into the body: the chroma white reads 37 of 40 px,
    # more than WHITE_MATCH off the search's, so only the luma's white says the inner edges are the body's;
    # the blue band's lower half hidden must then be placed from its inner edge (was 3.8 px short in L)
    img, cand = _hidden_blue(3.0)
    rows = measure_rows(img, cand, (1.0, 1.0, 1.0), GEOMETRY, 39.5)
    assert rows.blue_merged and rows.white_px == pytest.approx(40.0, abs=0.5)
    assert rows.blue_y_px - rows.red_y_px == pytest.approx(55.0, abs=0.8)
