"""Pixel format names (picamera2/formats.py)."""

YUV_FORMATS = {"NV21", "NV12", "YUV420", "YVU420", "YVYU", "YUYV", "UYVY", "VYUY"}
RGB_FORMATS = {"BGR888", "RGB888", "XBGR8888", "XRGB8888", "RGB161616", "BGR161616"}
BAYER_FORMATS = {p + b for p in ("SBGGR", "SGBRG", "SGRBG", "SRGGB") for b in ("8", "10", "10_CSI2P", "12",
                                                                              "12_CSI2P", "16")}
MONO_FORMATS = {"R8", "R10", "R12", "R16", "R8_CSI2P", "R10_CSI2P", "R12_CSI2P"}


def is_YUV(fmt: str) -> bool:
    return fmt in YUV_FORMATS


def is_RGB(fmt: str) -> bool:
    return fmt in RGB_FORMATS


def is_raw(fmt: str) -> bool:
    return fmt in BAYER_FORMATS or fmt in MONO_FORMATS
