import cv2
import numpy as np
import pytest

from rangebearing.core.color import apply_gains, class_masks, grey_world_gains, to_hsv
from rangebearing.core.detect import _clipped, downscale
from rangebearing.core.gain_clip import pushed_over, reclass_pushed
from rangebearing.core.params import DetectionParams
from rangebearing.core.yuv import (
    BLUE,
    NONE,
    RED,
    chroma_masks,
    class_table,
    yuv420_from_bgr,
    yuv420_planes,
    yuv_grey_world_gains,
)
from rangebearing.synth import LandmarkPose, Lighting, Scene, render

DET = DetectionParams()


def patch(bgr, size=4):
    return np.full((size, size, 3), bgr, np.uint8)


def bgr_masks(bgr, gains=None):
    """The BGR fast path's unfiltered masks, for comparison."""
    small = downscale(bgr, 2)
    gains = grey_world_gains(small) if gains is None else gains
    return class_masks(to_hsv(apply_gains(small, gains)), DET.red_hue, DET.blue_hue, DET.s_min, DET.v_min)


def test_opencv_i420_is_smpte170m_limited_range():
    # pure red, white and black as the camera (and OpenCV's I420) encode them
    for bgr, yuv in (((0, 0, 255), (82, 90, 240)), ((255, 255, 255), (235, 128, 128)), ((0, 0, 0), (16, 128, 128))):
        planes = yuv420_from_bgr(patch(bgr))
        assert (int(planes.y[0, 0]), int(planes.u[0, 0]), int(planes.v[0, 0])) == yuv
        i420 = cv2.cvtColor(patch(bgr), cv2.COLOR_BGR2YUV_I420).reshape(-1)
        assert (i420[0], i420[16], i420[20]) == yuv


def test_chroma_is_the_2x2_block_mean_where_opencv_point_samples():
    block = np.zeros((2, 2, 3), np.uint8)
    block[1, 1] = (0, 0, 255)  # one red pixel of four
    planes = yuv420_from_bgr(block)
    assert cv2.cvtColor(block, cv2.COLOR_BGR2YUV_I420).reshape(-1)[4:].tolist() == [128, 128]  # it sees none
    mean = yuv420_from_bgr(np.full((2, 2, 3), (0, 0, 64), np.uint8))  # the block's mean colour
    assert (int(planes.u[0, 0]), int(planes.v[0, 0])) == (int(mean.u[0, 0]), int(mean.v[0, 0]))


@pytest.mark.parametrize("pad", [0, 32])
def test_planes_are_views_that_skip_the_stride_padding(pad):
    rng = np.random.default_rng(0)
    w, h = 8, 6
    y = rng.integers(0, 256, (h, w), np.uint8)
    u = rng.integers(0, 256, (h // 2, w // 2), np.uint8)
    v = rng.integers(0, 256, (h // 2, w // 2), np.uint8)
    stride = w + pad
    buf = np.full((h * 3 // 2, stride), 77, np.uint8)  # 77: padding that must never be read
    buf[:h, :w] = y
    chroma = buf[h:].reshape(2, h // 2, stride // 2)
    chroma[0, :, : w // 2], chroma[1, :, : w // 2] = u, v
    planes = yuv420_planes(buf, w, h)
    assert np.array_equal(planes.y, y) and np.array_equal(planes.u, u) and np.array_equal(planes.v, v)
    assert np.shares_memory(planes.y, buf) and np.shares_memory(planes.v, buf)


def test_a_buffer_of_the_wrong_shape_is_refused():
    with pytest.raises(ValueError, match="YUV420"):
        yuv420_planes(np.zeros((10, 8), np.uint8), 8, 6)  # 6 rows of Y need 9 rows in all
    with pytest.raises(ValueError, match="even"):
        yuv420_from_bgr(np.zeros((5, 8, 3), np.uint8))


@pytest.mark.parametrize(
    "bgr, cls",
    [
        ((30, 30, 200), RED),
        ((60, 20, 200), RED),  # hue wraps near 179
        ((200, 40, 30), BLUE),
        ((180, 180, 180), NONE),  # white
        ((40, 160, 40), NONE),  # green
        ((70, 110, 160), NONE),  # tan floor: too little saturation
        ((5, 5, 20), NONE),  # too dark to trust
    ],
)
def test_hand_picked_colours_classify_as_the_hsv_thresholds_do(bgr, cls):
    planes = yuv420_from_bgr(patch(bgr))
    red, blue = chroma_masks(planes, DET)
    assert (red == 255).all() == (cls == RED) and (blue == 255).all() == (cls == BLUE)
    hsv_red, hsv_blue = bgr_masks(patch(bgr), (1.0, 1.0, 1.0))
    assert np.array_equal(red, hsv_red) and np.array_equal(blue, hsv_blue)


def test_table_agrees_with_opencv_hsv_over_every_colour_of_a_grid():
    # every (B, G, R) on a 16-level grid, encoded the way the camera does, one colour per 2×2 block
    levels = np.arange(8, 256, 16, dtype=np.uint8)
    grid = np.stack(np.meshgrid(levels, levels, levels, indexing="ij"), -1).reshape(-1, 1, 3)
    bgr = np.repeat(np.repeat(grid.reshape(64, 64, 3), 2, 0), 2, 1)
    small = bgr[::2, ::2]
    planes = yuv420_from_bgr(bgr)
    red, blue = chroma_masks(planes, DET)
    # the reference: OpenCV's HSV of the colours themselves; 8-bit Y'CbCr rounding moves a few across a threshold
    ref_red, ref_blue = class_masks(to_hsv(np.ascontiguousarray(small)), DET.red_hue, DET.blue_hue, DET.s_min,
                                    DET.v_min)
    assert small.shape[:2] == red.shape
    for got, ref in ((red, ref_red), (blue, ref_blue)):
        assert np.count_nonzero(ref) > 100
        assert np.count_nonzero(got != ref) <= 0.05 * np.count_nonzero(ref)


def test_table_is_cached_and_packs_bounds_and_class():
    t = class_table("smpte170m", DET.red_hue, DET.blue_hue, DET.s_min, DET.v_min)
    assert t is class_table("smpte170m", DET.red_hue, DET.blue_hue, DET.s_min, DET.v_min)
    neutral = int(t[128 << 8 | 128])
    assert neutral >> 16 == NONE and (neutral & 255) > ((neutral >> 8) & 255)  # an empty Y range
    red = int(t[90 << 8 | 240])
    assert red >> 16 == RED and (red & 255) <= 82 <= ((red >> 8) & 255)


def _table_by_stacking(colour_space, red_hue, blue_hue, s_min, v_min):
    """class_table as first written (a (256, 256, 3) stack, hue of every U, V pair): the reference."""
    from rangebearing.core.yuv import COLOUR_SPACES, _rgb_matrix

    a, y0 = COLOUR_SPACES[colour_space][:2]
    m, _ = _rgb_matrix(colour_space)
    u, v = np.meshgrid(np.arange(256.0), np.arange(256.0), indexing="ij")
    d = np.stack([m[k, 1] * (u - 128.0) + m[k, 2] * (v - 128.0) for k in range(3)], axis=-1)
    bgr = np.ascontiguousarray(d[..., ::-1] + 256.0, dtype=np.float32)
    hue8 = np.round(cv2.cvtColor(bgr.reshape(-1, 1, 3), cv2.COLOR_BGR2HSV)[:, 0, 0].reshape(256, 256) / 2.0)
    hue8 = hue8.astype(np.int64) % 180
    chroma, top = d.max(axis=-1) - d.min(axis=-1), d.max(axis=-1)
    cls = np.zeros((256, 256), np.uint32)
    for label, ranges in ((RED, red_hue), (BLUE, blue_hue)):
        inside = np.zeros((256, 256), bool)
        for lo, hi in ranges:
            inside |= (hue8 >= lo) & (hue8 <= hi)
        cls[inside & (chroma > 0)] = label
    ylo = np.ceil(y0 + (v_min - 0.5 - top) / a)
    with np.errstate(divide="ignore"):
        yhi = np.floor(y0 + (255.0 * chroma / max(s_min - 0.5, 1e-6) - top) / a)
    empty = (ylo > yhi) | (ylo > 255) | (yhi < 0) | (cls == NONE)
    ylo = np.where(empty, 255, np.clip(ylo, 0, 255)).astype(np.uint32)
    yhi = np.where(empty, 0, np.clip(yhi, 0, 255)).astype(np.uint32)
    return (ylo | (yhi << 8) | (cls << 16)).reshape(-1)


@pytest.mark.parametrize("colour_space", ["smpte170m", "rec709"])
@pytest.mark.parametrize("hues, s_min, v_min", [
    ((((0, 10), (165, 179)), ((98, 132),)), 90, 25), ((((0, 15),), ((90, 140),)), 40, 10),
    ((((170, 179),), ((100, 120),)), 1, 0), ((((0, 179),), ((0, 179),)), 255, 255),
])
def test_table_is_the_same_as_by_stacking(colour_space, hues, s_min, v_min):
    got = class_table(colour_space, hues[0], hues[1], s_min, v_min)
    assert np.array_equal(got, _table_by_stacking(colour_space, hues[0], hues[1], s_min, v_min))


def _cast_scene():
    warm = Lighting(colour=(1.25, 1.0, 0.8)) if "colour" in Lighting.__dataclass_fields__ else Lighting()
    return Scene(landmarks=(LandmarkPose(0.5, 0.15), LandmarkPose(1.1, -0.2)), wall_distance_m=1.8, lighting=warm)


def test_masks_and_gains_match_the_bgr_path_on_a_rendered_frame():
    bgr = render(_cast_scene(), np.random.default_rng(3))
    planes = yuv420_from_bgr(bgr)
    gains = yuv_grey_world_gains(planes)
    assert gains == pytest.approx(grey_world_gains(downscale(bgr, 2)), abs=0.01)
    kernel = np.ones((3, 3), np.uint8)
    for got, ref in zip(chroma_masks(planes, DET, gains), bgr_masks(bgr)):
        n = np.count_nonzero(ref)
        assert n > 100 and abs(np.count_nonzero(got) - n) <= 0.1 * n
        edge = cv2.dilate(ref, kernel) != cv2.erode(ref, kernel)
        assert not np.any((got != ref) & ~edge)  # they differ only on the bands' outlines


def _bgr_path_masks(small, gains):
    """The BGR path's unfiltered masks with its clipped rules (pixels clipped before the gains included)."""
    hsv = to_hsv(apply_gains(small, gains))
    masks = class_masks(hsv, DET.red_hue, DET.blue_hue, DET.s_min, DET.v_min, _clipped(small, gains))
    return reclass_pushed(*masks, small, gains, pushed_over(small, gains, hsv[..., 2]), DET.red_hue, DET.blue_hue,
                          DET.s_min)


def test_clipped_colours_of_a_grid_classify_as_the_bgr_path_does():
    # every (B, G, R) on a 16-level grid with its strongest channel clipped (255): over-exposed bands read
    # orange/magenta or cyan/violet and paler than the paint; the BGR path widens their hues and halves S's floor
    levels = np.arange(15, 256, 16, dtype=np.uint8)
    grid = np.stack(np.meshgrid(levels, levels, levels, indexing="ij"), -1).reshape(-1, 3)
    grid = grid[grid.max(1) == 255].reshape(1, -1, 3)
    bgr = np.repeat(np.repeat(grid, 2, 0), 2, 1)
    ref = _bgr_path_masks(np.ascontiguousarray(bgr[::2, ::2]), (1.0, 1.0, 1.0))
    got = chroma_masks(yuv420_from_bgr(bgr), DET)
    for g, r in zip(got, ref):
        assert np.count_nonzero(r) > 20
        # 8-bit Y'CbCr rounding moves a colour lying on a threshold (S = 80, hue 83) across it
        assert np.count_nonzero(g != r) <= 0.02 * np.count_nonzero(r)


@pytest.mark.parametrize("bgr", [(150, 160, 252), (252, 200, 170)])
def test_a_band_clipped_before_a_gain_below_one_stays_clipped(bgr):
    # a gain of 0.85 on the clipped channel takes it under 250: the pixel is still clipped (color.clipped_mask),
    # so S >= s_min / 2 suffices on both paths
    gains = (0.85, 1.0, 1.0) if bgr[0] > 250 else (1.0, 1.0, 0.85)
    ref = _bgr_path_masks(patch(bgr, 2), gains)
    got = chroma_masks(yuv420_from_bgr(patch(bgr)), DET, gains)
    assert np.array_equal(got[0], ref[0]) and np.array_equal(got[1], ref[1])
    assert (ref[0] if bgr[2] > 250 else ref[1]).all()


def test_masks_match_the_bgr_path_on_an_over_exposed_frame():
    # two stops over: every band's strongest channel clips; the masks agree pixel for pixel but for rounding
    scene = Scene(landmarks=(LandmarkPose(0.5, 0.15), LandmarkPose(1.1, -0.2)), wall_distance_m=1.8,
                  lighting=Lighting(exposure=4.0))
    bgr = render(scene, np.random.default_rng(3))
    small = downscale(bgr, 2)
    assert np.count_nonzero(small.max(2) >= 250) > 0.5 * small.shape[0] * small.shape[1]
    gains = grey_world_gains(small)
    planes = yuv420_from_bgr(bgr)
    for got, ref in zip(chroma_masks(planes, DET, yuv_grey_world_gains(planes)), _bgr_path_masks(small, gains)):
        assert np.count_nonzero(ref) > 200
        assert np.count_nonzero(got != ref) <= 2


def test_a_gain_above_one_saturates_a_clipped_white_as_on_the_bgr_path():
    # clipped white under gains (1.15, 1.0, 0.87): the BGR path's blue saturates at 255, (255, 255, 222) reads
    # cyan and pale (S 33); unsaturated, the same (Y, U, V) would read blue at S 60, clipped, S >= s_min / 2
    gains = (1.15, 1.0, 0.87)
    ref = _bgr_path_masks(patch((255, 255, 255), 2), gains)
    got = chroma_masks(yuv420_from_bgr(patch((255, 255, 255))), DET, gains)
    assert not ref[1].any() and not got[1].any() and not got[0].any()


@pytest.mark.parametrize("exposure, wb", [(3.0, (1.3, 1.0, 0.8)), (3.5, (0.8, 1.0, 1.3))])
def test_masks_match_the_bgr_path_on_an_over_exposed_tinted_frame(exposure, wb):
    scene = Scene(landmarks=(LandmarkPose(0.5, 0.15), LandmarkPose(1.1, -0.2)), wall_distance_m=1.8,
                  lighting=Lighting(exposure=exposure, wb_gains=wb))
    bgr = render(scene, np.random.default_rng(3))
    small = downscale(bgr, 2)
    gains = grey_world_gains(small)
    assert max(gains) > 1.05 and min(gains) < 0.95  # a gain each way: saturated and hidden clipped channels
    planes = yuv420_from_bgr(bgr)
    for got, ref in zip(chroma_masks(planes, DET, yuv_grey_world_gains(planes)), _bgr_path_masks(small, gains)):
        assert np.count_nonzero(ref) > 200
        assert np.count_nonzero(got != ref) <= 0.01 * np.count_nonzero(ref)  # 8-bit rounding on the outlines
