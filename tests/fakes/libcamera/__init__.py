"""A stand-in for the parts of libcamera's Python bindings that rangebearing touches."""

from __future__ import annotations


class Transform:
    """libcamera.Transform(rotation=0, hflip=False, vflip=False, transpose=False)."""

    def __init__(self, rotation: int = 0, hflip: bool = False, vflip: bool = False,
                 transpose: bool = False) -> None:
        if rotation not in (0, 180):
            raise ValueError("fake Transform supports rotation 0 or 180 only")
        flip = rotation == 180
        self.hflip = bool(hflip) ^ flip
        self.vflip = bool(vflip) ^ flip
        self.transpose = bool(transpose)

    def __repr__(self) -> str:
        return f"<libcamera.Transform hflip={self.hflip} vflip={self.vflip}>"


class ColorSpace:
    """Enough of libcamera.ColorSpace for picamera2's default configurations."""

    def __init__(self, name: str) -> None:
        self.name = name

    @staticmethod
    def Sycc() -> ColorSpace:
        return ColorSpace("sYCC")

    @staticmethod
    def Smpte170m() -> ColorSpace:
        return ColorSpace("SMPTE170M")

    @staticmethod
    def Rec709() -> ColorSpace:
        return ColorSpace("Rec709")
