"""rangebearing: range and bearing to red/blue cylinder landmarks from camera frames.

>>> import rangebearing
>>> cfg = rangebearing.load_config(None)          # built-in defaults
>>> pipe = rangebearing.Pipeline(cfg.pipeline)    # camera, landmark, detection, model
>>> result = pipe.process(frame_bgr)              # doctest: +SKIP
>>> [(lm.range_m, lm.bearing_rad) for lm in result.landmarks]  # doctest: +SKIP
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ._compat import lazy_attributes
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

# Imported on first use: ``rangebearing run`` must reach its signal handlers before numpy and
# OpenCV load (see ``_signals``), and ``import rangebearing.errors`` should cost nothing.
_LAZY = {
    "Config": ".config", "load_config": ".config",
    "DetectionParams": ".core.params", "ModelParams": ".core.params", "PipelineParams": ".core.params",
    "Pipeline": ".core.pipeline",
    "CameraIntrinsics": ".core.types", "FrameResult": ".core.types", "Landmark": ".core.types",
    "LandmarkGeometry": ".core.types",
}

if TYPE_CHECKING:
    from .config import Config, load_config
    from .core.params import DetectionParams, ModelParams, PipelineParams
    from .core.pipeline import Pipeline
    from .core.types import CameraIntrinsics, FrameResult, Landmark, LandmarkGeometry


__getattr__ = lazy_attributes(__name__, _LAZY)

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
