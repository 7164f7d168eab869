"""rangebearing: range and bearing to red/blue cylinder landmarks from camera frames.

>>> import rangebearing
>>> cfg = rangebearing.load_config(None)          # built-in defaults
>>> pipe = rangebearing.Pipeline(cfg.pipeline)    # camera, landmark, detection, model
>>> result = pipe.process(frame_bgr)              # doctest: +SKIP
>>> [(lm.range_m, lm.bearing_rad) for lm in result.landmarks]  # doctest: +SKIP
"""

from __future__ import annotations

from .config import Config, load_config
from .core.params import DetectionParams, ModelParams, PipelineParams
from .core.pipeline import Pipeline
from .core.types import CameraIntrinsics, FrameResult, Landmark, LandmarkGeometry
from .errors import (
    CalibrationError,
    CameraError,
    ConfigError,
    FrameError,
    ProtocolError,
    RangeBearingError,
    SourceError,
)

__version__ = "0.1.0"

__all__ = [
    "CalibrationError",
    "CameraError",
    "CameraIntrinsics",
    "Config",
    "ConfigError",
    "DetectionParams",
    "FrameError",
    "FrameResult",
    "Landmark",
    "LandmarkGeometry",
    "ModelParams",
    "Pipeline",
    "PipelineParams",
    "ProtocolError",
    "RangeBearingError",
    "SourceError",
    "__version__",
    "load_config",
]
