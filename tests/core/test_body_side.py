"""A merged band's inner edge must be where the luma rises to the white body (core/band_seed.body_side)."""

import math

import numpy as np
import pytest

from rangebearing.core.band_seed import body_side
from rangebearing.core.edges import BandEdges


def _profile(wall=0.3, band=0.08, white=0.5, n=50):
    """Luma rows: a bright wall of the band's hue (rows 0-15), the band (16-24), the white body (25-49)."""
    p = np.full(n, white, np.float32)
    p[:16], p[16:25] = wall, band
    return p


def _merged(edge):
    return BandEdges(centre=edge, inner=edge, merged=True, sigma=math.nan)


def test_a_red_band_before_a_stronger_red_wall_gets_its_inner_edge_where_the_luma_rises():
    # the chroma took the wall for the band: its "inner" edge is the wall's edge with the band, where luma falls
    got = body_side(_profile(), _merged(16.0), True, 9.0)
    assert got.merged and got.inner == pytest.approx(24.5, abs=0.05)  # the step between rows 24 and 25


def test_the_same_for_a_blue_band_over_a_stronger_blue_floor():
    p = _profile()[::-1].copy()  # the body above, the band, then the floor of the band's hue
    got = body_side(p, _merged(50 - 16.0), False, 9.0)
    assert got.merged and got.inner == pytest.approx(49 - 24.5, abs=0.05)


def test_bands_whose_luma_rises_into_the_body_and_bands_seen_whole_are_unchanged():
    p = _profile()
    own = _merged(25.0)  # merged with the wall, but its inner edge is the body's
    assert body_side(p, own, True, 9.0) is own
    whole = BandEdges(centre=20.5, inner=16.0, merged=False, sigma=math.nan)
    assert body_side(p, whole, True, 9.0) is whole
    flat = _merged(16.0)  # no rise to a body within reach: nothing to place it by
    assert body_side(np.full(50, 0.3, np.float32), flat, True, 9.0) is flat


def test_a_shadow_on_the_body_next_to_a_merged_band_is_not_taken_for_the_band():
    # the body's lower part in a nearer part's shadow (luma 0.1 against 0.15-0.2): it dims the body, less
    # than a band would; the band's edge is where the luma rises from the band's darkness, not the shadow
    p = np.full(50, 0.025, np.float32)  # the blue band and the wall of its hue below, rows 41 on
    p[20:28], p[28:36], p[36:41] = 0.19, 0.11, 0.15  # the body, in the shadow, out of it
    band = _merged(36.7)  # the chroma's inner edge (bled into the body)
    got = body_side(p, band, False, 8.0)
    assert got.merged and got.inner == pytest.approx(40.5, abs=0.2)  # the step between rows 40 and 41


def test_a_seed_run_that_ended_inside_the_band_is_moved_to_where_the_luma_rises():
    # an orange wall redder than a dim crimson band: the seed's run spilled over the band's outer edge and its
    # "inner" edge landed in the band's middle, where the luma neither rises nor falls
    got = body_side(_profile(), _merged(20.0), True, 9.0)
    assert got.merged and got.inner == pytest.approx(24.5, abs=0.05)
    p = _profile()[::-1].copy()
    got = body_side(p, _merged(50 - 20.0), False, 9.0)
    assert got.merged and got.inner == pytest.approx(49 - 24.5, abs=0.05)


def test_a_merged_edge_a_little_inside_a_dim_body_goes_back_to_the_band_not_to_the_body_s_noise():
    # two stops under: the body's luma 0.06-0.09 row to row, the band 0.007; the chroma put the blue band's
    # inner edge 2 rows into the body, where the luma is level: the rise is the band's, not the body's ripples
    rng = np.random.default_rng(3)
    p = (0.075 + 0.012 * rng.standard_normal(50)).astype(np.float32)
    p[36:] = 0.007  # the band (and a dark floor), rows 36-49 below the body
    got = body_side(p, _merged(33.5), False, 10.0)
    assert got.merged and got.inner == pytest.approx(35.5, abs=0.6)
