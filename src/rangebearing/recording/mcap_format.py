"""What a rangebearing MCAP file holds: topics, schemas and the JSON messages (pure: no I/O).

Every channel uses JSON message encoding with a JSON Schema, which Foxglove and
the ``mcap`` tools read without generated code:

- ``/camera/image`` — ``foxglove.CompressedImage``: PNG (bit-exact) or JPEG bytes,
  base64 in ``data`` as Foxglove's JSON encoding wants; ``timestamp`` is the
  capture time. The MCAP ``log_time`` is the same instant in Unix ns and the
  message ``sequence`` the source's frame index.
- ``/camera/calibration`` — ``foxglove.CameraCalibration``: the intrinsics, one
  message at the start (``plumb_bob`` distortion, OpenCV's k1 k2 p1 p2 k3).
- ``/rangebearing/readings`` — exactly the wire-format v1 JSON of each reading,
  with ``schema/reading-v1.json`` attached; ``log_time`` is the reading's ``t``.

The schemas of the two Foxglove types are copies of foxglove-sdk's
``schemas/jsonschema`` (MIT licence).
"""

from __future__ import annotations

import base64
import json
from importlib import resources
from typing import Any, Dict, Tuple

from .._compat import frozen
from ..core.types import CameraIntrinsics
from ..errors import RecordingError

IMAGE_TOPIC = "/camera/image"
CALIBRATION_TOPIC = "/camera/calibration"
READINGS_TOPIC = "/rangebearing/readings"
FRAME_ID = "camera"
PROFILE = ""  # no ROS profile: plain JSON channels
FORMATS = ("png", "jpeg")

# topic -> (schema name, schema file in rangebearing/schema)
SCHEMAS: Dict[str, Tuple[str, str]] = {
    IMAGE_TOPIC: ("foxglove.CompressedImage", "foxglove.CompressedImage.json"),
    CALIBRATION_TOPIC: ("foxglove.CameraCalibration", "foxglove.CameraCalibration.json"),
    READINGS_TOPIC: ("rangebearing.Reading.v1", "reading-v1.json"),
}


def schema_bytes(file_name: str) -> bytes:
    """A schema file shipped in ``rangebearing/schema``, compacted."""
    text = resources.files("rangebearing").joinpath("schema", file_name).read_text("utf-8")
    return json.dumps(json.loads(text), separators=(",", ":")).encode("utf-8")


def _stamp(t_ns: int) -> Dict[str, int]:
    sec, nsec = divmod(int(t_ns), 1_000_000_000)
    return {"sec": sec, "nsec": nsec}


def _dumps(msg: Dict[str, Any]) -> bytes:
    return json.dumps(msg, separators=(",", ":"), allow_nan=False).encode("ascii")


def image_message(data: bytes, fmt: str, t_ns: int) -> bytes:
    """A ``foxglove.CompressedImage`` holding encoded image bytes taken at ``t_ns`` (Unix ns)."""
    return _dumps({
        "timestamp": _stamp(t_ns),
        "frame_id": FRAME_ID,
        "data": base64.b64encode(data).decode("ascii"),
        "format": fmt,
    })


@frozen
class ImageMessage:
    """A decoded ``foxglove.CompressedImage``: encoded bytes, format, capture time (Unix ns)."""

    data: bytes
    fmt: str
    t_ns: int


def parse_image(payload: bytes) -> ImageMessage:
    """Decode a ``foxglove.CompressedImage`` JSON message; :class:`RecordingError` if it is not one."""
    try:
        msg = json.loads(payload)
        stamp = msg["timestamp"]
        return ImageMessage(
            data=base64.b64decode(msg["data"], validate=True),
            fmt=str(msg["format"]),
            t_ns=int(stamp["sec"]) * 1_000_000_000 + int(stamp["nsec"]),
        )
    except (ValueError, TypeError, KeyError) as exc:
        raise RecordingError(f"not a foxglove.CompressedImage message: {exc}") from None


def calibration_message(camera: CameraIntrinsics, t_ns: int) -> bytes:
    """The intrinsics as a ``foxglove.CameraCalibration`` (monocular: R = I, P = [K | 0])."""
    fx, fy, cx, cy = camera.fx_px, camera.fy_px, camera.cx_px, camera.cy_px
    return _dumps({
        "timestamp": _stamp(t_ns),
        "frame_id": FRAME_ID,
        "width": camera.width_px,
        "height": camera.height_px,
        "distortion_model": "plumb_bob",
        "D": [float(c) for c in camera.distortion],
        "K": [fx, 0.0, cx, 0.0, fy, cy, 0.0, 0.0, 1.0],
        "R": [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
        "P": [fx, 0.0, cx, 0.0, 0.0, fy, cy, 0.0, 0.0, 0.0, 1.0, 0.0],
    })


def parse_calibration(payload: bytes) -> CameraIntrinsics:
    """The intrinsics from a ``foxglove.CameraCalibration`` message."""
    try:
        msg = json.loads(payload)
        k = [float(v) for v in msg["K"]]
        return CameraIntrinsics(
            width_px=int(msg["width"]), height_px=int(msg["height"]),
            fx_px=k[0], fy_px=k[4], cx_px=k[2], cy_px=k[5],
            distortion=tuple(float(c) for c in msg["D"]),
        )
    except (ValueError, TypeError, KeyError, IndexError) as exc:
        raise RecordingError(f"not a foxglove.CameraCalibration message: {exc}") from None
