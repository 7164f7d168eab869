"""The camera behind the lens: blur, noise, exposure, Bayer mosaic, lens and ISP stages."""

from __future__ import annotations

from typing import List, Optional, Tuple

from .._compat import frozen

TONES = ("gamma", "srgb", "filmic")


@frozen
class Imaging:
    """The sensor and lens: blur, noise (in linear units of full scale) and gamma.

    ``auto_exposure``: the exposure is set from the scene's metered brightness
    (centre-weighted mean luminance brought to ``ae_target``, times
    ``ae_error`` for a loop not quite settled, within ``ae_limits``), and noise
    grows with the gain it needs. ``bayer``: noise is drawn per photosite of an
    RGGB mosaic that is then demosaiced (colour fringes at band edges).
    ``glare``: the fraction of light scattered into a wide halo (veiling glare
    from a bright window). ``edge_supersample`` > 0: edges away from every
    landmark get that many rays squared instead of the renderer's full count.
    ``vignetting``: the fraction of light lost in the image corners (cos⁴-like).

    The lens and ISP of :mod:`.optics` and :mod:`.isp` (all off by default):
    ``focus_m`` > 0 defocuses by depth (thin lens focused there, aperture
    ``aperture_m``); ``soft_corners_px`` widens the blur towards the corners;
    ``lateral_colour`` scales red and blue about the centre by ±that; ``ccm``
    (9 numbers, row-major) mixes the colours on the sensor and unmixes them
    after the noise; ``awb_pull`` pulls the white balance towards the frame's
    grey world; ``demosaic`` is ``"ea"`` (edge-aware) or ``"bilinear"``;
    ``chroma_denoise_px`` smooths colour (not luma) by that sigma; ``sharpen``
    is the ISP's luma sharpening strength; ``chroma_420`` keeps colour at half
    resolution; ``jpeg_quality`` > 0 passes the frame through JPEG.
    ``exposure_s`` > 0: moving landmarks (``LandmarkPose.velocity_mps``) blur
    over that exposure time (see :func:`.render.render`).

    Another camera's choices (:mod:`.photoreal_alt`, all off by default):
    ``tone`` is the curve from linear light to 8 bits: ``"gamma"`` (``gamma``
    alone), ``"srgb"`` (the piecewise sRGB curve) or ``"filmic"`` (an ACES-like
    shoulder, then sRGB); ``pan_blur_px`` blurs the whole frame horizontally
    over that many pixels (the observing robot turning during the exposure);
    ``barrel_k1`` warps the image radially by ``1 + k1·r²`` (normalised
    coordinates) that the detector's camera does not know of (a calibration's
    residual); ``h264_quality`` > 0 keeps colour in 2×2 blocks (4:2:0 without
    interpolation) and passes the frame through a coarse block coder at that quality.
    """

    blur_sigma_px: float = 0.0
    read_noise: float = 0.0
    shot_noise: float = 0.0
    gamma: float = 1.0 / 2.2
    auto_exposure: bool = False
    ae_target: float = 0.18
    ae_error: float = 1.0
    ae_limits: Tuple[float, float] = (0.01, 16.0)
    bayer: bool = False
    glare: float = 0.0
    edge_supersample: int = 0
    vignetting: float = 0.0
    focus_m: float = 0.0
    aperture_m: float = 0.00124
    soft_corners_px: float = 0.0
    lateral_colour: float = 0.0
    ccm: Optional[Tuple[float, ...]] = None
    awb_pull: float = 0.0
    demosaic: str = "ea"
    chroma_denoise_px: float = 0.0
    sharpen: float = 0.0
    chroma_420: bool = False
    jpeg_quality: int = 0
    exposure_s: float = 0.0
    tone: str = "gamma"
    pan_blur_px: float = 0.0
    barrel_k1: float = 0.0
    h264_quality: int = 0

    @property
    def isp(self) -> bool:
        """Whether any lens or ISP stage of :mod:`.optics` / :mod:`.isp` is on."""
        return (self.focus_m > 0 or self.soft_corners_px > 0 or self.lateral_colour != 0
                or self.ccm is not None or self.awb_pull > 0 or self.demosaic != "ea"
                or self.chroma_denoise_px > 0 or self.sharpen > 0 or self.chroma_420 or self.jpeg_quality > 0
                or self.pan_blur_px > 0 or self.barrel_k1 != 0 or self.h264_quality > 0)


def imaging_problems(im: Imaging) -> List[str]:
    """What is wrong with a camera description (empty: nothing)."""
    out = []
    if im.demosaic not in ("ea", "bilinear"):
        out.append(f"imaging.demosaic must be 'ea' or 'bilinear', got {im.demosaic!r}")
    if not 0 <= im.jpeg_quality <= 100:
        out.append(f"imaging.jpeg_quality must be 0-100, got {im.jpeg_quality}")
    if im.focus_m < 0 or im.aperture_m < 0:
        out.append("imaging.focus_m and aperture_m must be >= 0")
    if im.tone not in TONES:
        out.append(f"imaging.tone must be one of {', '.join(TONES)}, got {im.tone!r}")
    if not 0 <= im.h264_quality <= 100:
        out.append(f"imaging.h264_quality must be 0-100, got {im.h264_quality}")
    if im.pan_blur_px < 0 or abs(im.barrel_k1) > 0.5:
        out.append("imaging.pan_blur_px must be >= 0 and |barrel_k1| <= 0.5")
    if im.ccm is not None and len(im.ccm) != 9:
        out.append(f"imaging.ccm must hold 9 numbers, got {len(im.ccm)}")
    return out
