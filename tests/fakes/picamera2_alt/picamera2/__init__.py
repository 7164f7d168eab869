"""Clean-room fake of the `picamera2` package (the real one's public names; see picamera2_alt_rig for the world).

Real package: picamera2/__init__.py exports Picamera2, MappedArray, CompletedRequest, TimeoutError (from
concurrent.futures), CancelledError, formats.
"""

from concurrent.futures import CancelledError, TimeoutError  # re-exported as the real one does

from . import formats
from .colour import ColorSpace
from .picamera2 import Picamera2
from .request import CompletedRequest, MappedArray

__all__ = ["CancelledError", "ColorSpace", "CompletedRequest", "MappedArray", "Picamera2", "TimeoutError",
           "formats"]


def _apply_rig() -> None:
    import picamera2_alt_rig

    picamera2_alt_rig.configure_from_env()


_apply_rig()
