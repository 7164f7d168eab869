"""Band rows under hard light: a dark band (dim, backlit) and a demosaic fringe at a bright background."""

import numpy as np
import pytest

from rangebearing.core.edges import band_rows
from rangebearing.core.measure import _band


def profile(level, white, above, band=(20, 45), rows=130, cols=6):
    """(rows, cols) red-excess array: ``above`` over the band, the band at ``level``, the white body below."""
    p = np.full(rows, white, np.float32)
    p[: band[0]] = above
    p[band[0] : band[1]] = level
    return np.repeat(p[:, None], cols, axis=1)


@pytest.mark.parametrize("level", [0.021, 0.06, 0.3])
def test_a_dark_band_still_steps_from_the_white_body(level):
    # backlit: the band reads (28, 30, 58) BGR, 0.021 above a dark grey body in linear light
    p2d = profile(level, 0.1 * level, -0.5 * level)
    edges = band_rows(p2d, 26, 38, True, 58, 12)
    assert edges is not None
    assert edges.inner == pytest.approx(44.5, abs=0.05)
    assert edges.centre == pytest.approx(32.0, abs=0.05)


def test_a_band_two_stops_under_steps_from_the_white_body():
    # a frame 2 stops under (photoreal-alt): the red band reads V ~25, 0.0045 above the body in linear light,
    # nine times the column-mean profile's noise there (0.0005 a row): the gamma's slope, not the noise, made it small
    rng = np.random.default_rng(18034)
    p2d = profile(0.0045, 0.0, -0.002) + rng.normal(0.0, 0.0005, (130, 1)).astype(np.float32)
    edges = band_rows(p2d, 26, 38, True, 58, 12)
    assert edges is not None
    assert edges.inner == pytest.approx(44.5, abs=0.5)


def test_no_colour_step_is_no_band_however_dark():
    p2d = profile(0.004, 0.003, -0.01)  # a faintly red-grey surface, no band
    assert band_rows(p2d, 26, 38, True, 58, 12) is None


def test_a_one_row_fringe_at_a_bright_background_does_not_seed_the_band():
    # a bright window above the band leaves a demosaic fringe row far redder than the band itself
    # (rows from a backlit frame: the fringe row is cut off from the band by a weak one)
    p2d = profile(0.029, 0.005, -0.017, band=(21, 45))
    p2d[17:21] = np.array([-0.065, 0.001, 0.047, 0.012], np.float32)[:, None]
    edges = _band(p2d, p2d.mean(axis=1), 32.5, 25.0, 67.0, True)
    assert edges is not None
    assert edges.centre == pytest.approx(32.5, abs=0.8)  # the fringe itself biases the outer edge a little



def test_a_region_with_no_excess_is_no_band_even_where_the_white_body_reads_lower():
    # an all-red room: the blue "band" rows read -0.0024 (no blue at all), the body above -0.008, and the
    # tile ends right after the band's core (the frame's edge): nothing to measure, and no division by zero
    p2d = np.full((15, 6), -0.008, np.float32)
    p2d[11:] = -0.0024
    assert band_rows(p2d, 13, 20, False, 8, 20) is None
