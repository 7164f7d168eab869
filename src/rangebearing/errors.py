"""The one exception tree of rangebearing.

Every error the package raises on purpose derives from :class:`RangeBearingError`
and also from the matching builtin, so callers may catch either.
"""

from __future__ import annotations


class RangeBearingError(Exception):
    """Root of every error rangebearing raises on purpose."""


class _Problems(Exception):
    """Mixin: an error that lists every problem found at once, under the name of what holds them."""

    def __init__(self, problems: list[str] | str, source: str) -> None:
        self.problems = [problems] if isinstance(problems, str) else list(problems)
        self.source = source
        lines = "\n".join(f"  - {p}" for p in self.problems)
        n = len(self.problems)
        super().__init__(f"{source}: {n} problem{'s' if n != 1 else ''}:\n{lines}")


class ConfigError(_Problems, RangeBearingError, ValueError):
    """A configuration file or value is invalid; the message names every problem."""

    def __init__(self, problems: list[str] | str, source: str = "<config>") -> None:
        super().__init__(problems, source)


class FrameError(RangeBearingError, ValueError):
    """A frame is unusable (wrong shape, wrong dtype, empty, corrupt)."""


class DetectorFault(FrameError):
    """The detector failed on one frame (a defect, not a bad frame): that frame is skipped, the run goes on."""


class FrameShapeError(FrameError):
    """Frames of a size the configuration cannot serve (another aspect ratio than camera.*): every frame would fail."""


class SourceError(RangeBearingError, OSError):
    """A frame source cannot be opened or read."""


class CameraError(SourceError):
    """The camera is missing, busy, or stopped delivering frames."""


class CameraLibraryError(CameraError):
    """picamera2 cannot be imported: retrying cannot help; the message says what to install."""


class CalibrationError(RangeBearingError, ValueError):
    """The calibration data cannot support a fit."""


class SceneError(_Problems, RangeBearingError, ValueError):
    """A synthetic scene or preset cannot be built as asked; the message names every problem."""

    def __init__(self, problems: list[str] | str, source: str = "synth") -> None:
        super().__init__(problems, source)


class PublishError(RangeBearingError, OSError):
    """Readings cannot be published: a destination does not resolve or a socket cannot be set up."""


class SubscribeError(RangeBearingError, OSError):
    """A subscriber cannot bind or join: a bad address, group or port."""


class NoReadingError(RangeBearingError, TimeoutError):
    """No valid reading arrived within the time a listener was told to wait."""


class ProtocolError(RangeBearingError, ValueError):
    """A datagram is not a valid rangebearing reading."""


class TruthError(RangeBearingError, ValueError):
    """A ground-truth file is malformed."""


class OutputError(RangeBearingError, OSError):
    """A file or folder the command was asked to write cannot be written."""


class RequestError(RangeBearingError, ValueError):
    """A request to the view server has an invalid parameter; answered with HTTP 400."""


class ServeError(RangeBearingError, OSError):
    """The view's web server cannot listen on the address asked for."""


class MissingExtraError(RangeBearingError, ImportError):
    """An optional extra (zenoh, mcap) is not installed; the message says what to pip install."""

    def __init__(self, extra: str, module: str, feature: str) -> None:
        self.extra = extra
        super().__init__(
            f"{feature} needs the optional package {module!r}: pip install 'rangebearing[{extra}]'"
        )


class TransportError(RangeBearingError, OSError):
    """A Zenoh session cannot be opened or declared (bad endpoint, no router in client mode)."""


class RecordingError(RangeBearingError, OSError):
    """An MCAP recording cannot be written or read (not MCAP, missing channels, I/O failure)."""
