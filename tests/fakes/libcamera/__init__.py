"""A stand-in for the parts of libcamera's Python bindings that rangebearing touches."""

from __future__ import annotations

import enum


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
    """libcamera.ColorSpace: primaries, transfer function, Y'CbCr encoding and range (pybind11 enums, ``.name``)."""

    class Primaries(enum.Enum):
        Raw = 0
        Smpte170m = 1
        Rec709 = 2
        Rec2020 = 3

    class TransferFunction(enum.Enum):
        Linear = 0
        Srgb = 1
        Rec709 = 2

    class YcbcrEncoding(enum.Enum):
        Null = 0  # "None" in C++
        Rec601 = 1
        Rec709 = 2
        Rec2020 = 3

    class Range(enum.Enum):
        Full = 0
        Limited = 1

    def __init__(self, name: str, primaries: Primaries, transfer: TransferFunction, encoding: YcbcrEncoding,
                 range_: Range) -> None:
        self.name = name
        self.primaries, self.transferFunction, self.ycbcrEncoding, self.range = primaries, transfer, encoding, range_

    def __eq__(self, other: object) -> bool:
        return isinstance(other, ColorSpace) and (
            (self.primaries, self.transferFunction, self.ycbcrEncoding, self.range)
            == (other.primaries, other.transferFunction, other.ycbcrEncoding, other.range))

    def __hash__(self) -> int:
        return hash((self.primaries, self.transferFunction, self.ycbcrEncoding, self.range))

    @staticmethod
    def Sycc() -> ColorSpace:
        c = ColorSpace
        return c("sYCC", c.Primaries.Rec709, c.TransferFunction.Srgb, c.YcbcrEncoding.Rec601, c.Range.Full)

    @staticmethod
    def Smpte170m() -> ColorSpace:
        c = ColorSpace
        return c("SMPTE170M", c.Primaries.Smpte170m, c.TransferFunction.Rec709, c.YcbcrEncoding.Rec601,
                 c.Range.Limited)

    @staticmethod
    def Rec709() -> ColorSpace:
        c = ColorSpace
        return c("Rec709", c.Primaries.Rec709, c.TransferFunction.Rec709, c.YcbcrEncoding.Rec709, c.Range.Limited)
